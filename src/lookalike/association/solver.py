"""The assignment solver contract (scipy's ``linear_sum_assignment`` behind it): rows matched to columns, pairs costing
``inf`` or more than ``max_cost`` forbidden; rectangular, empty and all-forbidden matrices are legal."""

from __future__ import annotations

import math
from collections.abc import Iterator
from dataclasses import dataclass

import numpy as np


def linear_sum_assignment(cost: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """scipy's solver, loaded on first use without importing ``scipy.optimize`` (:mod:`lookalike._lsap`)."""
    from lookalike._lsap import linear_sum_assignment as solve

    rows, cols = solve(cost)
    return rows, cols


@dataclass(frozen=True)
class Assignment:
    """Result of an assignment.

    Attributes:
        matches: ``(k, 2)`` int array of ``(row, col)`` pairs, sorted by row.
        unmatched_rows: ``(r,)`` sorted row indices without a match.
        unmatched_cols: ``(c,)`` sorted column indices without a match."""

    matches: np.ndarray
    unmatched_rows: np.ndarray
    unmatched_cols: np.ndarray

    def __iter__(self) -> Iterator[np.ndarray]:  # allows ``matches, rows, cols = assign(...)``
        return iter((self.matches, self.unmatched_rows, self.unmatched_cols))


def _result(rows: np.ndarray, cols: np.ndarray, shape: tuple[int, int]) -> Assignment:
    """The assignment of pairs ``(rows, cols)`` already sorted by row."""
    matches = np.empty((len(rows), 2), dtype=int)
    matches[:, 0] = rows
    matches[:, 1] = cols
    free_rows = np.ones(shape[0], dtype=bool)
    free_rows[rows] = False
    free_cols = np.ones(shape[1], dtype=bool)
    free_cols[cols] = False
    return Assignment(matches=matches, unmatched_rows=np.flatnonzero(free_rows),
                      unmatched_cols=np.flatnonzero(free_cols))


def _check(cost: np.ndarray) -> np.ndarray:
    c = np.asarray(cost, dtype=float)
    if c.ndim != 2:
        raise ValueError(f"cost: expected a 2-D matrix, got shape {c.shape}")
    if c.size and np.count_nonzero(c > -np.inf) != c.size:  # one pass for both NaN and -inf
        if np.isnan(c).any():
            row, col = np.argwhere(np.isnan(c))[0]
            raise ValueError(f"cost: NaN at row {row}, column {col}; use inf to forbid a pair")
        row, col = np.argwhere(np.isneginf(c))[0]
        raise ValueError(f"cost: -inf at row {row}, column {col}")
    return c


def assign(cost: np.ndarray, max_cost: float = np.inf) -> Assignment:
    """Minimum-cost assignment where pairs costing more than ``max_cost`` (or ``inf``) are forbidden. With a finite
    ``max_cost`` an unmatched row costs as much as a pair at ``max_cost`` (deep SORT's convention); with ``inf`` the
    number of allowed pairs is maximised first."""
    c = _check(cost)
    rows, cols = _solve(c, max_cost)
    return _result(rows, cols, c.shape)


def assign_pairs(cost: np.ndarray, max_cost: float = np.inf) -> np.ndarray:
    """The matched ``(row, col)`` pairs of :func:`assign` alone, ``(k, 2)`` sorted by row."""
    rows, cols = _solve(_check(cost), max_cost)
    matches = np.empty((len(rows), 2), dtype=int)
    matches[:, 0] = rows
    matches[:, 1] = cols
    return matches


_NONE = np.zeros(0, dtype=int)
_NONE.flags.writeable = False  # shared by every empty result


def _solve(c: np.ndarray, max_cost: float) -> tuple[np.ndarray, np.ndarray]:
    none = _NONE
    if c.size == 0:
        return none, none
    finite = math.isfinite(max_cost)
    allowed = c <= max_cost if finite else c < np.inf
    rows, cols = allowed.nonzero()
    if not len(rows):
        return none, none
    if len(set(rows.tolist())) == len(rows) and len(set(cols.tolist())) == len(cols):
        return rows, cols  # disjoint allowed pairs: every optimum holds all of them
    return solve_allowed(c, allowed, max_cost)


def solve_allowed(c: np.ndarray, allowed: np.ndarray, max_cost: float) -> tuple[np.ndarray, np.ndarray]:
    """The minimum-cost matching of ``c`` over the ``allowed`` pairs (at least one), forbidden pairs dropped."""
    if math.isfinite(max_cost):
        # Clip forbidden pairs to just above the limit; they are dropped after solving.
        scale = max(abs(max_cost - float(c[allowed].min())), 1.0)
        work = np.where(allowed, c, max_cost + 1e-6 * scale)
        # Rescale when values are so large that sums could overflow.
        big = max(abs(float(work.max())), abs(float(work.min())))
        if big * min(c.shape) > 1e300:
            work = work / big
    else:
        low = float(c[allowed].min())
        work = np.where(allowed, c - low, 0.0)
        top = float(work.max())
        if top > 0 and top * min(c.shape) > 1e290:
            work = work / top
            top = 1.0
        penalty = (top + 1.0) * (min(c.shape) + 1)
        work = np.where(allowed, work, penalty)
    rows, cols = linear_sum_assignment(work)
    keep = allowed[rows, cols]
    return rows[keep], cols[keep]


def max_weight_complete(weight: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Rows and columns of a maximum-weight complete matching (no gating; SORT's "solve then gate")."""
    w = _check(weight)
    if w.size == 0:
        return np.zeros(0, int), np.zeros(0, int)
    rows, cols = linear_sum_assignment(-w)
    return np.asarray(rows), np.asarray(cols)
