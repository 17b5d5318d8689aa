"""Which parameters earn their place: per fold, the best of the defaults and the defaults with one parameter moved over
its range, chosen on the training sequences, against the defaults on the left-out ones."""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

from lookalike.trackers.registry import tracker_parameters
from lookalike.tune.folds import Fold
from lookalike.tune.objective import Scores, criterion, objective
from lookalike.tune.selection import select_from_table
from lookalike.tune.space import Space, grid, searched

INERT_POINTS = 0.05  # a parameter whose whole range moves no fold's training objective more than this is inert


def _same(a: Any, b: Any) -> bool:
    if isinstance(a, (int, float)) and isinstance(b, (int, float)) and not isinstance(a, bool):
        return math.isclose(a, b, rel_tol=1e-6, abs_tol=1e-12)
    return a == b and type(a) is type(b)


def one_at_a_time(tracker: str, space: Space, points: int = 5) -> tuple[list[dict[str, Any]], dict[str, list[int]]]:
    """``(candidates, by_parameter)``: 0 is the defaults; ``by_parameter[name]``: those moving only ``name``."""
    defaults = {p.name: p.default for p in tracker_parameters(tracker)}
    candidates: list[dict[str, Any]] = [{}]
    by_parameter: dict[str, list[int]] = {}
    for name, dim in searched(space).items():
        by_parameter[name] = []
        for value in grid(dim, points):
            if _same(value, defaults.get(name)):
                continue
            by_parameter[name].append(len(candidates))
            candidates.append({name: value})
    return candidates, by_parameter


@dataclass(frozen=True)
class ParameterGain:
    """Left-out ``gains`` per fold of tuning parameter ``name`` over the defaults (criterion points), their ``mean``,
    ``sd`` and ``se``; ``spread``: the largest change its range makes to a training objective; ``chosen`` per fold;
    ``verdict``: ``"keep"`` (mean > 2 se), ``"drop"`` (spread < :data:`INERT_POINTS`) or ``"fix"``."""

    name: str
    gains: list[float]
    mean: float
    sd: float
    se: float
    spread: float
    chosen: list[Any]
    verdict: str


def parameter_gains(table: Sequence[Sequence[Scores | None]], candidates: Sequence[dict[str, Any]],
                    by_parameter: dict[str, list[int]], folds: Sequence[Fold], keys: Sequence[str],
                    groups: Sequence[str] | None = None, metric: str = "hota+idf1+mota") -> list[ParameterGain]:
    """:class:`ParameterGain` of every parameter from a table of :func:`one_at_a_time` candidates."""
    crit = criterion(metric)
    groups = list(keys) if groups is None else list(groups)
    base = select_from_table(table, folds, keys, groups, metric, candidates, allowed=[0])
    out = []
    for name, idx in by_parameter.items():
        tuned = select_from_table(table, folds, keys, groups, metric, candidates, allowed=[0, *idx])
        gains = [100 * (t.test_value - b.test_value) for t, b in zip(tuned, base)]
        n = len(gains)
        mean = sum(gains) / n
        sd = math.sqrt(sum((g - mean) ** 2 for g in gains) / (n - 1)) if n > 1 else 0.0
        se = sd / math.sqrt(n) if n > 1 else 0.0
        spread = 0.0
        for fold in folds:
            train = list(fold.train)
            ref = objective([table[0][j] for j in train], [groups[j] for j in train], crit)  # type: ignore[misc]
            for k in idx:
                if all(table[k][j] is not None for j in train):
                    v = objective([table[k][j] for j in train], [groups[j] for j in train], crit)  # type: ignore[misc]
                    spread = max(spread, 100 * abs(v - ref))
        verdict = "drop" if spread < INERT_POINTS else "keep" if mean > 2 * se and mean > 0 else "fix"
        chosen = ["default" if t.candidate == 0 else candidates[t.candidate][name] for t in tuned]
        out.append(ParameterGain(name, gains, mean, sd, se, spread, chosen, verdict))
    return out


__all__ = ["INERT_POINTS", "ParameterGain", "one_at_a_time", "parameter_gains"]
