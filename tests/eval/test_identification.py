"""Seed A's identification success rate and localisation error on hand-computed cases."""

from __future__ import annotations

import math

import numpy as np
import pytest

from lookalike.eval import (
    identification_by_agent,
    identification_success_rate,
    localisation_coverage,
    localisation_error,
    localisation_error_by_agent,
)


def test_success_rate_counts_false_positive_labelled_as_such() -> None:
    # frame 0: all 3 right (the false positive -1 labelled -1 counts as correct);
    # frame 1: agent 0 labelled 1 (wrong), false positive labelled -1 (right): 4 / 5 = 0.8.
    predicted = [np.array([0, 1, -1]), np.array([1, -1])]
    true = [np.array([0, 1, -1]), np.array([0, -1])]
    assert identification_success_rate(predicted, true) == pytest.approx(0.8)
    # per agent: agent 0 has 2 detections, 1 right -> 0.5; agent 1: 1/1; false positives: 2/2.
    assert identification_by_agent(predicted, true) == {-1: 1.0, 0: 0.5, 1: 1.0}


def test_success_rate_bad_and_empty_inputs() -> None:
    assert math.isnan(identification_success_rate([np.zeros(0, int)], [np.zeros(0, int)]))
    with pytest.raises(ValueError, match="frame 0"):
        identification_success_rate([np.array([0, 1])], [np.array([0])])
    with pytest.raises(ValueError, match="frames"):
        identification_success_rate([np.array([0])], [])
    with pytest.raises(ValueError, match="predicted_labels"):
        identification_success_rate([np.array([-2])], [np.array([0])])


def test_localisation_error_over_present_agents() -> None:
    nan = np.nan
    truth = np.array([[[0, 0], [10, 10]], [[0, 0], [nan, nan]], [[0, 0], [10, 10]]], float)
    est = np.array([[[3, 4], [10, 11]], [[0, 1], [5, 5]], [[nan, nan], [10, 13]]], float)
    # agent 0: distances 5, 1 (frame 2 not estimated) -> 3; agent 1: 1, (absent), 3 -> 2.
    np.testing.assert_allclose(localisation_error_by_agent(est, truth), [3.0, 2.0])
    # all pairs: (5 + 1 + 1 + 3) / 4 = 2.5; 4 of 5 presences estimated.
    assert localisation_error(est, truth) == pytest.approx(2.5)
    assert localisation_coverage(est, truth) == pytest.approx(0.8)
    with pytest.raises(ValueError, match="estimated"):
        localisation_error(est[:2], truth)
