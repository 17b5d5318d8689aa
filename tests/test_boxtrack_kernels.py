"""boxtrack's compiled kernels (numba, optional) give bit for bit the rows of its numpy path: ids, status, boxes,
velocities and detection indices, on awkward inputs (empty frames, one detection, dropped frames, zero time
steps, scores below every threshold, degenerate boxes, duplicates whose pairs compete, closed sets), and each
kernel the numbers of the numpy operations it replaces. Without numba the switch tests still run."""

from __future__ import annotations

import subprocess
import sys
from collections.abc import Iterator

import numpy as np
import pytest

import lookalike.trackers.kernels.boxtrack as bk
from lookalike.association.costs import iou_columns
from lookalike.motion.spaces import BoxCXCYWH
from lookalike.sim import BoxSceneConfig, simulate_boxes
from lookalike.trackers.boxtrack import BoxTrack, BoxTrackConfig
from lookalike.types import Detections, Frame


@pytest.fixture(autouse=True)
def _default_switch() -> Iterator[None]:
    yield
    bk.use_compiled(None)


def test_the_switch_off_gives_the_numpy_path(monkeypatch: pytest.MonkeyPatch) -> None:
    bk.use_compiled(False)
    assert bk.compiled() is None and not BoxTrack().compiled
    bk.use_compiled(None)
    monkeypatch.setenv("LOOKALIKE_BOXTRACK_NUMBA", "0")
    assert bk.compiled() is None and not BoxTrack().compiled


def test_import_lookalike_does_not_import_numba() -> None:
    code = "import sys, lookalike; from lookalike.trackers.boxtrack import BoxTrack; print('numba' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "False"


def test_a_default_tracker_takes_the_numpy_path_until_loading_pays(monkeypatch: pytest.MonkeyPatch) -> None:
    switch = bk._SWITCH
    monkeypatch.setattr(switch, "_loaded", False)
    monkeypatch.setattr(switch, "_spent", 0.0)
    monkeypatch.setattr(switch, "_load", lambda: pytest.fail("the kernels were loaded before they paid"))
    tracker = BoxTrack()
    for frame in _awkward(0, frames=30):
        tracker.update(frame)
    assert not tracker.compiled and 0 < switch._spent < bk.LOAD_AFTER_S
    monkeypatch.setattr(switch, "_load", lambda: None)  # numba absent: once due, the numpy path for good
    monkeypatch.setattr(switch, "_load_after_s", 0.0)
    tracker.update(_awkward(0, frames=31)[-1])
    assert not tracker.compiled and tracker._path.kernels is False and switch._loaded


def test_a_run_announced_long_loads_the_kernels_at_its_start(monkeypatch: pytest.MonkeyPatch) -> None:
    switch, loads = bk._SWITCH, []
    monkeypatch.setattr(switch, "_loaded", False)
    monkeypatch.setattr(switch, "_spent", 0.0)
    monkeypatch.setattr(switch, "_load", lambda: loads.append(1))  # (None: as without numba)
    tracker = BoxTrack()
    tracker.expect(bk.EAGER_FRAMES - 1)
    assert not loads and tracker._path.kernels is None  # short: still the numpy path, undecided
    tracker.expect(bk.EAGER_FRAMES)
    assert loads == [1] and tracker._path.kernels is False  # long: loaded and decided at once


numba_missing = pytest.mark.skipif(
    bk.module() is None,
    reason="numba (the `fast` extra) is not installed: only the numpy path runs")


def _rows(tracks) -> np.ndarray:  # type: ignore[no-untyped-def]
    return np.column_stack([tracks.id, tracks.status, tracks.xywh, tracks.velocity, tracks.detection_index])


def _run_both(frames: list[Frame], config: BoxTrackConfig | None = None, vel_noise: float | None = None) -> int:
    bk.use_compiled(True)
    fast = BoxTrack(config, vel_noise=vel_noise)
    bk.use_compiled(False)
    plain = BoxTrack(config, vel_noise=vel_noise)
    assert fast.compiled and not plain.compiled
    reported = 0
    for frame in frames:
        got, want = _rows(fast.update(frame)), _rows(plain.update(frame))
        assert got.shape == want.shape and np.array_equal(got, want, equal_nan=True), f"frame {frame.index}"
        assert got.dtype == want.dtype
        reported += len(got)
    return reported


@numba_missing
def test_a_tracker_that_switches_to_the_kernels_midway_gives_the_numpy_rows(monkeypatch: pytest.MonkeyPatch) -> None:
    frames = _awkward(1)
    bk.use_compiled(False)
    plain = BoxTrack()
    want = [_rows(plain.update(frame)) for frame in frames]
    bk.use_compiled(None)
    switch = bk._SWITCH
    monkeypatch.setattr(switch, "_loaded", False)
    monkeypatch.setattr(switch, "_spent", 0.0)
    tracker = BoxTrack()
    assert not tracker.compiled
    for k, frame in enumerate(frames):
        if k == 40:
            monkeypatch.setattr(switch, "_load_after_s", 0.0)  # loading pays from now on
        got = _rows(tracker.update(frame))
        assert np.array_equal(got, want[k], equal_nan=True), f"frame {frame.index}"
        assert tracker.compiled == (k >= 40)


