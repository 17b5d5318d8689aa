"""``BoxCXCYWH``'s column form (every track's state and covariance blocks as one quantity-major
table) gives the same numbers as its full ``(k, 8)`` / ``(k, 8, 8)`` form, bit for bit, over chains
of predictions and updates; ``MotionFit.observe_columns`` equals ``observe_parts`` with ``b = 0``."""

from __future__ import annotations

import numpy as np
import pytest

from lookalike.motion.spaces import BoxCXCYWH, _blocks
from lookalike.trackers.parts.motion_fit import MotionFit


def to_columns(mean: np.ndarray, cov: np.ndarray) -> np.ndarray:
    """The column table ``(24, k)`` of states ``mean (k, 8)`` and full covariances ``cov (k, 8, 8)``."""
    p11, p12, p21, p22 = _blocks(np.ascontiguousarray(cov))
    return np.concatenate((mean.T, p11.T, p12.T, p21.T, p22.T))


def from_columns(columns: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """States ``(k, 8)`` and full covariances ``(k, 8, 8)`` of a column table ``(24, k)``."""
    cov = np.zeros((columns.shape[1], 8, 8))
    for b, view in enumerate(_blocks(cov)):
        view[...] = columns[8 + 4 * b: 12 + 4 * b].T
    return columns[:8].T.copy(), cov


def _boxes(rng: np.random.Generator, k: int) -> np.ndarray:
    """``(k, 4)`` centre/size boxes, some sizes below one pixel."""
    size = rng.uniform(0.3, 120.0, (k, 2))
    return np.column_stack([rng.uniform(-50, 900, (k, 2)), size])


@pytest.mark.parametrize("space", [BoxCXCYWH(1 / 20, 1 / 160), BoxCXCYWH(0.37, 0.09)])
def test_column_form_equals_the_full_form(space: BoxCXCYWH) -> None:
    rng = np.random.default_rng(0)
    z0 = _boxes(rng, 12)
    mean, cov = space.initial(z0)
    columns = space.initial_rows(z0).T.copy()
    assert np.array_equal(to_columns(mean, cov), columns)
    for steps in [1.0, 2.0, 1.0, 0.5, 0.0, 3.0, 1.0, 1.0, 2.5, 1.0]:
        mean[:, 4:] = rng.normal(0, 3, (12, 4))  # size velocities shrinking some boxes below 1 pixel
        columns[4:8] = mean[:, 4:].T
        mean, cov = space.predict(mean, cov, steps)
        space.predict_columns(columns, steps)
        m, c = from_columns(columns)
        assert np.array_equal(mean, m) and np.array_equal(cov, c), steps
        rows = np.flatnonzero(rng.random(12) < 0.7)
        z = _boxes(rng, len(rows))
        S = (space.H @ cov[rows] @ space.H.T) + space.R(z[:, 2:4])  # innovation covariances of the prior
        mean[rows], cov[rows] = space.update(mean[rows], cov[rows], z)
        sub = columns[:, rows]
        innovation, s = space.innovation_columns(sub, np.ascontiguousarray(z.T))
        assert np.array_equal(innovation, z.T - sub[:4])
        assert np.allclose(s, np.diagonal(S, axis1=1, axis2=2).T, rtol=1e-12, atol=0)
        space.correct_columns(sub, innovation, s)
        columns[:, rows] = sub
        m, c = from_columns(columns)
        assert np.array_equal(mean, m) and np.array_equal(cov, c), steps


@pytest.mark.parametrize("mixed", [False, True])
def test_column_nis_equals_the_general_form(mixed: bool) -> None:
    rng = np.random.default_rng(1)
    plain, fast = MotionFit(batch=25), MotionFit(batch=25)
    for step in range(60):
        k = int(rng.integers(0, 9))
        innovation = rng.normal(0, 20, (k, 2)) * (1 + step / 10)
        var = rng.uniform(0.1, 400, (k, 2))
        rows = None if rng.random() < 0.3 else rng.random(k) < 0.7
        kept = slice(None) if rows is None else rows
        plain.observe_parts(innovation[kept], var[kept, 0], np.zeros(len(var[kept])), var[kept, 1])
        if mixed and step % 3 == 0:  # the general form and columns in one batch
            fast.observe_parts(innovation[kept], var[kept, 0], np.zeros(len(var[kept])), var[kept, 1])
        else:
            fast.observe_columns(np.ascontiguousarray(innovation.T), np.ascontiguousarray(var.T), rows)
        assert plain.scale == fast.scale and plain._count == fast._count
    assert plain.scale > 1.0


def test_median_equals_numpys() -> None:
    from lookalike.trackers.parts.motion_fit import _median

    rng = np.random.default_rng(2)
    for n in range(1, 80):
        values = rng.chisquare(2, n) * rng.choice([1e-3, 1.0, 1e3])
        if n % 7 == 0:
            values[rng.integers(0, n, 2)] = values[0]  # ties
        assert _median(values) == float(np.median(values))
    assert np.isnan(_median(np.array([1.0, np.nan, 2.0])))
