"""The sixth to ninth stages' choices for the ``set`` identifier (issue 23): the report-exchange detector.

``python -m lookalike.bench.set_select RUN --stage 6`` (7, 8) scores the shipped weights and options with
``exchange_llr`` off and at each of the stage's thresholds (stage 6: :data:`STAGE6_EXCHANGE_LLR` without the
evidence's decay; stage 7: :data:`STAGE7_EXCHANGE_LLR` with ``exchange_memory_s`` 1 s; stage 8:
:data:`STAGE8_EXCHANGE_LLR` with that and ``exchange_fresh_s`` 0.6 s) on the third stage's tuning
sequences and tuning recovery (:func:`~lookalike.bench.set_select_stage4.score_candidates`; scores kept in
``RUN/set_select_stage<k>.json``) and applies the fourth stage's rule against the candidate with the detector
off (stage 9: :func:`stage9_candidates`), as written in docs/experiments/any-team-size.md before any of the
stage's candidates was scored.
"""

from __future__ import annotations

from pathlib import Path

from lookalike.bench.set_select_stage4 import print_choice, score_candidates
from lookalike.learn.set_tracker import SHIPPED_SET_WEIGHTS

STAGE6_EXCHANGE_LLR: tuple[float | None, ...] = (None, 6.0, 8.0, 12.0)
STAGE7_EXCHANGE_LLR: tuple[float | None, ...] = (None, 6.0, 8.0, 10.0)
STAGE8_EXCHANGE_LLR: tuple[float | None, ...] = (None, 8.0, 10.0, 12.0)
EXCHANGE_BASELINE = "exchange=off"
# Per stage: the thresholds, exchange_memory_s and exchange_fresh_s of its candidates.
_STAGES: dict[int, tuple[tuple[float | None, ...], float | None, float | None]] = {
    6: (STAGE6_EXCHANGE_LLR, None, None), 7: (STAGE7_EXCHANGE_LLR, 1.0, None), 8: (STAGE8_EXCHANGE_LLR, 1.0, 0.6)}


def exchange_candidates(stage: int) -> dict[str, tuple[Path, dict[str, object]]]:
    """Stage 6, 7 or 8's candidates: name (``exchange=off``, ``exchange=8.0``, ...) -> (the shipped weights,
    inference options)."""
    thresholds, memory_s, fresh_s = _STAGES[stage]
    return {f"exchange={'off' if llr is None else llr}":
            (SHIPPED_SET_WEIGHTS, {"exchange_llr": llr, "exchange_memory_s": memory_s, "exchange_fresh_s": fresh_s})
            for llr in thresholds}


def stage9_candidates() -> dict[str, tuple[Path, dict[str, object]]]:
    """The ninth stage's candidates: the detector off, or at 8 for teams of up to seven agents."""
    return {EXCHANGE_BASELINE: (SHIPPED_SET_WEIGHTS, {"exchange_llr": None}),
            "exchange=8.0,max_agents=7": (SHIPPED_SET_WEIGHTS, {"exchange_llr": 8.0, "exchange_memory_s": 1.0,
                                                                "exchange_fresh_s": 0.6, "exchange_max_agents": 7})}


def select_exchange(run_dir: Path, stage: int, only: str | None = None) -> str | None:
    """Score stage ``stage``'s candidates (all, or ``only``), print them and the choice (None: nothing eligible);
    a chosen ``exchange_llr`` is made the identifier's default by hand."""
    candidates = stage9_candidates() if stage == 9 else exchange_candidates(stage)
    rows = score_candidates(candidates, run_dir / f"set_select_stage{stage}.json", only)
    return print_choice(rows, EXCHANGE_BASELINE)