def _awkward(seed: int, frames: int = 120) -> list[Frame]:
    """A crowded simulated scene with every awkward case: empty frames (the first one too), one detection,
    dropped frames, zero and long time steps, every score below ``low_score``, duplicated detections (pairs that
    compete), boxes of zero and sub-pixel size."""
    scene = simulate_boxes(BoxSceneConfig(seed=seed, frames=frames, n_targets=7, speed_px=6.0, miss_rate=0.2,
                                          false_positives_per_frame=2.0))
    rng = np.random.default_rng(seed)
    out: list[Frame] = []
    time = 0.0
    for frame in scene.frames:
        k = frame.index
        if k % 19 == 5 or 50 <= k < 55:
            continue  # dropped frames
        xywh = frame.detections.xywh.copy()
        score = np.clip(rng.beta(5.0, 1.5, len(xywh)), 0.0, 1.0)
        score[rng.random(len(xywh)) < 0.1] = 1.0
        if k == 0 or k % 23 == 11:
            xywh, score = xywh[:0], score[:0]
        elif k % 29 == 3:
            xywh, score = xywh[:1], score[:1]
        elif k % 31 == 8:
            score = np.full(len(xywh), 0.05)  # all below low_score
        elif k % 13 == 4 and len(xywh):
            xywh, score = np.vstack([xywh, xywh[:2] + 1.0]), np.concatenate([score, score[:2]])  # competing pairs
        elif k % 37 == 9 and len(xywh):
            xywh[0, 2:] = 0.0 if k % 2 else 0.4  # degenerate boxes
        time = time if k % 41 == 7 else frame.time  # a zero step
        out.append(Frame(k, time, Detections(xywh=xywh, score=score)))
    return out


@numba_missing
@pytest.mark.parametrize("seed", [0, 1])
def test_compiled_rows_equal_the_numpy_paths_on_awkward_scenes(seed: int) -> None:
    assert _run_both(_awkward(seed)) > 50


@numba_missing
@pytest.mark.parametrize("config", [
    BoxTrackConfig(max_targets=5),
    BoxTrackConfig(max_targets=1, max_age_s=0.3),
    BoxTrackConfig(n_init=1, match_iou=0.5, high_match_ratio=None),
    BoxTrackConfig(low_score=0.5, high_score=0.7, birth_score=0.7, n_init=3, reid_scale=3.0, clutter_factor=None,
                   frame_interval_s=0.02),
])
def test_compiled_rows_equal_the_numpy_paths_with_other_settings(config: BoxTrackConfig) -> None:
    assert _run_both(_awkward(2, frames=90), config) > 20


@numba_missing
def test_compiled_rows_equal_the_numpy_paths_with_another_velocity_noise() -> None:
    assert _run_both(_awkward(3, frames=90), vel_noise=0.05) > 20


@numba_missing
def test_compiled_rows_equal_the_numpy_paths_on_real_detections(shared_data) -> None:  # type: ignore[no-untyped-def]
    from lookalike.io import find_sequences, frames_from_table, read_mot

    seq = find_sequences(shared_data / "mot15" / "TUD-Stadtmitte")[0]
    frames = list(frames_from_table(read_mot(seq.det_path), seq.length, seq.frame_rate))
    assert _run_both(frames) > 500
    assert _run_both(frames, BoxTrackConfig(max_targets=10)) > 500


@numba_missing
def test_frames_with_other_float_columns_take_the_numpy_path() -> None:
    frames = _awkward(5, frames=60)
    for frame in frames[20:40]:  # float32 columns, as a caller building Detections without checks could leave
        object.__setattr__(frame.detections, "xywh", frame.detections.xywh.astype(np.float32))
        object.__setattr__(frame.detections, "score", frame.detections.score.astype(np.float32))
    assert _run_both(frames) > 10


@numba_missing
def test_a_copied_compiled_tracker_goes_on_as_the_original() -> None:
    import copy
    import pickle

    frames = _awkward(4, frames=60)
    bk.use_compiled(True)
    tracker = BoxTrack()
    for frame in frames[:30]:
        tracker.update(frame)
    twins = [copy.deepcopy(tracker), pickle.loads(pickle.dumps(tracker))]
    for frame in frames[30:]:
        want = _rows(tracker.update(frame))
        for twin in twins:
            assert twin.compiled and np.array_equal(_rows(twin.update(frame)), want)


