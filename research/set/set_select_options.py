"""The fifth to twentieth stages' choices for the ``set`` identifier (issue 23): inference options of the shipped
weights, each stage scored against its candidate with the option off.

``python research/set/set_select.py RUN --stage K`` (K = 5 … 10, 12 … 20) scores stage K's candidates
(:func:`stage_candidates`) on the third stage's tuning sequences and tuning recovery
(:func:`~set_select_stage4.score_candidates`; scores kept in ``RUN/set_select_stage<K>.json``)
and applies the fourth stage's rule against the stage's baseline, as written in
docs/experiments/any-team-size.md before any of the stage's candidates was scored:

- stage 5: the false-positive prior ``fp_prior_ref`` at each of :data:`STAGE5_FP_PRIOR`;
- stages 6-8: the report-exchange detector ``exchange_llr`` (6: :data:`STAGE6_EXCHANGE_LLR` without the
  evidence's decay; 7: :data:`STAGE7_EXCHANGE_LLR` with ``exchange_memory_s`` 1 s; 8: :data:`STAGE8_EXCHANGE_LLR`
  with that and ``exchange_fresh_s`` 0.6 s);
- stage 9: the detector at 8 for teams of up to seven agents (``exchange_max_agents``);
- stage 10: pairing two report jumps that mirror each other (``jump_pair_s`` at each of :data:`STAGE10_JUMP_PAIR`);
- stage 12: the exchange detector's heading model (``exchange_accel``, ``exchange_lag_s`` at each of
  :data:`STAGE12_EXCHANGE_MOTION`); its rule keeps only the fourth stage's guard on the tuning sequences
  (:func:`passes_guard`) and chooses on a development sample (``research/set/recovery_sample.py``);
- stage 13: the same with the tighter heading model and a step gate (``exchange_step_rad`` at each of
  :data:`STAGE13_EXCHANGE_STEP`), the same rule;
- stage 14: the tighter heading model for teams of at least :data:`STAGE14_TIGHT_AGENTS` agents only
  (``exchange_tight_agents``), the same rule;
- stage 15: pairing a report jump with another agent's first report after a silence (``jump_silent``), alone and
  with the exchange detector keeping silent tracks (``exchange_fresh_s`` off), the same rule.
- stage 16: trains: the snapshots of ``python research/set/set_finetune.py RUN --stage 16`` (swaps that end in
  a silence) at multiples of :data:`STAGE16_EVERY` steps, with the shipped inference options, the same rule.
- stage 17: exchanging two agents whose detections' visual headings, gathered over seconds, fit each other's reports
  (``visual_exchange`` at each of :data:`STAGE17_VISUAL`, ``visual_memory_s`` :data:`STAGE17_MEMORY_S`), the same rule.
- stage 18: that detector counting silent agents' older reports too, their noise widened (``visual_stale_rad_s`` at
  each of :data:`STAGE18_STALE`), the same rule.
- stage 19: a pair exchanged within the last :data:`STAGE19_UNDO_S` seconds exchanged again on less evidence
  (``undo_factor`` at each of :data:`STAGE19_UNDO`), the same rule; scored at a1eef66, before an agent's newer
  exchange ended the undo of its older one. Stage 20: the same candidates with that, judged on a new development
  sample.

A chosen option is made the identifier's default by hand.
"""

from __future__ import annotations

from pathlib import Path

from set_select import snapshot_steps
from set_select_stage4 import passes_guard, print_choice, score_candidates

from lookalike.trackers.set.network import SHIPPED_SET_WEIGHTS

Candidates = dict[str, tuple[Path, dict[str, object]]]  # name -> (weights, inference options)

