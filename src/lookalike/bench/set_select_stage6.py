"""The sixth stage's choice for the ``set`` identifier (issue 23): the report-exchange detector.

``python -m lookalike.bench.set_select RUN --stage 6`` scores the shipped weights and options with ``exchange_llr``
off and at each of :data:`STAGE6_EXCHANGE_LLR` on the third stage's tuning sequences and tuning recovery
(:func:`~lookalike.bench.set_select_stage4.score_candidates`; scores kept in ``RUN/set_select_stage6.json``) and
applies the fourth stage's rule against the candidate with the detector off, as written in
docs/experiments/any-team-size.md ("A sixth stage") before any candidate was scored.
"""

from __future__ import annotations

from pathlib import Path

from lookalike.bench.set_select_stage4 import print_choice, score_candidates
from lookalike.learn.set_tracker import SHIPPED_SET_WEIGHTS

STAGE6_EXCHANGE_LLR: tuple[float | None, ...] = (None, 6.0, 8.0, 12.0)
STAGE6_BASELINE = "exchange=off"


def stage6_candidates() -> dict[str, tuple[Path, dict[str, object]]]:
    """Candidate name (``exchange=off``, ``exchange=8.0``, ...) -> (the shipped weights, inference options)."""
    return {f"exchange={'off' if llr is None else llr}": (SHIPPED_SET_WEIGHTS, {"exchange_llr": llr})
            for llr in STAGE6_EXCHANGE_LLR}


def select_stage6(run_dir: Path, only: str | None = None) -> str | None:
    """Score the candidates (all, or ``only``), print them and the choice (None: nothing eligible); a chosen
    ``exchange_llr`` is made the identifier's default by hand."""
    return print_choice(score_candidates(stage6_candidates(), run_dir / "set_select_stage6.json", only),
                        STAGE6_BASELINE)
