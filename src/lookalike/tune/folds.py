"""Cross-validation folds over sequences: leave one sequence (or group) out, or K folds."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass


@dataclass(frozen=True)
class Fold:
    """Indices of the sequences a choice is made on (``train``) and scored on (``test``)."""

    name: str
    train: tuple[int, ...]
    test: tuple[int, ...]


def leave_one_group_out(groups: Sequence[str]) -> list[Fold]:
    """One fold per group ``groups[i]`` of sequence ``i`` (first-seen order; at least two), its sequences left out."""
    names = list(dict.fromkeys(groups))
    if len(names) < 2:
        raise ValueError(f"folds: leaving one out needs at least two sequences/groups, got {len(names)}")
    return [Fold(g, tuple(i for i, x in enumerate(groups) if x != g), tuple(i for i, x in enumerate(groups) if x == g))
            for g in names]


def k_folds(names: Sequence[str], k: int) -> list[Fold]:
    """``k`` folds over the sequences ``names``: sequence ``i`` is left out in fold ``i mod k``."""
    if not 2 <= k <= len(names):
        raise ValueError(f"folds: K must be between 2 and the number of sequences ({len(names)}), got {k}")
    out = []
    for f in range(k):
        test = tuple(i for i in range(len(names)) if i % k == f)
        out.append(Fold("+".join(names[i] for i in test), tuple(i for i in range(len(names)) if i % k != f), test))
    return out


def make_folds(names: Sequence[str], spec: str | int, groups: Sequence[str] | None = None) -> list[Fold]:
    """Folds from ``"loso"`` (one per sequence), ``"lodo"`` (one per group) or K (:func:`k_folds`)."""
    text = str(spec).strip().lower()
    if text == "loso":
        return leave_one_group_out(list(names))
    if text == "lodo":
        if groups is None:
            raise ValueError("folds: 'lodo' needs the sequences' datasets")
        return leave_one_group_out(list(groups))
    try:
        k = int(text)
    except ValueError:
        raise ValueError(f"folds: expected 'loso', 'lodo' or a number K, got {spec!r}") from None
    return k_folds(list(names), k)


__all__ = ["Fold", "k_folds", "leave_one_group_out", "make_folds"]
