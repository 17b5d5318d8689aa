"""boxtrack on large frames: the batched association (connected groups of tracks and detections found with a k-d
tree) gives the rows of the dense one, and its memory stays linear in the boxes."""

from __future__ import annotations

import numpy as np
import pytest

import lookalike.trackers.boxtrack as boxtrack_module
from lookalike.io.points import POINT_VEL_NOISE
from lookalike.sim import BoxSceneConfig, simulate_boxes
from lookalike.trackers.boxtrack import BoxTrack, BoxTrackConfig
from lookalike.trackers.parts.batches import batches, near_pairs, overlapping_pairs, pair_iou
from lookalike.types import Detections, Frame


def _rows(tracks) -> np.ndarray:  # type: ignore[no-untyped-def]
    return np.column_stack([tracks.id, tracks.status, tracks.xywh, tracks.velocity, tracks.detection_index])


def _crowd(seed: int, frames: int = 80) -> list[Frame]:
    """A crowded scene: crossings, misses, clutter, low scores, a gap of frames (lost tracks re-identified)."""
    scene = simulate_boxes(BoxSceneConfig(seed=seed, frames=frames, n_targets=12, speed_px=6.0, miss_rate=0.2,
                                          false_positives_per_frame=3.0))
    rng = np.random.default_rng(seed)
    out = []
    for frame in scene.frames:
        if 30 <= frame.index < 36:
            continue
        n = len(frame.detections.score)
        score = rng.uniform(0.0, 1.0, n) if seed % 2 else np.where(rng.random(n) < 0.2, 0.3, 0.97)
        out.append(Frame(index=frame.index, time=frame.time,
                         detections=Detections(xywh=frame.detections.xywh.copy(), score=score)))
    return out


@pytest.mark.parametrize("seed", range(6))
@pytest.mark.parametrize("closed", [False, True])
@pytest.mark.parametrize("budget", [0, 60])
def test_batched_association_gives_the_dense_rows(seed: int, closed: bool, budget: int,
                                                  monkeypatch: pytest.MonkeyPatch) -> None:
    frames = _crowd(seed)
    config = BoxTrackConfig(max_targets=12 if closed else None)
    dense = BoxTrack(config)
    dense_rows = [_rows(dense.update(f)) for f in frames]
    monkeypatch.setattr(boxtrack_module, "LARGE_PAIRS", budget)  # 0: each batch one group; 60: groups packed
    calls = []
    run_batches = BoxTrack._associate_batches
    monkeypatch.setattr(BoxTrack, "_associate_batches", lambda self, *a: calls.append(1) or run_batches(self, *a))
    batched = BoxTrack(config)
    for frame, want in zip(frames, dense_rows):
        got = _rows(batched.update(frame))
        assert np.array_equal(got, want, equal_nan=True), f"frame {frame.index}"
    assert len(calls) >= len(frames) // 2


def test_pairs_are_those_of_the_dense_matrices() -> None:
    rng = np.random.default_rng(1)
    a = np.column_stack([rng.uniform(0, 200, (60, 2)), rng.uniform(1, 30, (60, 2))])
    b = np.column_stack([rng.uniform(0, 200, (50, 2)), rng.uniform(1, 30, (50, 2))])
    i, j = overlapping_pairs(a, b)
    ax, bx = a[:, None, :], b[None, :, :]
    inter = np.prod(np.maximum(np.minimum(ax[..., :2] + ax[..., 2:], bx[..., :2] + bx[..., 2:])
                               - np.maximum(ax[..., :2], bx[..., :2]), 0), axis=2)
    assert set(zip(i.tolist(), j.tolist())) == set(zip(*np.nonzero(inter > 0)))
    union = (a[:, 2] * a[:, 3])[:, None] + b[:, 2] * b[:, 3] - inter
    assert np.allclose(pair_iou(a[i], b[j]), (inter / union)[i, j])
    radius = rng.uniform(0, 40, 60)
    radius[3] = np.nan  # not a candidate
    i, j = near_pairs(a[:, :2], radius, b[:, :2])
    dist = np.linalg.norm(a[:, None, :2] - b[None, :, :2], axis=2)
    want = {(r, c) for r, c in zip(*np.nonzero(dist <= radius[:, None])) if r != 3}
    assert set(zip(i.tolist(), j.tolist())) == want


def test_batches_pack_whole_groups_within_the_budget() -> None:
    i = np.array([0, 1, 1, 3, 4])  # groups: {t0, d0}, {t1, d1, d2}, {t3, d3}, {t4, d3} joins t3; t2, d4 on no pair
    j = np.array([0, 1, 2, 3, 3])
    got = list(batches(5, 5, i, j, budget=4))
    assert [(r.tolist(), c.tolist()) for r, c in got] == [([0], [0]), ([1], [1, 2]), ([3, 4], [3])]
    assert [(r.tolist(), c.tolist()) for r, c in batches(5, 5, i, j, budget=100)] == [([0, 1, 3, 4], [0, 1, 2, 3])]
    assert not list(batches(5, 5, np.zeros(0, int), np.zeros(0, int), budget=4))


def test_ten_thousand_points_a_frame_use_memory_linear_in_them() -> None:
    """tracemalloc's peak of a frame of n points (the tracks of the frame before) grows about linearly with n."""
    import tracemalloc

    def peak(n: int) -> int:
        rng = np.random.default_rng(0)
        pos = rng.uniform(0, 40 * np.sqrt(n), (n, 2))
        tracker = BoxTrack(vel_noise=POINT_VEL_NOISE)
        for k in range(3):
            pos += rng.normal(0, 1, pos.shape)
            xywh = np.hstack([pos - 5, np.full((n, 2), 10.0)])
            if k == 2:
                tracemalloc.start()
            tracker.update(Frame(index=k, time=k / 25, detections=Detections(xywh=xywh, score=np.ones(n))))
        peak = tracemalloc.get_traced_memory()[1]
        tracemalloc.stop()
        return peak

    small, large = peak(2_500), peak(10_000)
    assert large < 200 * 2**20  # a dense 10,000 x 10,000 IoU matrix alone is 800 MB
    assert large < 8 * small  # four times the points, well under sixteen times the memory
