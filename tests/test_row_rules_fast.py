"""``row_problem``'s whole-table shortcut gives the row-by-row answer: None exactly when no row breaks a rule."""

from __future__ import annotations

import numpy as np
import pytest

from lookalike.io import motchallenge
from lookalike.io.motchallenge import row_problem


def _careful(data: np.ndarray, **kw: object) -> tuple[int, str] | None:
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(motchallenge, "_rows_fine", lambda *a: False)
        return row_problem(data, **kw)  # type: ignore[arg-type]


def _table(rng: np.random.Generator, n: int) -> np.ndarray:
    data = np.column_stack([np.sort(rng.integers(1, 50, n)), rng.integers(1, 9, n), rng.uniform(-50, 500, (n, 2)),
                            rng.uniform(0.5, 80, (n, 2)), rng.uniform(0, 1, n), -np.ones((n, 3))]).astype(float)
    return data


BREAKS = [
    lambda d: d.__setitem__((3, 2), np.nan), lambda d: d.__setitem__((5, 6), np.inf),
    lambda d: d.__setitem__((2, 1), -np.inf), lambda d: d.__setitem__((7, 4), -1.0),
    lambda d: d.__setitem__((7, 5), 0.0), lambda d: d.__setitem__((4, 0), 2.5), lambda d: d.__setitem__((4, 0), 0.0),
    lambda d: d.__setitem__((9, 0), np.nan), lambda d: d.__setitem__((9, 0), 1e9),
    lambda d: d.__setitem__((1, 0), 60.0), lambda d: d.__setitem__((slice(None), 3), -1e308),
    lambda d: d.__setitem__((slice(None), 2), 1e308),  # sums overflow to infinity: the careful path decides
    lambda d: None,
]


@pytest.mark.parametrize("brk", range(len(BREAKS)))
@pytest.mark.parametrize("kw", [{}, {"positive_size": True}, {"length": 55}, {"length": 49}, {"previous_max": 20.0},
                                {"previous_max": 2e4}])
def test_shortcut_agrees_with_row_checks(brk: int, kw: dict[str, object]) -> None:
    for seed in range(3):
        data = _table(np.random.default_rng(seed), 30)
        BREAKS[brk](data)
        assert row_problem(data, **kw) == _careful(data, **kw)  # type: ignore[arg-type]
