"""The left-out score of the whole selection procedure: a study per fold (:func:`leave_one_out_selection`) or an argmax
per fold over stored scores of every candidate (:func:`select_from_table`), scored on the left-out sequences."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

from lookalike.eval import combine
from lookalike.tune.data import score_params, sequence_key
from lookalike.tune.folds import Fold, make_folds
from lookalike.tune.objective import Evaluator, Scores, criterion, evaluate_job, objective
from lookalike.tune.space import Space
from lookalike.tune.study import run_study


@dataclass(frozen=True)
class FoldChoice:
    """One fold: ``params`` (``candidate``'s index in a table, -1 for a study) chosen on ``chosen_on`` with objective
    ``train_value``, scored on ``left_out``: combined ``test_scores``, their criterion ``test_value``, and
    ``per_sequence``."""

    fold: str
    chosen_on: list[str]
    left_out: list[str]
    params: dict[str, Any]
    candidate: int
    train_value: float
    test_scores: Scores
    test_value: float
    per_sequence: list[Scores]


def _valid(row: Sequence[Scores | None], idx: Sequence[int]) -> bool:
    return all(row[i] is not None for i in idx)


def select_from_table(table: Sequence[Sequence[Scores | None]], folds: Sequence[Fold], keys: Sequence[str],
                      groups: Sequence[str] | None = None, metric: str = "hota+idf1+mota",
                      candidates: Sequence[dict[str, Any]] | None = None,
                      allowed: Sequence[int] | None = None) -> list[FoldChoice]:
    """Per fold, the ``allowed`` candidate (default all; first on ties; none that failed) with the best objective on
    the training sequences, scored on the left-out ones; ``table[k][i]``: candidate ``k`` on sequence ``i``."""
    crit = criterion(metric)
    groups = list(keys) if groups is None else list(groups)
    pool = list(range(len(table))) if allowed is None else list(allowed)
    out = []
    for fold in folds:
        train = list(fold.train)
        usable = [k for k in pool if _valid(table[k], train) and _valid(table[k], fold.test)]
        if not usable:
            raise ValueError(f"fold {fold.name}: no candidate has scores on every sequence")
        values = {k: objective([table[k][j] for j in train], [groups[j] for j in train], crit)  # type: ignore[misc]
                  for k in usable}
        best = max(usable, key=lambda k: (values[k], -k))
        held = [table[best][i] for i in fold.test]
        combined = combine(held)  # type: ignore[arg-type]
        out.append(FoldChoice(fold.name, [keys[j] for j in train], [keys[i] for i in fold.test],
                              dict(candidates[best]) if candidates is not None else {}, best, values[best],
                              combined, crit(combined), held))  # type: ignore[arg-type]
    return out


def leave_one_out_selection(tracker: str, sequences: Sequence[Any], *, folds: str | int | Sequence[Fold] = "loso",
                            space: Space | None = None, trials: int = 30, sampler: str = "tpe", seed: int = 0,
                            metric: str = "hota+idf1+mota", groups: Sequence[str] | None = None,
                            keys: Sequence[str] | None = None, storage: str | None = None,
                            study_name: str | None = None, resume: bool = False, workers: int = 1,
                            backend: str = "local", address: str | None = None, evaluator: Evaluator = score_params,
                            progress: Callable[[str, int, int, float | None], None] | None = None
                            ) -> list[FoldChoice]:
    """Per fold (``"loso"``, ``"lodo"``, K or :class:`~lookalike.tune.folds.Fold` objects), a
    :func:`~lookalike.tune.study.run_study` (``<study_name or tracker>/<fold>``) on the other sequences, its choice
    scored on the left-out ones."""
    keys = [sequence_key(s) for s in sequences] if keys is None else list(keys)
    groups = [str(getattr(s, "dataset", "")) for s in sequences] if groups is None else list(groups)
    fold_list = make_folds(keys, folds, groups) if isinstance(folds, (str, int)) else list(folds)
    crit = criterion(metric)
    out = []
    for fold in fold_list:
        train = list(fold.train)

        def report(done: int, total: int, best: float | None, _name: str = fold.name) -> None:
            if progress is not None:
                progress(_name, done, total, best)

        result = run_study(tracker, [sequences[j] for j in train], space=space, trials=trials, sampler=sampler,
                           seed=seed, metric=metric, groups=[groups[j] for j in train], keys=[keys[j] for j in train],
                           storage=storage, study_name=f"{study_name or tracker}/{fold.name}", resume=resume,
                           workers=workers, backend=backend, address=address, evaluator=evaluator, progress=report)
        held = []
        for i in fold.test:
            r = evaluate_job(evaluator, tracker, result.params, sequences[i])
            if "error" in r:
                raise ValueError(f"fold {fold.name}: the chosen parameters failed on {keys[i]}: {r['error']}")
            held.append(r["scores"])
        combined = combine(held)
        out.append(FoldChoice(fold.name, [keys[j] for j in train], [keys[i] for i in fold.test], result.params, -1,
                              result.value, combined, crit(combined), held))
    return out


def combined_left_out(choices: Sequence[FoldChoice]) -> Scores:
    """The left-out scores of every fold combined (each sequence left out once: the whole set)."""
    return combine([s for c in choices for s in c.per_sequence])


__all__ = ["FoldChoice", "combined_left_out", "leave_one_out_selection", "select_from_table"]
