"""Choosing among a ``set`` fine-tuning run's snapshots on tuning sequences, and shipping the choice.

``python research/set/set_select.py RUN [--baseline B] [--average-from S] [--ship]`` scores the
snapshots ``RUN/set_step{k}.npz`` (k a multiple of ``--every``) and the baseline on tuning sequences
only (:data:`TUNING_TEAMS`, seeds below 100000, apart from every bench): eligible are the snapshots no
worse than the baseline on any tuning team; of those, the best on M=3, N=2 (a tie within 0.01 points
goes to the best mean), or the baseline when none is. ``--average-from S`` adds one more candidate,
``RUN/set_avg.npz``, the mean of the weights of the snapshots from step S on. ``--ship`` copies the
chosen weights into the package's shipped weights with what they were chosen on.

``--stage 2`` applies the rule of the second fine-tuning stage (:func:`choose_stage2`): the candidates are
the snapshots at multiples of 200 and the mean of those from step 300 on; each is also timed on
``bench recovery``'s swap on tuning seeds (:data:`RECOVERY_SEED`), and a choice ships only when it is
better than the baseline (:func:`better_than`).

``--stage 3`` trains nothing: it chooses the identifier's inference options (:data:`STAGE3_OPTIONS`: the
stale-report rule ``stale_s``/``stale_turn`` and ``on_jump``) for the shipped weights on more tuning teams
(:data:`STAGE3_TEAMS`) and the tuning recovery, leaving out the sequences where the swapped pair is not
seen while swapped or not after the restore (:func:`measurable`); see :func:`choose_stage3`.

``--stage 4`` chooses among a fourth fine-tuning's snapshots and the pair-swap rule
(:mod:`set_select_stage4`); ``--stage 5`` whether to correct the false-positive probability
for the world's false-positive rate, ``--stage 6`` to ``9`` the report-exchange detector, ``--stage 10``
the pairing of mirroring report jumps, ``--stage 12`` the exchange detector's heading model, ``--stage 13``
that and a step gate, ``--stage 14`` that model for larger teams, ``--stage 15`` pairing jumps after silences,
``--stage 16`` a fine-tuning's snapshots with swaps that end in a silence, ``--stage 17`` exchanges found in the
detections' visual headings, ``--stage 18`` the same counting silent agents' older reports, ``--stage 19`` and
``20`` a recent exchange undone on less evidence (:mod:`set_select_options`).
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import re
import shutil
from pathlib import Path

import numpy as np

from lookalike.bench.experiments import measurable, swap_recovery
from lookalike.bench.pixel_recordings import score_identifier
from lookalike.learn.set_data import world
from lookalike.loop import run
from lookalike.sim import PRESET_NAMES, RobotSequence, preset, simulate_robots
from lookalike.trackers import make_tracker
from lookalike.trackers.parts.identity import labels_from_tracks
from lookalike.trackers.set.network import SHIPPED_SET_WEIGHTS, load_set_weights, save_set_weights
from lookalike.types import Frame

# Tuning sequences for --select (name, (N, M, fp), first seed, sequences), 1000 frames each; apart from every bench.
TUNING_TEAMS = (("m3n2", (2, 3, 0.5), 50_000, 20), ("m5n3", (3, 5, 0.8), 51_000, 10),
                ("m10n7", (7, 10, 1.5), 52_000, 10), ("m6n4", (4, 6, 1.0), 54_000, 10))
# Recovery on tuning seeds (stage 2): ``bench recovery``'s sequences and swap with base seed 55000
# (seeds 55000 + 1000·set-up + k), 10 per set-up; apart from every bench and the tuning teams above.
RECOVERY_SEED = 55_000
RECOVERY_SEQUENCES = 10
RECOVERY_FRAMES = 900
RECOVERY_SWAP = (5.0, 10.0)  # (start, duration) in seconds, as ``bench recovery``'s defaults
STAGE2_EVERY = 200
STAGE2_AVERAGE_FROM = 300
STAGE2_RULE = ("candidates: snapshots at multiples of 200 and the mean of those from step 300 on; eligible: tuning "
               "M=3, N=2 >= baseline, other tuning teams >= baseline - 0.3 points, tuning recovery mean <= baseline "
               "+ 0.05 s on every set-up and always recovered; choice: best M=3, N=2, within 0.05 points the lowest "
               "mean recovery, then the best mean success; shipped only if M=3, N=2 > baseline + 0.05 points or "
               "the mean recovery < baseline's - 0.03 s")


# Stage 3: two more tuning teams (the unseen teams' N = 6 and 12 with their clutter; seeds apart from the others).
STAGE3_TEAMS = TUNING_TEAMS + (("m8n6", (6, 8, 1.3), 58_000, 10), ("m14n12", (12, 14, 2.5), 59_000, 5))
# Stage 3's candidates: the set identifier's inference options for the shipped weights; the first is the baseline.
STAGE3_OPTIONS: tuple[dict[str, object], ...] = tuple(
    {"stale_s": stale, "stale_turn": turn, "on_jump": jump} for jump in ("forget", "swap")
    for stale, turn in ((None, 0.6), (0.5, 0.6), (0.5, 1.0), (1.0, 0.6), (1.0, 1.0), (2.0, 0.6), (2.0, 1.0)))
STAGE3_RULE = ("candidates: stale_s in (off, 0.5, 1, 2 s) x stale_turn in (0.6, 1.0 rad) x on_jump in (forget, swap), "
               "the shipped weights; eligible: tuning M=3, N=2 >= baseline + 0.1 points, the other five tuning teams "
               ">= baseline - 0.05 points, tuning recovery mean <= baseline + 0.02 s on every set-up (sequences whose "
               "swapped pair is not seen while swapped or after the restore left out); choice: best M=3, N=2, within "
               "0.05 points the lowest mean recovery, then the best mean success of the other teams; shipped as the "
               "identifier's defaults when one is eligible")


def set_success(weights: Path, sequences: list[RobotSequence], **options: object) -> float:
    """Identification success rate of ``set`` with ``weights`` (and inference ``options``) over ``sequences``
    (as ``bench ident`` runs it)."""
    return score_identifier(sequences, "set", weights=str(weights), **options)[0]


def tuning_sequences(teams: tuple[tuple[str, tuple[int, int, float], int, int], ...] = TUNING_TEAMS
                     ) -> dict[str, list[RobotSequence]]:
    """The tuning sequences of ``teams`` (default :data:`TUNING_TEAMS`), by name."""
    out = {}
    for name, (n, m, fp), first, count in teams:
        cfg = preset(name) if name in PRESET_NAMES else world(n, m, fp)
        out[name] = [simulate_robots(cfg, 1000, first + k) for k in range(count)]
    return out


def choose(rows: dict[str, dict[str, float]], baseline: dict[str, float]) -> str | None:
    """The chosen candidate of ``rows`` (path -> tuning success per team): no team below ``baseline``,
    then the best M=3, N=2 (ties within 0.01 points: the best mean); None when none is eligible."""
    eligible = [p for p, r in rows.items() if all(r[k] >= baseline[k] for k in baseline)]
    if not eligible:
        return None
    top = max(rows[p]["m3n2"] for p in eligible)
    near = [p for p in eligible if rows[p]["m3n2"] >= top - 0.01]
    return max(near, key=lambda p: float(np.mean([rows[p][k] for k in baseline])))


def _labels(weights: Path, sequence: RobotSequence, frames: list[Frame], **options: object) -> list[np.ndarray]:
    """Per frame, ``set``'s labels with ``weights`` (and ``options``) over ``frames``, configured as ``bench
    ident`` does."""
    cfg = sequence.config
    tracker = make_tracker("set", n_agents=cfg.n_agents, n_slots=cfg.max_detections, weights=str(weights), **options)
    labels: list[np.ndarray] = []
    run(tracker, frames, lambda f, tracks: labels.append(labels_from_tracks(len(f.detections), tracks)))
    return labels


def set_recovery_s(weights: Path, sequence: RobotSequence, swap_at_s: float = RECOVERY_SWAP[0],
                   swap_s: float = RECOVERY_SWAP[1], options: dict[str, object] | None = None) -> float:
    """Seconds ``set`` with ``weights`` (and inference ``options``) takes to recover after ``bench
    recovery``'s swap of the two robots seen most (inf: never), measured as ``bench recovery`` does."""
    return swap_recovery(lambda s, fs: _labels(weights, s, fs, **(options or {})), sequence, swap_at_s,
                         swap_s).recovery_s