STAGE5_FP_PRIOR: tuple[float | None, ...] = (None, 0.7, 1.0, 1.4)
STAGE5_BASELINE = "fp_prior=off"
STAGE6_EXCHANGE_LLR: tuple[float | None, ...] = (None, 6.0, 8.0, 12.0)
STAGE7_EXCHANGE_LLR: tuple[float | None, ...] = (None, 6.0, 8.0, 10.0)
STAGE8_EXCHANGE_LLR: tuple[float | None, ...] = (None, 8.0, 10.0, 12.0)
EXCHANGE_BASELINE = "exchange=off"
STAGE10_JUMP_PAIR: tuple[float | None, ...] = (None, 1.0)
STAGE10_BASELINE = "jump_pair=off"
# Stage 12: (exchange_accel rad^2/s^3, exchange_lag_s s); the first is the shipped detector's.
STAGE12_EXCHANGE_MOTION: tuple[tuple[float, float], ...] = ((0.1, 0.4), (0.03, 0.3), (0.05, 0.2), (0.03, 0.2))
STAGE12_BASELINE = "exchange_motion=0.1/0.4"
# Stage 13: exchange_step_rad (rad) with exchange_accel 0.03 rad^2/s^3 and exchange_lag_s 0.3 s, against the shipped.
STAGE13_EXCHANGE_STEP: tuple[float, ...] = (0.08, 0.12)
STAGE13_BASELINE = "shipped"
STAGE14_TIGHT_AGENTS = 5  # exchange_tight_agents: teams of 5-7 agents use exchange_accel 0.03, exchange_lag_s 0.3
# The identifiers shipped before the fifteenth and fourteenth stages' choices (a stage scores what it scored).
BEFORE_STAGE15: dict[str, object] = {"jump_silent": False, "exchange_fresh_s": 0.6}
BEFORE_STAGE14: dict[str, object] = {"exchange_tight_agents": None, **BEFORE_STAGE15}
# Stage 15: its candidates' options against the identifier shipped before it.
STAGE15_OPTIONS: tuple[dict[str, object], ...] = ({"jump_silent": True},
                                                   {"jump_silent": True, "exchange_fresh_s": None})
STAGE15_BASELINE = "shipped-before-15"
STAGE16_EVERY = 250  # stage 16: the fine-tuning's snapshots at multiples of this step
STAGE16_BASELINE = "shipped"
STAGE17_VISUAL: tuple[float, ...] = (8.0, 10.0, 12.0)  # stage 17: visual_exchange's log-likelihood ratios
STAGE17_MEMORY_S = 10.0  # and the time constant of its evidence's decay, seconds
STAGE18_STALE: tuple[float, ...] = (0.25, 0.5)  # stage 18: visual_stale_rad_s, radians per second of a report's age
STAGE19_UNDO: tuple[float, ...] = (0.25, 0.5)  # stage 19: undo_factor, the fraction of the evidence an undo needs
STAGE19_UNDO_S = 30.0  # and how long after a pair's exchange it holds, seconds
BEFORE_STAGE19: dict[str, object] = {"undo_factor": None}  # the identifier before the nineteenth and twentieth stages
# The visual detector before the eighteenth stage (and the identifier before the twentieth's choice).
BEFORE_STAGE18: dict[str, object] = {"visual_stale_rad_s": None, **BEFORE_STAGE19}
# Stages 6-8: the thresholds, exchange_memory_s and exchange_fresh_s of the candidates.
_EXCHANGE_STAGES: dict[int, tuple[tuple[float | None, ...], float | None, float | None]] = {
    6: (STAGE6_EXCHANGE_LLR, None, None), 7: (STAGE7_EXCHANGE_LLR, 1.0, None), 8: (STAGE8_EXCHANGE_LLR, 1.0, 0.6)}


def stage5_candidates() -> Candidates:
    """Candidate name (``fp_prior=off``, ``fp_prior=1.0``, ...) -> (the shipped weights, inference options)."""
    return {f"fp_prior={'off' if ref is None else ref}": (SHIPPED_SET_WEIGHTS, {"fp_prior_ref": ref})
            for ref in STAGE5_FP_PRIOR}


