"""boxtrack on data it was not tuned on: leave one sequence out (MOT15) and one dataset out (dev sets).

The honest figure of a way of choosing parameters is its score on data outside the choice. The
criterion is fixed up front: HOTA + IDF1 + MOTA (combined over the sequences as TrackEval does;
over several datasets, the mean of each dataset's sum, so no dataset outweighs another).

The choice is random search over boxtrack's default search space (:mod:`lookalike.tune.space`):
``--trials`` parameter sets drawn at random (seeded) plus the defaults, each run once on every
sequence and its per-sequence scores stored. For each fold, the candidate with the best criterion
on the fold's *training* sequences is chosen and its stored scores on the left-out sequences are
reported (:func:`lookalike.tune.select_from_table`). Because the candidates are drawn without looking
at any score, this is exactly what running random search with that budget on each fold's training
sequences would give, at the cost of one pass; ``lookalike tune --folds loso`` runs the same
protocol with a study (TPE or random) per fold.

- leave one sequence out over MOT15's 7 sequences (the choice made on the other 6);
- leave one dataset out over ``--datasets`` (default mot15, pigs, mot17-synth; add hexbug with
  ``--datasets mot15,pigs,hexbug,mot17-synth``: its blob detection adds about a minute).

Printed beside: boxtrack's defaults, lookalike's ``sort`` and every installed peer of ``bench real``
(once each with their own defaults: they choose nothing; BoxMOT's trackers with their default presets,
:mod:`lookalike.bench.peers`). Each row says what its parameters were chosen on.

    .venv-bench/bin/python benchmarks/real_loso.py --workers 2            # ~10 min on 2 cores
    .venv-bench/bin/python benchmarks/real_loso.py --trials 12 --peers none --json loso.json
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np

from lookalike.bench.datasets import load_datasets
from lookalike.bench.peers import PEERS, peer_status
from lookalike.bench.runner import Entry, run_jobs
from lookalike.eval import combine, headline
from lookalike.tune import (
    default_space,
    evaluate_table,
    leave_one_group_out,
    sample,
    score_params,
    select_from_table,
    sequence_key,
)

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import SHARED_DATA

CRITERION = "hota+idf1+mota"


def candidates(trials: int, seed: int) -> list[dict[str, Any]]:
    """The defaults, then ``trials`` parameter sets drawn at random from boxtrack's default space."""
    rng = np.random.default_rng(seed)
    space = default_space("boxtrack")
    return [{}] + [sample(space, rng) for _ in range(trials)]


def _fmt(s: dict[str, float]) -> str:
    return f"{100 * s['HOTA']:6.2f} {100 * s['IDF1']:6.2f} {100 * s['MOTA']:6.2f} {100 * headline(s):7.2f}"


