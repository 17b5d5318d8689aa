"""Choosing among a ``set`` fine-tuning run's snapshots on tuning sequences, and shipping the choice.

``python -m lookalike.bench.set_select RUN [--baseline B] [--average-from S] [--ship]`` scores the
snapshots ``RUN/set_step{k}.npz`` (k a multiple of ``--every``) and the baseline on tuning sequences
only (:data:`TUNING_TEAMS`, seeds below 100000, apart from every bench): eligible are the snapshots no
worse than the baseline on any tuning team; of those, the best on M=3, N=2 (a tie within 0.01 points
goes to the best mean), or the baseline when none is. ``--average-from S`` adds one more candidate,
``RUN/set_avg.npz``, the mean of the weights of the snapshots from step S on. ``--ship`` copies the
chosen weights into the package's shipped weights with what they were chosen on.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import re
import shutil
from pathlib import Path

import numpy as np

from lookalike.bench.pixel_recordings import score_identifier
from lookalike.learn.set_data import world
from lookalike.learn.set_numpy import load_set_weights, save_set_weights
from lookalike.learn.set_tracker import SHIPPED_SET_WEIGHTS
from lookalike.sim import PRESET_NAMES, RobotSequence, preset, simulate_robots

# Tuning sequences for --select (name, (N, M, fp), first seed, sequences), 1000 frames each; apart from every bench.
TUNING_TEAMS = (("m3n2", (2, 3, 0.5), 50_000, 20), ("m5n3", (3, 5, 0.8), 51_000, 10),
                ("m10n7", (7, 10, 1.5), 52_000, 10), ("m6n4", (4, 6, 1.0), 54_000, 10))


def set_success(weights: Path, sequences: list[RobotSequence]) -> float:
    """Identification success rate of ``set`` with ``weights`` over ``sequences`` (as ``bench ident`` runs it)."""
    return score_identifier(sequences, "set", weights=str(weights))[0]


def tuning_sequences() -> dict[str, list[RobotSequence]]:
    """The tuning sequences of :data:`TUNING_TEAMS`, by name."""
    out = {}
    for name, (n, m, fp), first, count in TUNING_TEAMS:
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


def average_weights(paths: list[Path], out: Path) -> Path:
    """Write the element-wise mean of the weights ``paths`` (same widths) to ``out``."""
    ws = [load_set_weights(p) for p in paths]
    arrays = {k: np.mean([w.arrays[k] for w in ws], axis=0) for k in ws[0].arrays}
    info = {**ws[-1].info, "averaged": [p.name for p in paths]}
    save_set_weights(dataclasses.replace(ws[-1], arrays=arrays, info=info), out)
    return out


def select(run_dir: Path, every: int = 50, baseline: Path = SHIPPED_SET_WEIGHTS, ship: bool = False,
           average_from: int | None = None) -> None:
    """Score the baseline and the snapshots on the tuning sequences, print them and the choice."""
    steps = sorted(int(m.group(1)) for p in run_dir.glob("set_step*.npz")
                   if (m := re.fullmatch(r"set_step(\d+)\.npz", p.name)) and int(m.group(1)) % every == 0)
    if not steps:
        raise SystemExit(f"{run_dir}: no set_step{{k}}.npz with k a multiple of {every}")
    candidates = [run_dir / f"set_step{k}.npz" for k in steps]
    if average_from is not None:
        late = [run_dir / f"set_step{k}.npz" for k in steps if k >= average_from]
        if late:
            candidates.append(average_weights(late, run_dir / "set_avg.npz"))
    seqs = tuning_sequences()
    names = [t[0] for t in TUNING_TEAMS]
    print("tuning success (%)          " + "".join(f"{n:>8s}" for n in names))

    def score(path: Path) -> dict[str, float]:
        row = {name: round(100 * set_success(path, seqs[name]), 3) for name in names}
        print(f"{str(path)[-28:]:28s}" + "".join(f"{row[n]:8.3f}" for n in names), flush=True)
        return row

    base = score(baseline)
    rows = {str(p): score(p) for p in candidates}
    chosen = choose(rows, base)
    print(f"chosen: {chosen}" if chosen else "chosen: none (every snapshot is below the baseline on a tuning team)")
    if ship:  # the chosen snapshot, or the baseline when none is eligible
        weights = load_set_weights(chosen or baseline)
        weights.info["chosen_on"] = {"rule": "no tuning team below the baseline, then best M=3, N=2",
                                     "tuning_teams": [list(t) for t in TUNING_TEAMS],
                                     "tuning": rows[chosen] if chosen else base,
                                     "baseline": {"path": str(baseline), **base}}
        save_set_weights(weights, SHIPPED_SET_WEIGHTS)
        log = run_dir / "training_log.csv"
        if chosen and log.is_file():
            shutil.copy(log, SHIPPED_SET_WEIGHTS.parent / "set_any_finetune_log.csv")
        print(f"shipped {chosen or baseline} as {SHIPPED_SET_WEIGHTS}: {json.dumps(rows[chosen] if chosen else base)}")


def main(argv: list[str] | None = None) -> None:
    """Parse the command line and run :func:`select`."""
    parser = argparse.ArgumentParser(prog="python -m lookalike.bench.set_select", description=__doc__)
    parser.add_argument("run", type=Path, help="a fine-tuning run's folder (set_step{k}.npz snapshots)")
    parser.add_argument("--every", type=int, default=50, help="snapshots at multiples of this step")
    parser.add_argument("--baseline", type=Path, default=SHIPPED_SET_WEIGHTS, help="weights to beat (.npz)")
    parser.add_argument("--average-from", type=int, default=None,
                        help="also the mean of the snapshots' weights from this step on")
    parser.add_argument("--ship", action="store_true", help="ship the chosen weights")
    args = parser.parse_args(argv)
    select(args.run, args.every, args.baseline, args.ship, args.average_from)


if __name__ == "__main__":
    main()
