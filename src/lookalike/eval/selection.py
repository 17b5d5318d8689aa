"""Parameter choice that never sees what it is scored on: leave one sequence out."""

from __future__ import annotations

from collections.abc import Callable, Sequence

from lookalike.eval.api import combine


def headline(scores: dict[str, float]) -> float:
    """HOTA + IDF1 + MOTA: the criterion lookalike's benchmarks choose parameters by; ``ValueError`` naming a missing
    one."""
    try:
        return scores["HOTA"] + scores["IDF1"] + scores["MOTA"]
    except KeyError as exc:
        raise ValueError(f"scores: lacks {exc.args[0]!r} (headline needs HOTA, IDF1 and MOTA)") from None


def leave_one_out(scores: Sequence[Sequence[dict[str, float]]],
                  criterion: Callable[[dict[str, float]], float] = headline) -> tuple[dict[str, float], list[int]]:
    """Left-out scores combined, and per sequence ``i`` the candidate ``k`` chosen by ``criterion`` over the *other*
    sequences (first on ties); ``scores[k][i]``: candidate ``k``'s :func:`combine`-able result on sequence ``i``."""
    if not scores or not scores[0]:
        raise ValueError("scores: need at least one candidate and one sequence")
    n = len(scores[0])
    if any(len(row) != n for row in scores):
        raise ValueError("scores: every candidate needs a result on every sequence")
    if n < 2:
        raise ValueError("scores: leaving one sequence out needs at least two sequences")
    held, chosen = [], []
    for i in range(n):
        others = [j for j in range(n) if j != i]
        best = max(range(len(scores)), key=lambda k: (criterion(combine([scores[k][j] for j in others])), -k))
        held.append(scores[best][i])
        chosen.append(best)
    return combine(held), chosen