def _progress(done: int, total: int, t0: float = time.perf_counter()) -> None:
    if done == total or done % max(1, total // 20) == 0:
        print(f"  {done}/{total} runs, {time.perf_counter() - t0:.0f} s", flush=True)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--datasets", default="mot15,pigs,mot17-synth", help="comma-separated dev datasets")
    parser.add_argument("--trials", type=int, default=30, help="random parameter sets (besides the defaults)")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--peers", default=",".join(PEERS), help="comma-separated peers, or 'none'")
    parser.add_argument("--workers", type=int, default=1)
    parser.add_argument("--json", type=Path, default=None, help="write the figures and choices as JSON")
    args = parser.parse_args()
    names = [d.strip() for d in args.datasets.split(",") if d.strip()]
    try:
        seqs = load_datasets(SHARED_DATA, names, workers=args.workers)
    except FileNotFoundError as exc:
        sys.exit(f"{exc} (this benchmark needs ../shared/data)")
    keys = [sequence_key(s) for s in seqs]
    groups = [s.dataset for s in seqs]
    cands = candidates(args.trials, args.seed)
    print(f"criterion (fixed before running): HOTA + IDF1 + MOTA; {len(cands)} candidates (defaults + {args.trials} "
          f"random, seed {args.seed}) x {len(seqs)} sequences of {', '.join(names)}", flush=True)
    table = evaluate_table("boxtrack", cands, seqs, score_params, workers=args.workers, progress=_progress)
    out: dict[str, Any] = {"criterion": CRITERION, "trials": args.trials, "seed": args.seed, "candidates": cands}
    rows: dict[str, list[tuple[str, str, dict[str, float]]]] = {}

    mot15 = [i for i, s in enumerate(seqs) if s.dataset == "mot15"]
    if len(mot15) >= 2:
        sub = [[row[i] for i in mot15] for row in table]
        sub_keys = [keys[i] for i in mot15]
        choices = select_from_table(sub, leave_one_group_out(sub_keys), sub_keys, None, CRITERION, cands)
        print("\nMOT15, leave one sequence out: each choice made on the other 6 sequences only")
        for c in choices:
            print(f"  left out {c.left_out[0]:24s} chose #{c.candidate:<3d} (criterion on the other 6: "
                  f"{100 * c.train_value:.2f}) -> left-out {_fmt(c.test_scores)}")
        held = combine([s for c in choices for s in c.per_sequence])
        rows.setdefault("mot15", []).append(("boxtrack (LOSO choice)", "the other 6 MOT15 sequences", held))
        out["mot15_loso"] = [{"left_out": c.left_out, "chosen_on": c.chosen_on, "candidate": c.candidate,
                              "params": c.params, "HOTA": c.test_scores["HOTA"], "IDF1": c.test_scores["IDF1"],
                              "MOTA": c.test_scores["MOTA"]} for c in choices]
    if len(set(groups)) >= 2:
        choices = select_from_table(table, leave_one_group_out(groups), keys, groups, CRITERION, cands)
        print("\nLeave one dataset out: each choice made on the other datasets only (mean of their criteria)")
        out["lodo"] = []
        for c in choices:
            on = sorted({k.split('/')[0] for k in c.chosen_on})
            print(f"  left out {c.fold:12s} chose #{c.candidate:<3d} on {'+'.join(on)} "
                  f"-> left-out {_fmt(c.test_scores)}")
            print(f"    params: {c.params or 'defaults'}")
            rows.setdefault(c.fold, []).append(("boxtrack (LODO choice)", "+".join(on), c.test_scores))
            out["lodo"].append({"left_out": c.fold, "chosen_on": on, "candidate": c.candidate, "params": c.params,
                                "HOTA": c.test_scores["HOTA"], "IDF1": c.test_scores["IDF1"],
                                "MOTA": c.test_scores["MOTA"]})
    for d in dict.fromkeys(groups):
        idx = [i for i, g in enumerate(groups) if g == d]
        rows.setdefault(d, []).append(("boxtrack (defaults)", "boxtrack's defaults",
                                       combine([table[0][i] for i in idx])))
    wanted = [] if args.peers == "none" else [p.strip() for p in args.peers.split(",") if p.strip()]
    status = peer_status(wanted) if wanted else {}
    for p, why in status.items():
        if why is not None:
            print(f"skipped peer {p}: {why}")
    entries = [Entry("sort", "sort")] + [Entry(p, p, kind="peer") for p, why in status.items() if why is None]
    fixed = run_jobs(entries, seqs, workers=args.workers)
    for k, e in enumerate(entries):
        for d in dict.fromkeys(groups):
            runs = [fixed[i * len(entries) + k] for i, g in enumerate(groups) if g == d]
            if all("scores" in r for r in runs):
                rows[d].append((e.label, "its own defaults", combine([r["scores"] for r in runs])))
            else:
                print(f"{e.label} failed on {d}: {next(r['error'] for r in runs if 'error' in r)}")
    out["tables"] = {}
    for d, rs in rows.items():
        print(f"\n{d}: left-out figures ({'whole sequences' if d != 'mot15' else '7 sequences'})")
        print(f"{'tracker':26s} {'HOTA':>6} {'IDF1':>6} {'MOTA':>6} {'sum':>7}  chosen on")
        for label, on, s in sorted(rs, key=lambda t: -headline(t[2])):
            print(f"{label:26s} {_fmt(s)}  {on}")
        out["tables"][d] = [{"tracker": label, "chosen_on": on, "HOTA": s["HOTA"], "IDF1": s["IDF1"],
                             "MOTA": s["MOTA"]} for label, on, s in rs]
    if args.json is not None:
        args.json.write_text(json.dumps(out, indent=2, default=str) + "\n")


if __name__ == "__main__":
    main()
