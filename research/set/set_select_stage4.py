"""The fourth stage's choice for the ``set`` identifier (issue 23): fine-tuned snapshots x the pair-swap rule.

``python research/set/set_select.py RUN --stage 4 [--ship]`` scores, on the tuning sequences of the third
stage (:data:`~set_select.STAGE3_TEAMS` and the tuning recovery, unmeasurable sequences left
out), every candidate of :func:`stage4_candidates`: the shipped weights and the snapshots ``RUN/set_step{k}.npz``
at multiples of :data:`STAGE4_EVERY`, each with the pair-swap rule off and at :data:`STAGE4_PAIR_SWAP`
(the other inference options at the shipped defaults). Scores are kept in ``RUN/set_select_stage4.json``
(one candidate at a time can be scored with ``--only NAME``). :func:`choose_stage4` applies the rule
written in docs/experiments/any-team-size.md ("A fourth stage") before any candidate was scored.
"""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np
from set_select import (
    STAGE3_TEAMS,
    best_choice,
    options_row,
    recovery_info,
    recovery_sequences,
    score_columns,
    snapshot_steps,
    tuning_sequences,
)

from lookalike.trackers.set.network import SHIPPED_SET_WEIGHTS, load_set_weights, save_set_weights

STAGE4_EVERY = 500
STAGE4_PAIR_SWAP: tuple[float | None, ...] = (None, 1.5, 1.0)
BASELINE = "shipped,pair=off"
STAGE4_RULE = ("candidates: the shipped weights and the stage-4 snapshots at multiples of 500 steps, each with "
               "pair_swap off, 1.5 and 1.0 rad (other options the shipped defaults); tuning teams and recovery as "
               "stage 3 (unmeasurable recovery sequences left out); baseline: the shipped weights, pair_swap off; "
               "eligible: every tuning team >= baseline - 0.05 points, recovery mean <= baseline + 0.02 s on every "
               "set-up, and either M=3, N=2 >= baseline + 0.05 points or the mean of the three mean recovery times "
               "<= baseline's - 0.03 s; choice: best M=3, N=2, within 0.05 points the lowest mean recovery, then "
               "the best mean of the other teams")


def candidate_name(weights: str, pair_swap: float | None) -> str:
    """``shipped,pair=off`` or ``step300,pair=3.0``."""
    return f"{weights},pair={'off' if pair_swap is None else pair_swap}"


def stage4_candidates(run_dir: Path) -> dict[str, tuple[Path, dict[str, object]]]:
    """Candidate name -> (weights, inference options): the shipped weights and the snapshots at multiples of
    :data:`STAGE4_EVERY`, each with every :data:`STAGE4_PAIR_SWAP`."""
    steps = snapshot_steps(run_dir, STAGE4_EVERY)
    weights = {"shipped": SHIPPED_SET_WEIGHTS, **{f"step{k}": run_dir / f"set_step{k}.npz" for k in steps}}
    return {candidate_name(w, ps): (path, {"pair_swap": ps}) for w, path in weights.items() for ps in STAGE4_PAIR_SWAP}


def passes_guard(row: dict[str, float], base: dict[str, float]) -> bool:
    """The fourth stage's guard: every tuning team at least the baseline's success less 0.05 points, and every
    tuning recovery mean at most the baseline's plus 0.02 s (rows as in :func:`choose_stage4`)."""
    teams = [k for k in base if not k.startswith(("rec_", "worst_"))]
    recs = [k for k in base if k.startswith("rec_")]
    return (all(row[k] >= base[k] - 0.05 for k in teams)
            and all(np.isfinite(row[k]) and row[k] <= base[k] + 0.02 for k in recs))