def _columns(rng: np.random.Generator, k: int) -> np.ndarray:
    space = BoxCXCYWH(1 / 20, 1 / 160)
    z = np.column_stack([rng.uniform(0, 600, (k, 2)), rng.uniform(0.2, 90, (k, 2))])
    x = space.initial_rows(z).T.copy()
    x[4:8] = rng.normal(0, 3, (4, k))
    x[8:24] *= rng.uniform(0.5, 4.0, (16, k))
    x[2, :1] = 0.0  # a zero width
    return x


@numba_missing
@pytest.mark.parametrize("steps", [1.0, 2.0, 0.0, 0.5, 3.7])
def test_advance_equals_the_prediction_and_iou_columns(steps: float) -> None:
    kern = bk.compiled()
    assert kern is not None
    rng = np.random.default_rng(int(steps * 10))
    space = BoxCXCYWH(0.07, 0.011)
    for k, n, p in [(0, 0, 0), (1, 1, 0), (5, 0, 3), (0, 4, 2), (9, 6, 5)]:
        x = _columns(rng, k)
        unseen = rng.choice([0.0, 0.2, 0.6], k)
        det = np.column_stack([rng.uniform(0, 600, (n, 2)), rng.uniform(0, 90, (n, 2))])
        prev = np.vstack([det[:2] + 0.5, rng.uniform(0, 600, (p, 4))])[:p] if p else np.zeros((0, 4))
        want = x.copy()
        want[4:8, unseen >= 0.5] = 0.0
        space.predict_columns(want, steps)
        got = x.copy()
        iou, flicker = kern.advance(got, steps, max(steps, 0.0), unseen, 0.5, space.pos_noise**2,
                                    space.vel_noise**2, prev, det, 0.5)
        assert np.array_equal(got, want)
        boxes = np.vstack([want[0:2] - np.maximum(want[2:4], 1e-3) / 2, np.maximum(want[2:4], 1e-3)])
        assert np.array_equal(iou, iou_columns(boxes, det.T))
        overlap = iou_columns(prev.T, det.T) >= 0.5
        assert flicker == (n if not p else n - np.count_nonzero(overlap.any(axis=0)))


@numba_missing
def test_correct_equals_the_update_columns() -> None:
    kern = bk.compiled()
    assert kern is not None
    rng = np.random.default_rng(5)
    space = BoxCXCYWH(1 / 20, 1 / 160)
    k, n = 8, 6
    x = _columns(rng, k)
    det = np.column_stack([rng.uniform(0, 600, (n, 2)), rng.uniform(0.5, 90, (n, 2))])
    det_of_track = np.array([3, -1, 0, 5, -1, 1, -1, 2])
    confirmed = np.array([True, True, False, True, True, False, False, True])
    misses, unseen, hits = rng.integers(0, 3, k), rng.uniform(0, 1, k), rng.integers(0, 4, k)
    matched = (det_of_track >= 0).nonzero()[0]
    want = x.copy()
    z = np.vstack([det[:, 0:2].T + det[:, 2:4].T / 2.0, det[:, 2:4].T])[:, det_of_track[matched]]
    sub = want[:, matched]
    innovation, s = space.innovation_columns(sub, z)
    space.correct_columns(sub, innovation, s)
    want[:, matched] = sub
    got, m2, u2, h2, c2 = x.copy(), misses.copy(), unseen.copy(), hits.copy(), confirmed.copy()
    fit, back = np.empty((4, k)), np.empty(k, dtype=np.int64)
    n_fit, n_back = kern.correct(got, det_of_track, det, space.pos_noise, c2, m2, u2, h2, True, 0.04, 2, False,
                                 fit, back)
    assert np.array_equal(got, want)
    conf = confirmed[matched]
    assert n_fit == np.count_nonzero(conf)
    assert np.array_equal(fit[:, :n_fit], np.vstack([innovation[0:2], s[0:2]])[:, conf])
    came_back = misses[matched][conf & (misses[matched] > 0)]
    assert np.array_equal(back[:n_back], came_back)
    hit = det_of_track >= 0
    assert np.array_equal(h2, (hits + hit) * hit)
    assert np.array_equal(m2, np.where(hit, 0, misses + 1)) and np.array_equal(u2, np.where(hit, 0.0, unseen + 0.04))
    assert np.array_equal(c2, confirmed | (h2 >= 2))


@numba_missing
def test_the_kernels_maximum_and_minimum_are_numpys() -> None:  # (NaN when either is NaN)
    from lookalike.trackers.kernels import boxtrack_numba as bn

    values = [np.nan, -np.inf, -1.5, -0.0, 0.0, 2.0, np.inf]
    for a in values:
        for b in values:
            for mine, theirs in ((bn._maximum, np.maximum), (bn._minimum, np.minimum)):
                got, want = np.float64(mine(a, b)), theirs(np.float64(a), np.float64(b))
                # (equal values: of two zeros of opposite sign the kernels return the first, numpy may not)
                assert got == want or (np.isnan(got) and np.isnan(want)), (a, b)
