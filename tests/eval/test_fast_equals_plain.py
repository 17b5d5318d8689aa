"""The sparse, vectorised scoring equals the plain one-frame-at-a-time oracle (tests/eval/plain.py)."""

from __future__ import annotations

import numpy as np
import pytest

from lookalike.eval import box_iou, evaluate_sequence
from lookalike.eval.similarity import pair_iou
from lookalike.io import MotTable

from .plain import plain_scores


def _random_gt(rng: np.random.Generator, frames: int, ids: int) -> MotTable:
    """Crowded ground truth: ``ids`` objects drifting in a 60-px square, each present in most frames."""
    rows = []
    centres = rng.uniform(0, 60, (ids, 2))
    for f in range(1, frames + 1):
        for k in np.flatnonzero(rng.random(ids) < 0.8):
            cx, cy = centres[k]
            w, h = rng.uniform(10, 25), rng.uniform(20, 45)
            rows.append((f, k + 1, cx - w / 2, cy - h / 2, w, h))
        centres += rng.normal(0, 2, centres.shape)
    data = np.array(rows, float).reshape(-1, 6)
    n = len(data)
    conf = (rng.random(n) > 0.1).astype(float)
    cls = rng.choice([1, 1, 1, 1, 2, 7, 8, 12], n).astype(float)
    return MotTable(data[:, 0].astype(int), data[:, 1].astype(int), data[:, 2:6], conf, cls[:, None])


def _random_result(rng: np.random.Generator, gt: MotTable) -> MotTable:
    """Tracker boxes: most ground-truth boxes jittered (some exactly copied: ties), ids that switch now and
    then, and false positives."""
    keep = rng.random(len(gt)) < 0.85
    xywh = gt.xywh[keep] + rng.normal(0, 2.5, (int(keep.sum()), 4)) * (rng.random((int(keep.sum()), 1)) > 0.2)
    ids = gt.track_id[keep] + 100 * (gt.frame[keep] > rng.integers(5, 20, int(keep.sum())))
    frames = gt.frame[keep]
    n_fp = len(gt) // 6
    fp = np.column_stack([rng.uniform(0, 60, (n_fp, 2)), rng.uniform(10, 40, (n_fp, 2))])
    frames = np.concatenate([frames, rng.integers(1, int(gt.frame.max()) + 1, n_fp)])
    ids = np.concatenate([ids, 1000 + np.arange(n_fp)])
    xywh = np.concatenate([xywh, fp])
    n = len(frames)
    return MotTable(frames, ids, xywh, rng.random(n), -np.ones((n, 1)))


def _assert_equal(fast: dict[str, float], plain: dict[str, float]) -> None:
    assert fast.keys() == plain.keys()
    for key, v in plain.items():
        assert fast[key] == pytest.approx(v, abs=1e-12, rel=1e-12), key


@pytest.mark.parametrize("benchmark", ["MOT17", "MOT15", "custom"])
@pytest.mark.parametrize("seed", range(4))
def test_random_sequences_score_as_the_plain_loop(benchmark: str, seed: int) -> None:
    rng = np.random.default_rng(seed)
    gt = _random_gt(rng, 25, 9)
    res = _random_result(rng, gt)
    for threshold in (0.5, 0.3):
        fast = evaluate_sequence(gt, res, benchmark=benchmark, num_frames=27, iou_threshold=threshold)
        _assert_equal(fast, plain_scores(gt, res, num_frames=27, benchmark=benchmark, threshold=threshold))


def test_empty_sides_score_as_the_plain_loop() -> None:
    rng = np.random.default_rng(1)
    gt = _random_gt(rng, 5, 3)
    empty = MotTable(np.zeros(0, int), np.zeros(0, int), np.zeros((0, 4)), np.zeros(0), np.zeros((0, 1)))
    for a, b in ((gt, empty), (empty, gt), (empty, empty)):
        _assert_equal(evaluate_sequence(a, b, benchmark="MOT15", num_frames=6),
                      plain_scores(a, b, num_frames=6, benchmark="MOT15"))


def test_pair_iou_is_box_iou_bit_for_bit() -> None:
    rng = np.random.default_rng(3)
    a = rng.uniform(0, 50, (7, 4))
    b = np.concatenate([rng.uniform(0, 50, (6, 4)), a[:2], [[0, 0, 0, 5]]])
    full = box_iou(a, b)
    i, j = np.meshgrid(np.arange(len(a)), np.arange(len(b)), indexing="ij")
    assert np.array_equal(pair_iou(a[i.ravel()], b[j.ravel()]), full.ravel())
