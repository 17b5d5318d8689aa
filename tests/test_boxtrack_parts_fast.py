"""The shortened forms boxtrack's parts use give the numbers of the forms they replaced: the score
quantiles walked from frame to frame (no cumulative sum), the centre distance without
``np.linalg.norm``, the solver's disjoint-pairs check with sets."""

from __future__ import annotations

import numpy as np
import pytest

from lookalike.association.costs import centre_distance_cost
from lookalike.association.solver import assign_pairs
from lookalike.trackers.parts.self_calibration import ScoreCalibration
from tests.test_self_calibration_fast import plain_decide


@pytest.mark.parametrize("bins, ratio", [(1000, None), (1000, 0.6), (7, None), (50, 0.3)])
def test_walked_quantiles_equal_one_search_per_quantile(bins: int, ratio: float | None) -> None:
    rng = np.random.default_rng(bins)
    cal = ScoreCalibration(0.9, 0.95, high_quantile=0.35, birth_quantile=0.8, tentative_quantile=0.02,
                           high_match_ratio=ratio, calib_min_count=10, bins=bins, clutter_factor=2.0)
    for frame in range(150):
        n = int(rng.integers(0, 15))
        score = rng.beta(5, 1, n) if frame < 60 else rng.uniform(-0.1, 1.1, n)  # the distribution shifts
        score[rng.random(n) < 0.1] = 1.0
        cal.observe_scores(score)
        cal.observe_continued(score, np.flatnonzero(rng.random(n) < 0.5))
        for share in rng.choice([0.0, 0.01, 0.3, 0.9], 2).tolist() + [None]:  # jumps both ways
            assert cal.decide(share) == plain_decide(cal, share)


def _plain_centre_distance(track: np.ndarray, det: np.ndarray, gate: np.ndarray | float,
                           max_scale: float) -> np.ndarray:
    height = np.maximum(track[:, 3:4], 1.0)
    dist = np.linalg.norm(track[:, None, :2] - det[None, :, :2], axis=2) / height
    size_t = np.maximum(track[:, None, 2:4], 1.0)
    ratio = np.abs(np.log(size_t / np.maximum(det[None, :, 2:4], 1.0))).max(axis=2)
    out: np.ndarray = np.where((dist <= gate) & (ratio <= np.log(max_scale)), dist, np.inf)
    return out


def test_centre_distance_equals_the_norm_form() -> None:
    rng = np.random.default_rng(0)
    for _ in range(100):
        k, n = (int(v) for v in rng.integers(0, 7, 2))
        track = np.column_stack([rng.uniform(0, 200, (k, 2)), rng.uniform(0.2, 60, (k, 2))])
        det = np.column_stack([rng.uniform(0, 200, (n, 2)), rng.uniform(0.2, 60, (n, 2))])
        gate = rng.uniform(0.5, 5, (k, 1)) if rng.random() < 0.5 else float(rng.uniform(0.5, 5))
        want = _plain_centre_distance(track, det, gate, 1.5)
        assert np.array_equal(centre_distance_cost(track, det, gate, 1.5), want)


def test_disjoint_allowed_pairs_are_taken_as_they_are() -> None:
    cost = np.full((4, 5), np.inf)
    cost[0, 3], cost[2, 1], cost[3, 4] = 0.5, 0.9, 0.1
    assert assign_pairs(cost).tolist() == [[0, 3], [2, 1], [3, 4]]
    cost[1, 3] = 0.2  # detection 3 now wanted twice: solved, the cheaper track wins
    assert assign_pairs(cost).tolist() == [[1, 3], [2, 1], [3, 4]]
    assert assign_pairs(cost, max_cost=0.6).tolist() == [[1, 3], [3, 4]]
