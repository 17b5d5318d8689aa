import itertools

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from lookalike.association import assign


def _check_partition(result, shape):
    rows, cols = shape
    matched_r, matched_c = result.matches[:, 0], result.matches[:, 1]
    assert sorted(np.concatenate([matched_r, result.unmatched_rows]).tolist()) == list(range(rows))
    assert sorted(np.concatenate([matched_c, result.unmatched_cols]).tolist()) == list(range(cols))
    assert len(set(matched_r)) == len(matched_r) and len(set(matched_c)) == len(matched_c)


def test_empty_matrices():
    for shape in [(0, 0), (0, 3), (4, 0)]:
        r = assign(np.zeros(shape), 1.0)
        assert r.matches.shape == (0, 2)
        _check_partition(r, shape)


def test_all_forbidden_rows_and_columns():
    cost = np.array([[np.inf, np.inf, np.inf], [0.2, np.inf, 0.1], [np.inf, np.inf, 0.3]])
    r = assign(cost)
    _check_partition(r, cost.shape)
    # Row 0 and column 1 can never match; the best full use of the rest is (1,0) + (2,2).
    assert r.matches.tolist() == [[1, 0], [2, 2]]
    assert r.unmatched_rows.tolist() == [0]
    assert r.unmatched_cols.tolist() == [1]


def test_everything_forbidden():
    r = assign(np.full((3, 2), np.inf), 5.0)
    assert r.matches.shape == (0, 2)
    assert r.unmatched_rows.tolist() == [0, 1, 2]


def test_threshold_forbids_pairs():
    cost = np.array([[0.1, 0.9], [0.8, 0.95]])
    r = assign(cost, max_cost=0.85)
    assert r.matches.tolist() == [[0, 0], [1, 1]] or r.matches.tolist() == [[0, 0]]
    assert all(cost[i, j] <= 0.85 for i, j in r.matches)


def test_rectangular_and_ties():
    cost = np.ones((2, 5))
    r = assign(cost, 2.0)
    assert len(r.matches) == 2
    _check_partition(r, cost.shape)
    r = assign(cost.T, 2.0)
    assert len(r.matches) == 2


def test_huge_finite_costs_do_not_overflow():
    cost = np.array([[1e300, 1e308], [1e308, 1e300]])
    r = assign(cost)
    assert r.matches.tolist() == [[0, 0], [1, 1]]
    r = assign(np.array([[1e308, 1.0], [np.inf, 1e308]]))
    assert len(r.matches) == 2  # (0,0) is forbidden-free and (1,1) too: both rows matched


def test_nan_is_an_error():
    with pytest.raises(ValueError, match="NaN at row 0, column 1"):
        assign(np.array([[0.0, np.nan]]))
    with pytest.raises(ValueError, match="2-D"):
        assign(np.zeros(3))


def _brute_force(cost, max_cost):
    """Max number of allowed pairs, then min total cost, over all partial matchings."""
    n, m = cost.shape
    best = (0, 0.0)
    allowed = np.isfinite(cost) & (cost <= max_cost)
    for k in range(min(n, m), 0, -1):
        for rows in itertools.combinations(range(n), k):
            for cols in itertools.permutations(range(m), k):
                if all(allowed[r, c] for r, c in zip(rows, cols)):
                    total = sum(cost[r, c] for r, c in zip(rows, cols))
                    if best[0] < k or total < best[1]:
                        best = (k, total)
        if best[0] == k:
            return best
    return best


@settings(max_examples=80, deadline=None)
@given(
    arrays(
        float,
        st.tuples(st.integers(1, 4), st.integers(1, 4)),
        elements=st.one_of(st.floats(0, 10, allow_nan=False), st.just(np.inf)),
    )
)
def test_unbounded_assignment_is_maximum_then_minimum(cost):
    r = assign(cost)
    _check_partition(r, cost.shape)
    k, total = _brute_force(cost, np.inf)
    assert len(r.matches) == k
    got = sum(cost[i, j] for i, j in r.matches)
    assert got == pytest.approx(total, abs=1e-9)


@settings(max_examples=80, deadline=None)
@given(
    arrays(float, st.tuples(st.integers(1, 4), st.integers(1, 4)), elements=st.floats(0, 1, allow_nan=False)),
    st.floats(0.05, 1.0),
)
def test_gated_assignment_respects_threshold(cost, max_cost):
    r = assign(cost, max_cost)
    _check_partition(r, cost.shape)
    assert all(cost[i, j] <= max_cost for i, j in r.matches)