def recovery_sequences() -> dict[str, list[RobotSequence]]:
    """``bench recovery``'s sequences on the tuning seeds :data:`RECOVERY_SEED` + 1000·set-up + k."""
    return {p: [simulate_robots(preset(p), RECOVERY_FRAMES, RECOVERY_SEED + 1000 * i + k)
                for k in range(RECOVERY_SEQUENCES)] for i, p in enumerate(PRESET_NAMES)}


def score_columns(teams: tuple[tuple[str, tuple[int, int, float], int, int], ...], recovery: bool = True) -> list[str]:
    """The printed columns: the ``teams``' names, then (with ``recovery``) ``rec_<setup>`` and ``worst_<setup>``."""
    return [t[0] for t in teams] + ([f"{c}_{p}" for c in ("rec", "worst") for p in PRESET_NAMES] if recovery else [])


def recovery_info() -> dict[str, object]:
    """What the tuning recovery was, as recorded with shipped weights."""
    return {"seed": RECOVERY_SEED, "sequences": RECOVERY_SEQUENCES, "frames": RECOVERY_FRAMES,
            "swap_at_s": RECOVERY_SWAP[0], "swap_s": RECOVERY_SWAP[1]}


def snapshot_steps(run_dir: Path, every: int) -> list[int]:
    """The steps ``k`` of the snapshots ``RUN/set_step{k}.npz`` with ``k`` a multiple of ``every``, ascending."""
    return sorted(int(m.group(1)) for p in run_dir.glob("set_step*.npz")
                  if (m := re.fullmatch(r"set_step(\d+)\.npz", p.name)) and int(m.group(1)) % every == 0)


