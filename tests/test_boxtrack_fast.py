"""boxtrack's columnar update (block covariances, gated association stages, one IoU matrix for the
tracks and the clutter share) gives the same rows as the plain tracker it replaced
(tests/boxtrack_oracle.py), bit for bit: ids, status, boxes, velocities and detection indices."""

from __future__ import annotations

import numpy as np
import pytest

from lookalike.io import find_sequences, frames_from_table, read_mot
from lookalike.sim import BoxSceneConfig, simulate_boxes
from lookalike.trackers.boxtrack import BoxTrack, BoxTrackConfig
from lookalike.types import Detections, Frame
from tests.boxtrack_oracle import PlainBoxTrack


def _rows(tracks) -> np.ndarray:  # type: ignore[no-untyped-def]
    return np.column_stack([tracks.id, tracks.status, tracks.xywh, tracks.velocity, tracks.detection_index])


def _run_both(frames: list[Frame], config: BoxTrackConfig | None = None, vel_noise: float | None = None) -> int:
    fast, plain = BoxTrack(config, vel_noise=vel_noise), PlainBoxTrack(config, vel_noise=vel_noise)
    reported = 0
    for frame in frames:
        got, want = _rows(fast.update(frame)), _rows(plain.update(frame))
        assert got.shape == want.shape and np.array_equal(got, want, equal_nan=True), f"frame {frame.index}"
        reported += len(got)
    return reported


def _scene(seed: int, frames: int = 150, n_targets: int = 8) -> list[Frame]:
    """A crowded simulated scene with scores spread over [0, 1] (some below every threshold), frames
    dropped (two-frame steps), a repeated time stamp (a zero step) and empty frames."""
    scene = simulate_boxes(BoxSceneConfig(seed=seed, frames=frames, n_targets=n_targets, speed_px=6.0,
                                          miss_rate=0.2, false_positives_per_frame=2.0))
    rng = np.random.default_rng(seed)
    out: list[Frame] = []
    for frame in scene.frames:
        k = frame.index
        if k % 17 == 5 or 60 <= k < 64:
            continue  # dropped frames: the next step is 2 or more frame intervals
        xywh = frame.detections.xywh
        if k % 23 == 11:
            xywh = xywh[:0]
        score = np.clip(rng.beta(5.0, 1.5, len(xywh)), 0.0, 1.0)
        score[rng.random(len(xywh)) < 0.1] = 1.0
        time = frame.time if k % 41 != 7 else out[-1].time  # a zero step
        out.append(Frame(k, time, Detections(xywh=xywh, score=score)))
    return out


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_same_rows_as_the_plain_tracker_on_crowded_scenes(seed: int) -> None:
    assert _run_both(_scene(seed)) > 100


@pytest.mark.parametrize("config", [
    BoxTrackConfig(max_targets=6),
    BoxTrackConfig(max_targets=3, max_age_s=0.5),
    BoxTrackConfig(n_init=1, clutter_factor=None, high_match_ratio=None, match_iou=0.0),
    BoxTrackConfig(low_score=0.5, high_score=0.7, birth_score=0.7, n_init=3, reid_scale=3.0),
])
def test_same_rows_as_the_plain_tracker_with_other_settings(config: BoxTrackConfig) -> None:
    assert _run_both(_scene(3, frames=120), config) > 50


def test_same_rows_as_the_plain_tracker_with_another_velocity_noise() -> None:
    assert _run_both(_scene(4, frames=100), vel_noise=0.05) > 50


def test_same_rows_as_the_plain_tracker_on_real_detections(shared_data) -> None:  # type: ignore[no-untyped-def]
    seq = find_sequences(shared_data / "mot15" / "TUD-Stadtmitte")[0]
    frames = list(frames_from_table(read_mot(seq.det_path), seq.length, seq.frame_rate))
    assert _run_both(frames) > 500
    assert _run_both(frames, BoxTrackConfig(max_targets=10)) > 500
