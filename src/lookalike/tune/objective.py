"""What a choice maximises (:data:`CRITERIA`: combined over sequences, averaged over groups), and evaluating parameter
sets on sequences."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from operator import itemgetter
from typing import Any

from lookalike.eval import combine, headline
from lookalike.parallel import JobPool

Scores = dict[str, float]
Evaluator = Callable[[str, dict[str, Any], Any], Scores]


CRITERIA: dict[str, Callable[[Scores], float]] = {"hota+idf1+mota": headline, "hota": itemgetter("HOTA"),
                                                  "idf1": itemgetter("IDF1")}


def criterion(name: str) -> Callable[[Scores], float]:
    """The criterion called ``name`` (:data:`CRITERIA`); ``ValueError`` listing the known ones."""
    try:
        return CRITERIA[name.lower()]
    except KeyError:
        raise ValueError(f"metric: expected one of {', '.join(CRITERIA)}, got {name!r}") from None


def objective(per_sequence: Sequence[Scores], groups: Sequence[str], crit: Callable[[Scores], float]) -> float:
    """Mean over the groups of ``crit`` of the group's combined scores (one group: the combined criterion)."""
    if len(per_sequence) != len(groups) or not groups:
        raise ValueError("objective: need one group per sequence, at least one sequence")
    values = []
    for g in dict.fromkeys(groups):
        values.append(crit(combine([s for s, x in zip(per_sequence, groups) if x == g])))
    return sum(values) / len(values)


def evaluate_job(evaluator: Evaluator, tracker: str, params: dict[str, Any], seq: Any) -> dict[str, Any]:
    """``{"scores": ...}`` of ``evaluator(tracker, params, seq)``, or ``{"error": ...}`` when it fails."""
    try:
        return {"scores": evaluator(tracker, params, seq)}
    except Exception as exc:  # noqa: BLE001 - reported per trial
        return {"error": f"{type(exc).__name__}: {exc}"[:300]}


def evaluate_table(tracker: str, candidates: Sequence[dict[str, Any]], sequences: Sequence[Any], evaluator: Evaluator,
                   *, workers: int = 1, backend: str = "local", address: str | None = None,
                   progress: Callable[[int, int], None] | None = None) -> list[list[Scores | None]]:
    """``table[k][i]``: scores of candidate ``k`` on sequence ``i`` (None: failed), each a job on the pool."""
    total = len(candidates) * len(sequences)
    with JobPool(max(1, min(workers, total)), backend, address) as pool:
        shared = [pool.share(s) for s in sequences]
        pending = [[pool.submit(evaluate_job, evaluator, tracker, dict(p), s) for s in shared] for p in candidates]
        table: list[list[Scores | None]] = []
        done = 0
        for row in pending:
            out: list[Scores | None] = []
            for job in row:
                result = job.result()
                out.append(result.get("scores"))
                done += 1
                if progress is not None:
                    progress(done, total)
            table.append(out)
    return table


__all__ = ["CRITERIA", "Evaluator", "Scores", "criterion", "evaluate_job", "evaluate_table", "objective"]