def choose_stage2(rows: dict[str, dict[str, float]], baseline: dict[str, float]) -> str | None:
    """The stage-2 choice of ``rows`` (path -> tuning success per team in % and ``rec_<setup>`` /
    ``worst_<setup>`` recovery seconds): see :data:`STAGE2_RULE`; None when none is eligible."""
    teams = [k for k in baseline if not k.startswith(("rec_", "worst_"))]
    recs = [k for k in baseline if k.startswith("rec_")]

    def eligible(r: dict[str, float]) -> bool:
        return (r["m3n2"] >= baseline["m3n2"]
                and all(r[k] >= baseline[k] - 0.3 for k in teams if k != "m3n2")
                and all(np.isfinite(r[k]) and r[k] <= baseline[k] + 0.05 for k in recs)
                and all(np.isfinite(r[k]) for k in r if k.startswith("worst_")))

    return best_choice(rows, [p for p, r in rows.items() if eligible(r)], recs, teams)


def best_choice(rows: dict[str, dict[str, float]], ok: list[str], recs: list[str], teams: list[str]) -> str | None:
    """Among the eligible ``ok``: the best M=3, N=2 tuning success; within 0.05 points of it, the lowest
    mean of the ``recs`` recovery times; then the best mean success over ``teams``. None when ``ok`` is empty."""
    if not ok:
        return None
    top = max(rows[p]["m3n2"] for p in ok)
    near = [p for p in ok if rows[p]["m3n2"] >= top - 0.05]
    return min(near, key=lambda p: (float(np.mean([rows[p][k] for k in recs])),
                                    -float(np.mean([rows[p][k] for k in teams]))))


