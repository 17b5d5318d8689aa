"""boxtrack's defaults by leave-one-dataset-out (issue 16): the candidates, the choice per fold, the choice on all.

Datasets: MOT15's 7 sequences, the pigs, mot17-synth and the HexBug clips with videos (the blob
detector's boxes, cached on disk after the first run). Criterion fixed before scoring: HOTA + IDF1 +
MOTA summed, the mean over datasets of each dataset's combined sum. Candidates: ``clutter_factor``
in {2, None, 1, 3, 4} x ``max_age_s`` in {1, 2, 3} x ``n_init`` in {3, 2}, each with the clutter
share judged after each of ``--min-counts`` detections (a constant of the code, patched in this
process). Every candidate is scored once per sequence;
each fold's choice is the best candidate on the other datasets
(:func:`lookalike.tune.select_from_table`) and is scored on the left-out one. The defaults boxtrack
ships are the choice on all datasets; the left-out figures are the headline (docs/trackers/boxtrack.md).

    .venv/bin/python benchmarks/boxtrack_lodo.py                    # ~20 min on one core
    .venv/bin/python benchmarks/boxtrack_lodo.py --min-counts 10    # the current constant only
"""

from __future__ import annotations

import argparse
import itertools
import sys
from pathlib import Path
from typing import Any

from lookalike.bench.datasets import load_datasets
from lookalike.eval import combine, headline
from lookalike.trackers import boxtrack_config
from lookalike.tune import evaluate_table, leave_one_group_out, score_params, select_from_table, sequence_key
from lookalike.tune.folds import Fold

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import SHARED_DATA

CRITERION = "hota+idf1+mota"


def candidates() -> list[dict[str, Any]]:
    """The grid: clutter_factor x max_age_s x n_init, every other parameter at boxtrack's default."""
    out = []
    for k, age, n in itertools.product([2.0, None, 1.0, 3.0, 4.0], [1.0, 2.0, 3.0], [3, 2]):
        out.append({"clutter_factor": k, "max_age_s": age, "n_init": n})
    return out


def _fmt(s: dict[str, float]) -> str:
    return f"{100 * s['HOTA']:.2f} / {100 * s['IDF1']:.2f} / {100 * s['MOTA']:.2f} (sum {100 * headline(s):.2f})"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--datasets", default="mot15,pigs,mot17-synth,hexbug")
    parser.add_argument("--min-counts", default="10,100", help="clutter share judged after these many detections")
    args = parser.parse_args()
    seqs = load_datasets(SHARED_DATA, args.datasets.split(","))
    keys, groups = [sequence_key(s) for s in seqs], [s.dataset for s in seqs]
    cands: list[dict[str, Any]] = []
    table: list[list[Any]] = []
    for mc in (int(x) for x in args.min_counts.split(",")):
        boxtrack_config.CLUTTER_MIN_COUNT = mc  # read by BoxTrack at construction (this process only)
        grid = candidates()
        table += evaluate_table("boxtrack", grid, seqs, score_params, workers=1)
        cands += [dict(c, clutter_min_count=mc) for c in grid]
        print(f"clutter min count {mc}: {len(grid)} candidates scored", flush=True)
    print(f"criterion (fixed): HOTA + IDF1 + MOTA; {len(cands)} candidates x {len(seqs)} sequences")
    for c in select_from_table(table, leave_one_group_out(groups), keys, groups, CRITERION, cands):
        on = sorted({k.split("/")[0] for k in c.chosen_on})
        print(f"left out {c.fold:12s} chosen on {'+'.join(on)}: {cands[c.candidate]} -> {_fmt(c.test_scores)}")
    every = tuple(range(len(seqs)))
    best = select_from_table(table, [Fold("all", every, every)], keys, groups, CRITERION, cands)[0]
    print(f"chosen on all ({'+'.join(dict.fromkeys(groups))}): {cands[best.candidate]}")
    for d in dict.fromkeys(groups):
        idx = [i for i, g in enumerate(groups) if g == d]
        print(f"  {d:12s} {_fmt(combine([table[best.candidate][i] for i in idx]))}")

if __name__ == "__main__":
    main()
