"""Frame matrices built many at a time in one reused buffer equal the per-frame ``-dense`` matrices bit for bit."""

from __future__ import annotations

import numpy as np
import pytest

from lookalike.eval import matching
from lookalike.eval.matching import negated_matrices, solve_matrices


def _frames(rng: np.random.Generator, k: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    shapes = rng.integers(1, 9, (k, 2))
    block, rows, cols, values = [], [], [], []
    for m, (n_r, n_c) in enumerate(shapes):
        cells = rng.choice(n_r * n_c, rng.integers(0, n_r * n_c + 1), replace=False)
        cells.sort()
        block += [m] * len(cells)
        rows += (cells // n_c).tolist()
        cols += (cells % n_c).tolist()
        values += rng.uniform(0.01, 1, len(cells)).tolist()
    return shapes, np.array(block, np.int64), np.array(rows, np.int64), np.array(cols, np.int64), np.array(values)


@pytest.mark.parametrize("chunk", [1, 7, 64, 1 << 15])
def test_matrices_equal_negated_dense(monkeypatch: pytest.MonkeyPatch, chunk: int) -> None:
    monkeypatch.setattr(matching, "_CHUNK", chunk)  # runs of matrices split anywhere, or one matrix per run
    shapes, block, rows, cols, values = _frames(np.random.default_rng(chunk), 40)
    got = [m.copy() for m in negated_matrices(shapes, block, rows, cols, values)]
    assert len(got) == len(shapes)
    for m, (n_r, n_c) in enumerate(shapes):
        dense = np.zeros((n_r, n_c))
        at = block == m
        dense[rows[at], cols[at]] = values[at]
        expected = -dense  # zeros become -0.0
        assert got[m].shape == (n_r, n_c)
        assert np.array_equal(got[m].view(np.int64), expected.view(np.int64))


def test_solve_matrices_matches_per_matrix_solves() -> None:
    from scipy.optimize import linear_sum_assignment

    shapes, block, rows, cols, values = _frames(np.random.default_rng(5), 25)
    r_all, c_all, counts = solve_matrices(negated_matrices(shapes, block, rows, cols, values))
    at = 0
    for m, (n_r, n_c) in enumerate(shapes):
        dense = np.zeros((n_r, n_c))
        sel = block == m
        dense[rows[sel], cols[sel]] = values[sel]
        r, c = linear_sum_assignment(-dense)
        assert counts[m] == len(r)
        assert np.array_equal(r_all[at:at + len(r)], r) and np.array_equal(c_all[at:at + len(c)], c)
        at += len(r)
    empty = solve_matrices(negated_matrices(np.zeros((0, 2), np.int64), *(np.zeros(0, np.int64),) * 3, np.zeros(0)))
    assert all(len(x) == 0 for x in empty)