def better_than(row: dict[str, float], baseline: dict[str, float]) -> bool:
    """Whether a stage-2 choice ships: M=3, N=2 more than 0.05 points above the baseline, or its mean
    recovery over the set-ups more than 0.03 s below the baseline's."""
    recs = [k for k in baseline if k.startswith("rec_")]
    mean_rec = float(np.mean([row[k] for k in recs])) if recs else 0.0
    base_rec = float(np.mean([baseline[k] for k in recs])) if recs else 0.0
    return row["m3n2"] > baseline["m3n2"] + 0.05 or mean_rec < base_rec - 0.03


def choose_stage3(rows: dict[str, dict[str, float]], baseline: str) -> str | None:
    """The stage-3 choice among ``rows`` (candidate -> tuning success per team in % and ``rec_<setup>`` /
    ``worst_<setup>`` recovery seconds), ``baseline`` one of its keys: see :data:`STAGE3_RULE`; None
    when none is eligible."""
    base = rows[baseline]
    teams = [k for k in base if not k.startswith(("rec_", "worst_"))]
    others = [k for k in teams if k != "m3n2"]
    recs = [k for k in base if k.startswith("rec_")]

    def eligible(r: dict[str, float]) -> bool:
        return (r["m3n2"] >= base["m3n2"] + 0.1 and all(r[k] >= base[k] - 0.05 for k in others)
                and all(np.isfinite(r[k]) and r[k] <= base[k] + 0.02 for k in recs))

    return best_choice(rows, [p for p, r in rows.items() if p != baseline and eligible(r)], recs, others)


def options_row(options: dict[str, object], seqs: dict[str, list[RobotSequence]],
                rec_seqs: dict[str, list[RobotSequence]], weights: Path = SHIPPED_SET_WEIGHTS) -> dict[str, float]:
    """Tuning success (%) of ``set`` with inference ``options`` per team of ``seqs`` and, per set-up of
    ``rec_seqs``, the mean (``rec_<setup>``) and worst (``worst_<setup>``) recovery seconds over the
    :func:`measurable` sequences."""
    row = {name: round(100 * set_success(weights, sq, **options), 3) for name, sq in seqs.items()}
    for p, sq in rec_seqs.items():
        times = [set_recovery_s(weights, q, options=options) for q in sq if measurable(q)]
        row[f"rec_{p}"], row[f"worst_{p}"] = round(float(np.mean(times)), 3), round(float(np.max(times)), 3)
    return row


def option_name(options: dict[str, object]) -> str:
    """A short name of a stage-3 candidate, e.g. ``stale=1.0/0.6,swap``."""
    stale = "off" if options["stale_s"] is None else f"{options['stale_s']}/{options['stale_turn']}"
    return f"stale={stale},{options['on_jump']}"


def select_stage3(cache_path: Path) -> str | None:
    """Score every :data:`STAGE3_OPTIONS` candidate on the tuning sequences (cached in ``cache_path``, JSON, by
    name), print them and return the chosen candidate's name (None: nothing eligible)."""
    seqs = tuning_sequences(STAGE3_TEAMS)
    rec_seqs = recovery_sequences()
    cols = score_columns(STAGE3_TEAMS)
    cache: dict[str, dict[str, float]] = json.loads(cache_path.read_text()) if cache_path.is_file() else {}
    print("tuning success (%), recovery (s)  " + "".join(f"{n:>12s}" for n in cols))
    for options in STAGE3_OPTIONS:
        name = option_name(options)
        if name not in cache:
            cache[name] = options_row(options, seqs, rec_seqs)
            cache_path.write_text(json.dumps(cache, indent=1))
        print(f"{name:32s}" + "".join(f"{cache[name][n]:12.3f}" for n in cols), flush=True)
    chosen = choose_stage3({option_name(o): cache[option_name(o)] for o in STAGE3_OPTIONS},
                           option_name(STAGE3_OPTIONS[0]))
    print(f"chosen: {chosen}" if chosen else "chosen: none (nothing eligible; the defaults stay)")
    return chosen