def exchange_candidates(stage: int) -> Candidates:
    """Stage 6, 7 or 8's candidates: name (``exchange=off``, ``exchange=8.0``, ...) -> (the shipped weights,
    inference options)."""
    thresholds, memory_s, fresh_s = _EXCHANGE_STAGES[stage]
    return {f"exchange={'off' if llr is None else llr}":
            (SHIPPED_SET_WEIGHTS, {"exchange_llr": llr, "exchange_memory_s": memory_s, "exchange_fresh_s": fresh_s})
            for llr in thresholds}


def stage9_candidates() -> Candidates:
    """The ninth stage's candidates: the detector off, or at 8 for teams of up to seven agents."""
    return {EXCHANGE_BASELINE: (SHIPPED_SET_WEIGHTS, {"exchange_llr": None}),
            "exchange=8.0,max_agents=7": (SHIPPED_SET_WEIGHTS, {"exchange_llr": 8.0, "exchange_memory_s": 1.0,
                                                                "exchange_fresh_s": 0.6, "exchange_max_agents": 7})}


def stage10_candidates() -> Candidates:
    """The tenth stage's candidates: name (``jump_pair=off``, ``jump_pair=1.0``) -> (the shipped weights, options)."""
    return {f"jump_pair={'off' if s is None else s}": (SHIPPED_SET_WEIGHTS, {"jump_pair_s": s})
            for s in STAGE10_JUMP_PAIR}


def stage12_candidates() -> Candidates:
    """The twelfth stage's candidates: name (``exchange_motion=0.03/0.3``: angular-acceleration density and lag)
    -> (the shipped weights, inference options)."""
    return {f"exchange_motion={accel}/{lag}": (SHIPPED_SET_WEIGHTS, {
        "exchange_accel": accel, "exchange_lag_s": lag, **BEFORE_STAGE14}) for accel, lag in STAGE12_EXCHANGE_MOTION}


def stage13_candidates() -> Candidates:
    """The thirteenth stage's candidates: the shipped identifier, and name (``exchange=0.03/0.3,step=0.08``) ->
    (the shipped weights, inference options)."""
    candidates: Candidates = {STAGE13_BASELINE: (SHIPPED_SET_WEIGHTS, dict(BEFORE_STAGE14))}
    for step in STAGE13_EXCHANGE_STEP:
        candidates[f"exchange=0.03/0.3,step={step}"] = (SHIPPED_SET_WEIGHTS, {
            "exchange_accel": 0.03, "exchange_lag_s": 0.3, "exchange_step_rad": step, **BEFORE_STAGE14})
    return candidates


def stage14_candidates() -> Candidates:
    """The fourteenth stage's candidates: the identifier shipped before it, and the tighter report model for teams
    of at least :data:`STAGE14_TIGHT_AGENTS` agents."""
    tight: dict[str, object] = {"exchange_tight_agents": STAGE14_TIGHT_AGENTS, **BEFORE_STAGE15}
    return {STAGE13_BASELINE: (SHIPPED_SET_WEIGHTS, dict(BEFORE_STAGE14)),
            f"exchange_tight_agents={STAGE14_TIGHT_AGENTS}": (SHIPPED_SET_WEIGHTS, tight)}


def stage15_candidates() -> Candidates:
    """The fifteenth stage's candidates: the identifier shipped before it and :data:`STAGE15_OPTIONS`."""
    candidates: Candidates = {STAGE15_BASELINE: (SHIPPED_SET_WEIGHTS, dict(BEFORE_STAGE15))}
    for options in STAGE15_OPTIONS:
        name = ",".join(f"{k}={'off' if v is None else v}" for k, v in options.items())
        candidates[name] = (SHIPPED_SET_WEIGHTS, {**BEFORE_STAGE15, **options})
    return candidates