def choose_stage4(rows: dict[str, dict[str, float]], baseline: str = BASELINE) -> str | None:
    """The stage-4 choice among ``rows`` (candidate -> tuning success per team in % and ``rec_<setup>`` /
    ``worst_<setup>`` recovery seconds), ``baseline`` one of its keys: see :data:`STAGE4_RULE`; None when
    none is eligible."""
    base = rows[baseline]
    teams = [k for k in base if not k.startswith(("rec_", "worst_"))]
    others = [k for k in teams if k != "m3n2"]
    recs = [k for k in base if k.startswith("rec_")]

    def mean_rec(r: dict[str, float]) -> float:
        return float(np.mean([r[k] for k in recs]))

    def eligible(r: dict[str, float]) -> bool:
        return passes_guard(r, base) and (r["m3n2"] >= base["m3n2"] + 0.05 or mean_rec(r) <= mean_rec(base) - 0.03)

    return best_choice(rows, [p for p, r in rows.items() if p != baseline and eligible(r)], recs, others)


def score_candidates(candidates: dict[str, tuple[Path, dict[str, object]]], cache_path: Path,
                     only: str | None = None) -> dict[str, dict[str, float]]:
    """Score ``candidates`` (name -> (weights, inference options); all, or ``only``) on the third stage's tuning
    sequences and tuning recovery, kept in the JSON file ``cache_path``; print every scored candidate and return
    their rows (name -> tuning success per team in %, ``rec_<setup>`` / ``worst_<setup>`` seconds)."""
    if only is not None and only not in candidates:
        raise SystemExit(f"--only {only}: not a candidate; candidates: {', '.join(candidates)}")
    cache: dict[str, dict[str, float]] = json.loads(cache_path.read_text()) if cache_path.is_file() else {}
    todo = [n for n in ([only] if only else candidates) if n not in cache]
    if todo:
        seqs, rec_seqs = tuning_sequences(STAGE3_TEAMS), recovery_sequences()
        for name in todo:
            weights, options = candidates[name]
            row = options_row(options, seqs, rec_seqs, weights)
            cache = json.loads(cache_path.read_text()) if cache_path.is_file() else {}  # others may have added
            cache[name] = row
            cache_path.write_text(json.dumps(cache, indent=1))
    cols = score_columns(STAGE3_TEAMS)
    print("tuning success (%), recovery (s)  " + "".join(f"{n:>12s}" for n in cols))
    rows = {n: cache[n] for n in candidates if n in cache}
    for name, row in rows.items():
        print(f"{name:24s}" + "".join(f"{row[n]:12.3f}" for n in cols), flush=True)
    return rows


def print_choice(rows: dict[str, dict[str, float]], baseline: str) -> str | None:
    """Print and return the choice of :func:`choose_stage4` among the scored ``rows`` against ``baseline``
    (None, said so, when the baseline is not scored yet or nothing is eligible)."""
    if baseline not in rows:
        print("the baseline is not scored yet: no choice")
        return None
    chosen = choose_stage4(rows, baseline)
    print(f"chosen: {chosen}" if chosen else "chosen: none (nothing eligible; nothing ships)")
    return chosen


def select_stage4(run_dir: Path, only: str | None = None, ship: bool = False) -> str | None:
    """Score the candidates (all, or ``only``) on the tuning sequences, cached in ``RUN/set_select_stage4.json``;
    print them and the choice among those scored; with ``ship``, copy chosen weights that are a snapshot into
    the package with what they were chosen on (a chosen ``pair_swap`` is made the identifier's default by hand)."""
    candidates = stage4_candidates(run_dir)
    rows = score_candidates(candidates, run_dir / "set_select_stage4.json", only)
    chosen = print_choice(rows, BASELINE)
    if ship and chosen and not chosen.startswith("shipped,"):
        chosen_weights = load_set_weights(candidates[chosen][0])
        chosen_weights.info["chosen_on"] = {
            "rule": STAGE4_RULE, "tuning_teams": [list(t) for t in STAGE3_TEAMS], "candidate": chosen,
            "tuning": rows[chosen], "baseline": rows[BASELINE], "candidates": rows,
            "recovery": recovery_info(),
            "before": load_set_weights(SHIPPED_SET_WEIGHTS).info,
        }
        save_set_weights(chosen_weights, SHIPPED_SET_WEIGHTS)
        log = run_dir / "training_log.csv"
        if log.is_file():
            shutil.copy(log, SHIPPED_SET_WEIGHTS.parent / "set_any_finetune4_log.csv")
        print(f"shipped {candidates[chosen][0]} as {SHIPPED_SET_WEIGHTS}")
    return chosen