def average_weights(paths: list[Path], out: Path) -> Path:
    """Write the element-wise mean of the weights ``paths`` (same widths) to ``out``."""
    ws = [load_set_weights(p) for p in paths]
    arrays = {k: np.mean([w.arrays[k] for w in ws], axis=0) for k in ws[0].arrays}
    info = {**ws[-1].info, "averaged": [p.name for p in paths]}
    save_set_weights(dataclasses.replace(ws[-1], arrays=arrays, info=info), out)
    return out


def tuning_row(weights: Path, seqs: dict[str, list[RobotSequence]],
               rec_seqs: dict[str, list[RobotSequence]]) -> dict[str, float]:
    """Tuning success (%) of ``weights`` per team of ``seqs`` and, per set-up of ``rec_seqs``, the mean
    (``rec_<setup>``) and worst (``worst_<setup>``) recovery seconds."""
    row = {name: round(100 * set_success(weights, sq), 3) for name, sq in seqs.items()}
    for p, sq in rec_seqs.items():
        times = [set_recovery_s(weights, q) for q in sq]
        row[f"rec_{p}"], row[f"worst_{p}"] = round(float(np.mean(times)), 3), round(float(np.max(times)), 3)
    return row


def _candidates(run_dir: Path, every: int, average_from: int | None) -> list[Path]:
    steps = snapshot_steps(run_dir, every)
    if not steps:
        raise SystemExit(f"{run_dir}: no set_step{{k}}.npz with k a multiple of {every}")
    candidates = [run_dir / f"set_step{k}.npz" for k in steps]
    if average_from is not None:
        late = [run_dir / f"set_step{k}.npz" for k in steps if k >= average_from]
        if len(late) >= 2:
            candidates.append(average_weights(late, run_dir / "set_avg.npz"))
    return candidates


def select(run_dir: Path, every: int = 50, baseline: Path = SHIPPED_SET_WEIGHTS, ship: bool = False,
           average_from: int | None = None, stage: int = 1) -> None:
    """Score the baseline and the snapshots on the tuning sequences, print them and the choice (stage 2:
    also the tuning recovery, cached in ``RUN/set_select_stage2.json`` by file name; the mean is rescored)."""
    if stage == 2:
        every, average_from = STAGE2_EVERY, STAGE2_AVERAGE_FROM
    candidates = _candidates(run_dir, every, average_from)
    seqs = tuning_sequences()
    cols = score_columns(TUNING_TEAMS, recovery=stage == 2)
    rec_seqs = recovery_sequences() if stage == 2 else {}
    cache_path = run_dir / "set_select_stage2.json"
    cache: dict[str, dict[str, float]] = {}
    if stage == 2 and cache_path.is_file():
        cache = json.loads(cache_path.read_text())
    print("tuning success (%), recovery (s)" + "".join(f"{n:>12s}" for n in cols))

    def score(path: Path, key: str | None) -> dict[str, float]:
        if key is not None and key in cache:
            row = cache[key]
        else:
            row = tuning_row(path, seqs, rec_seqs)
            if stage == 2 and key is not None:
                cache[key] = row
                cache_path.write_text(json.dumps(cache, indent=1))
        print(f"{str(path)[-32:]:32s}" + "".join(f"{row[n]:12.3f}" for n in cols), flush=True)
        return row

    base = score(baseline, "baseline:" + str(baseline))
    rows = {str(p): score(p, None if p.name == "set_avg.npz" else p.name) for p in candidates}
    if stage == 2:
        chosen = choose_stage2(rows, base)
        if chosen and not better_than(rows[chosen], base):
            print(f"choice {chosen} is not better than the baseline on tuning: nothing ships")
            chosen = None
    else:
        chosen = choose(rows, base)
    print(f"chosen: {chosen}" if chosen else "chosen: none (no eligible candidate better than the baseline)")
    if ship:  # the chosen snapshot, or the baseline when none is eligible
        weights = load_set_weights(chosen or baseline)
        rule = STAGE2_RULE if stage == 2 else "no tuning team below the baseline, then best M=3, N=2"
        chosen_on = {"rule": rule, "tuning_teams": [list(t) for t in TUNING_TEAMS],
                     "tuning": rows[chosen] if chosen else base, "baseline": {"path": str(baseline), **base}}
        if stage == 2:
            chosen_on["recovery"] = recovery_info()
            chosen_on["candidates"] = rows
            weights.info["stage1"] = load_set_weights(baseline).info
        weights.info["chosen_on"] = chosen_on
        save_set_weights(weights, SHIPPED_SET_WEIGHTS)
        log = run_dir / "training_log.csv"
        if chosen and log.is_file():
            name = "set_any_finetune2_log.csv" if stage == 2 else "set_any_finetune_log.csv"
            shutil.copy(log, SHIPPED_SET_WEIGHTS.parent / name)
        print(f"shipped {chosen or baseline} as {SHIPPED_SET_WEIGHTS}: {json.dumps(rows[chosen] if chosen else base)}")