def stage16_candidates(run_dir: Path) -> Candidates:
    """The sixteenth stage's candidates: the shipped identifier and ``step{k}``, the snapshots of ``run_dir`` at
    multiples of :data:`STAGE16_EVERY`, with the shipped inference options."""
    snapshots: Candidates = {f"step{k}": (run_dir / f"set_step{k}.npz", {})
                             for k in snapshot_steps(run_dir, STAGE16_EVERY)}
    return {STAGE16_BASELINE: (SHIPPED_SET_WEIGHTS, {}), **snapshots}


def stage17_candidates() -> Candidates:
    """The seventeenth stage's candidates: the identifier shipped before it and ``visual=h``, the visual exchange
    detector at each of :data:`STAGE17_VISUAL`."""
    return {STAGE16_BASELINE: (SHIPPED_SET_WEIGHTS, {"visual_exchange": None}),
            **{f"visual={h}": (SHIPPED_SET_WEIGHTS, {"visual_exchange": h, "visual_memory_s": STAGE17_MEMORY_S,
                                                     **BEFORE_STAGE18}) for h in STAGE17_VISUAL}}


def stage18_candidates() -> Candidates:
    """The eighteenth stage's candidates: the identifier shipped before it and ``visual_stale=r``, its visual
    exchange detector counting older reports with their noise widened by each of :data:`STAGE18_STALE`."""
    return {STAGE16_BASELINE: (SHIPPED_SET_WEIGHTS, dict(BEFORE_STAGE18)),
            **{f"visual_stale={r}": (SHIPPED_SET_WEIGHTS, {"visual_stale_rad_s": r, **BEFORE_STAGE19})
               for r in STAGE18_STALE}}


def stage19_candidates() -> Candidates:
    """The nineteenth stage's candidates: the identifier shipped before it and ``undo=f``, a pair exchanged within
    :data:`STAGE19_UNDO_S` seconds needing the fraction ``f`` of the evidence, for each of :data:`STAGE19_UNDO`."""
    return {STAGE16_BASELINE: (SHIPPED_SET_WEIGHTS, dict(BEFORE_STAGE19)),
            **{f"undo={f}": (SHIPPED_SET_WEIGHTS, {"undo_factor": f, "undo_s": STAGE19_UNDO_S}) for f in STAGE19_UNDO}}


def stage_candidates(stage: int, run_dir: Path | None = None) -> tuple[Candidates, str]:
    """Stage ``stage``'s (5 … 10, 12 … 20; 16: the snapshots in ``run_dir``) candidates and the name of its
    baseline."""
    if stage in (19, 20):
        return stage19_candidates(), STAGE16_BASELINE
    if stage == 18:
        return stage18_candidates(), STAGE16_BASELINE
    if stage == 17:
        return stage17_candidates(), STAGE16_BASELINE
    if stage == 16:
        return stage16_candidates(run_dir or Path(".")), STAGE16_BASELINE
    if stage == 15:
        return stage15_candidates(), STAGE15_BASELINE
    if stage == 12:
        return stage12_candidates(), STAGE12_BASELINE
    if stage == 13:
        return stage13_candidates(), STAGE13_BASELINE
    if stage == 14:
        return stage14_candidates(), STAGE13_BASELINE
    if stage == 5:
        return stage5_candidates(), STAGE5_BASELINE
    if stage == 10:
        return stage10_candidates(), STAGE10_BASELINE
    return (stage9_candidates() if stage == 9 else exchange_candidates(stage)), EXCHANGE_BASELINE


def select_options(run_dir: Path, stage: int, only: str | None = None) -> str | None:
    """Score stage ``stage``'s candidates (all, or ``only``), print them and the choice (None: nothing eligible)."""
    candidates, baseline = stage_candidates(stage, run_dir)
    rows = score_candidates(candidates, run_dir / f"set_select_stage{stage}.json", only)
    if stage < 12:
        return print_choice(rows, baseline)
    if baseline not in rows:
        print("the baseline is not scored yet")
        return None
    kept = [name for name, row in rows.items() if name != baseline and passes_guard(row, rows[baseline])]
    print("pass the tuning guard (the development sample decides among them): " + (", ".join(kept) or "none"))
    return None
