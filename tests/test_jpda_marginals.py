"""JPDA marginals equal a brute-force sum over all joint events."""

from __future__ import annotations

import itertools

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from lookalike.association.jpda import jpda_marginals


def _brute(L: np.ndarray, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    k, m = L.shape
    beta, miss, total = np.zeros((k, m)), np.zeros(k), 0.0
    for event in itertools.product(range(-1, m), repeat=k):
        used = [j for j in event if j >= 0]
        if len(used) != len(set(used)):
            continue
        w = np.prod([q[i] if j < 0 else L[i, j] for i, j in enumerate(event)])
        total += w
        for i, j in enumerate(event):
            if j < 0:
                miss[i] += w
            else:
                beta[i, j] += w
    return beta / total, miss / total


@st.composite
def cases(draw):
    k, m = draw(st.integers(0, 4)), draw(st.integers(0, 5))
    seed = draw(st.integers(0, 2**31))
    rng = np.random.default_rng(seed)
    L = rng.exponential(1.0, (k, m)) * 10 ** rng.uniform(-3, 3, (k, 1))
    L[rng.random((k, m)) < draw(st.floats(0, 0.8))] = 0.0  # outside the gate
    q = rng.uniform(0.01, 1.0, k)
    return L, q


@settings(max_examples=150, deadline=None)
@given(cases())
def test_enumeration_equals_brute_force(case):
    L, q = case
    beta, miss = jpda_marginals(L, q)
    if L.shape[0]:
        b, b0 = _brute(L, q)
        np.testing.assert_allclose(beta, b, atol=1e-10)
        np.testing.assert_allclose(miss, b0, atol=1e-10)
    np.testing.assert_allclose(beta.sum(axis=1) + miss, 1.0)


@settings(max_examples=80, deadline=None)
@given(cases())
def test_subset_dp_equals_brute_force(case):
    L, q = case
    beta, miss = jpda_marginals(L, q, max_events=0)  # force the dynamic programme
    if L.shape[0]:
        b, b0 = _brute(L, q)
        np.testing.assert_allclose(beta, b, atol=1e-10)
        np.testing.assert_allclose(miss, b0, atol=1e-10)


def test_independent_clusters_and_single_track():
    L = np.array([[2.0, 0.0], [0.0, 3.0]])
    q = np.array([1.0, 1.0])
    beta, miss = jpda_marginals(L, q)
    np.testing.assert_allclose(beta, [[2 / 3, 0], [0, 3 / 4]])
    np.testing.assert_allclose(miss, [1 / 3, 1 / 4])


def test_large_cluster_uses_exact_dp():
    rng = np.random.default_rng(0)
    L = rng.exponential(1.0, (5, 7))
    q = np.full(5, 0.1)
    beta, miss = jpda_marginals(L, q, max_events=100)
    b, b0 = jpda_marginals(L, q, max_events=10**8)
    np.testing.assert_allclose(beta, b, atol=1e-12)
    np.testing.assert_allclose(miss, b0, atol=1e-12)


def test_bad_input():
    with pytest.raises(ValueError, match="likelihood"):
        jpda_marginals(np.array([[-1.0]]), np.array([1.0]))
    with pytest.raises(ValueError, match="miss"):
        jpda_marginals(np.ones((2, 2)), np.ones(3))