def main(argv: list[str] | None = None) -> None:
    """Parse the command line and run :func:`select`."""
    parser = argparse.ArgumentParser(prog="python research/set/set_select.py", description=__doc__)
    parser.add_argument("run", type=Path, help="a fine-tuning run's folder (set_step{k}.npz snapshots)")
    parser.add_argument("--every", type=int, default=50, help="snapshots at multiples of this step")
    parser.add_argument("--baseline", type=Path, default=SHIPPED_SET_WEIGHTS, help="weights to beat (.npz)")
    parser.add_argument("--average-from", type=int, default=None,
                        help="also the mean of the snapshots' weights from this step on")
    parser.add_argument("--ship", action="store_true", help="ship the chosen weights")
    parser.add_argument("--stage", type=int, choices=(*range(1, 11), *range(12, 21)), default=1,
                        help="2: the second stage's rule (tuning recovery too; fixes --every and --average-from); "
                        "3: the inference options of the shipped weights (RUN: where the scores are kept); "
                        "4: the fourth stage's snapshots x the pair-swap rule (set_select_stage4); "
                        "5: the false-positive prior correction; "
                        "6-9: the report-exchange detector (7: its evidence decays; 8: and lost bursts leave a "
                        "track out; 9: for teams of up to seven); 10: mirroring report jumps paired; "
                        "12: the exchange detector's heading model; 13: and a step gate; 14: that model for "
                        "larger teams; 15: jumps paired across silences; 16: a fine-tuning with swaps that end "
                        "in a silence; 17: exchanges in the visual headings; 18: and silent agents' older reports; "
                        "19, 20: a recent exchange undone on less evidence (5-20: set_select_options)")
    parser.add_argument("--only", default=None,
                        help="stages 4-20: score this candidate only (e.g. step300,pair=off)")
    parser.add_argument("--cache", type=Path, default=None,
                        help="stage 3: the JSON file of scored candidates (default RUN/set_select_stage3.json)")
    args = parser.parse_args(argv)
    if args.stage == 3:
        select_stage3(args.cache or args.run / "set_select_stage3.json")
        return
    if args.stage == 4:
        from set_select_stage4 import select_stage4

        select_stage4(args.run, args.only, args.ship)
        return
    if args.stage >= 5:
        from set_select_options import select_options

        select_options(args.run, args.stage, args.only)
        return
    select(args.run, args.every, args.baseline, args.ship, args.average_from, args.stage)


if __name__ == "__main__":
    main()
