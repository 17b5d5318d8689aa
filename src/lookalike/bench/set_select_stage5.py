"""The fifth stage's choice for the ``set`` identifier (issue 23): the false-positive prior correction.

``python -m lookalike.bench.set_select RUN --stage 5`` scores the shipped weights with ``fp_prior_ref`` off and
at each of :data:`STAGE5_FP_PRIOR` (the other inference options at their defaults) on the third stage's tuning
sequences and tuning recovery (:func:`~lookalike.bench.set_select_stage4.score_candidates`; scores kept in
``RUN/set_select_stage5.json``) and applies the fourth stage's rule
(:func:`~lookalike.bench.set_select_stage4.choose_stage4`) against the candidate with the correction off, as
written in docs/experiments/any-team-size.md ("A fifth stage") before any candidate was scored.
"""

from __future__ import annotations

from pathlib import Path

from lookalike.bench.set_select_stage4 import print_choice, score_candidates
from lookalike.learn.set_tracker import SHIPPED_SET_WEIGHTS

STAGE5_FP_PRIOR: tuple[float | None, ...] = (None, 0.7, 1.0, 1.4)
STAGE5_BASELINE = "fp_prior=off"


def stage5_candidates() -> dict[str, tuple[Path, dict[str, object]]]:
    """Candidate name (``fp_prior=off``, ``fp_prior=1.0``, ...) -> (the shipped weights, inference options)."""
    return {f"fp_prior={'off' if ref is None else ref}": (SHIPPED_SET_WEIGHTS, {"fp_prior_ref": ref})
            for ref in STAGE5_FP_PRIOR}


def select_stage5(run_dir: Path, only: str | None = None) -> str | None:
    """Score the candidates (all, or ``only``), print them and the choice (None: nothing eligible); a chosen
    ``fp_prior_ref`` is made the identifier's default by hand."""
    return print_choice(score_candidates(stage5_candidates(), run_dir / "set_select_stage5.json", only),
                        STAGE5_BASELINE)
