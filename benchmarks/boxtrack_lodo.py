"""boxtrack's defaults by leave-one-dataset-out (issue 16): the candidates, the choice per fold, the choice on all.

Datasets: MOT15's 7 sequences, the pigs, mot17-synth and the HexBug clips with videos (the blob
detector's boxes, cached on disk after the first run; boxtrack runs on them as ``lookalike track
--detector blob`` does, :func:`lookalike.vision.blob_boxtrack.blob_boxtrack_config`). Criterion
fixed before scoring: HOTA + IDF1 + MOTA summed, the mean over datasets of each dataset's combined
sum. Candidates: ``clutter_factor`` in {2, None, 1, 3, 4} x ``max_age_s`` in {1, 2, 3} x ``n_init``
in {3, 2}, each with the clutter share judged after each of ``--min-counts`` detections (a constant
of the code, patched in this process). Every candidate is scored once per sequence;
each fold's choice is the best candidate on the other datasets
(:func:`lookalike.tune.select_from_table`) and is scored on the left-out one. The defaults boxtrack
ships are the choice on all datasets; the left-out figures are the headline (docs/trackers/boxtrack.md).
Printed after them: every installed peer of ``bench real`` (BoxMOT's trackers with their default presets
included) once per dataset with its own defaults, and the best peer per column (``--peers none``: none).

    .venv/bin/python benchmarks/boxtrack_lodo.py                    # ~20 min on one core
    .venv/bin/python benchmarks/boxtrack_lodo.py --min-counts 10    # the current constant only
    .venv-bench/bin/python benchmarks/boxtrack_lodo.py --min-counts 10 --grid small   # with the peers (16 min)
"""

from __future__ import annotations

import argparse
import itertools
import pickle
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
from _peers import score_peers

CRITERION = "hota+idf1+mota"


GRIDS = {  # clutter_factor, max_age_s, n_init[, match_iou]
    "full": ([2.0, None, 1.0, 3.0, 4.0], [1.0, 2.0, 3.0], [3, 2]),
    # for comparing mechanisms on a 2-core budget: every value the full grid's folds chose (fixed before scoring)
    "small": ([2.0, 1.0, 4.0], [2.0, 3.0], [2]),
    # "small" with BoT-SORT's looser first-association overlap (its match threshold 0.8 on 1 - IoU·score)
    "match-iou": ([2.0, 1.0, 4.0], [2.0, 3.0], [2], [0.3, 0.2]),
}


def candidates(grid: str = "full") -> list[dict[str, Any]]:
    """The grid: clutter_factor x max_age_s x n_init (x match_iou), every other parameter at boxtrack's default."""
    names = ("clutter_factor", "max_age_s", "n_init", "match_iou")
    return [dict(zip(names, combo)) for combo in itertools.product(*GRIDS[grid])]


def _fmt(s: dict[str, float]) -> str:
    return f"{100 * s['HOTA']:.2f} / {100 * s['IDF1']:.2f} / {100 * s['MOTA']:.2f} (sum {100 * headline(s):.2f})"


def _score(datasets: list[str], min_counts: str, grid_name: str) -> tuple[list[dict[str, Any]], list[list[Any]],
                                                                        list[str], list[str]]:
    """Every candidate once on every sequence: ``(candidates, table, sequence keys, dataset groups)``."""
    seqs = load_datasets(SHARED_DATA, datasets)
    keys, groups = [sequence_key(s) for s in seqs], [s.dataset for s in seqs]
    cands: list[dict[str, Any]] = []
    table: list[list[Any]] = []
    for mc in (int(x) for x in min_counts.split(",")):
        boxtrack_config.CLUTTER_MIN_COUNT = mc  # read by BoxTrack at construction (this process only)
        grid = candidates(grid_name)
        table += evaluate_table("boxtrack", grid, seqs, score_params, workers=1)
        cands += [dict(c, clutter_min_count=mc) for c in grid]
        print(f"clutter min count {mc}: {len(grid)} candidates scored", flush=True)
    return cands, table, keys, groups


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--datasets", default="mot15,pigs,mot17-synth,hexbug")
    parser.add_argument("--min-counts", default="10,100", help="clutter share judged after these many detections")
    parser.add_argument("--grid", choices=sorted(GRIDS), default="full", help="the candidates (see GRIDS)")
    parser.add_argument("--set", action="append", default=[], metavar="CONST=VALUE",
                        help="patch a constant of trackers/boxtrack_config in this process (a mechanism on/off)")
    parser.add_argument("--save", type=Path, default=None, help="pickle the scores table here (for --load)")
    parser.add_argument("--load", type=Path, default=None, help="a table saved by --save: select, do not run")
    parser.add_argument("--peers", default="all", help="peers run beside: 'all' installed, 'none', or names")
    args = parser.parse_args()
    if args.load is None and len({d.strip() for d in args.datasets.split(",") if d.strip()}) < 2:
        parser.error(f"--datasets: leaving one dataset out needs at least two, got {args.datasets!r}")
    for spec in args.set:
        name, value = spec.split("=", 1)
        if not hasattr(boxtrack_config, name):
            parser.error(f"--set {spec}: boxtrack_config has no constant {name}")
        setattr(boxtrack_config, name, type(getattr(boxtrack_config, name))(float(value)))
        print(f"constant {name} = {getattr(boxtrack_config, name)}")
    if args.load is not None:
        cands, table, keys, groups = pickle.loads(args.load.read_bytes())
        if len(set(groups)) < 2:
            parser.error(f"--load {args.load}: leaving one dataset out needs at least two datasets, the table "
                         f"has {len(set(groups))}")
    else:
        cands, table, keys, groups = _score(args.datasets.split(","), args.min_counts, args.grid)
    if args.save is not None:
        args.save.write_bytes(pickle.dumps((cands, table, keys, groups)))
    print(f"criterion (fixed): HOTA + IDF1 + MOTA; {len(cands)} candidates x {len(keys)} sequences")
    for c in select_from_table(table, leave_one_group_out(groups), keys, groups, CRITERION, cands):
        on = sorted({k.split("/")[0] for k in c.chosen_on})
        print(f"left out {c.fold:12s} chosen on {'+'.join(on)}: {cands[c.candidate]} -> {_fmt(c.test_scores)}")
    mot15 = [i for i, g in enumerate(groups) if g == "mot15"]
    if len(mot15) >= 2:  # each MOT15 sequence left out of the choice, made on every other sequence
        folds = [Fold(keys[i], tuple(j for j in range(len(keys)) if j != i), (i,)) for i in mot15]
        loso = select_from_table(table, folds, keys, groups, CRITERION, cands)
        for c in loso:
            print(f"  MOT15 left out {c.fold:28s} chose {cands[c.candidate]} -> {_fmt(c.test_scores)}")
        print(f"left out MOT15 sequence by sequence (7 folds, combined): "
              f"{_fmt(combine([s for c in loso for s in c.per_sequence]))}")
    every = tuple(range(len(keys)))
    best = select_from_table(table, [Fold("all", every, every)], keys, groups, CRITERION, cands)[0]
    print(f"chosen on all ({'+'.join(dict.fromkeys(groups))}): {cands[best.candidate]}")
    for d in dict.fromkeys(groups):
        idx = [i for i, g in enumerate(groups) if g == d]
        print(f"  {d:12s} {_fmt(combine([table[best.candidate][i] for i in idx]))}")
    if args.peers != "none":
        _print_peers(score_peers(load_datasets(SHARED_DATA, list(dict.fromkeys(groups))), args.peers))


def _print_peers(scores: dict[str, dict[str, dict[str, float]]]) -> None:
    """Each peer's figures per dataset (its own defaults, chosen on none of it) and the best per column."""
    print("peers, each with its own defaults (whole datasets):")
    for d, by_peer in scores.items():
        for name, s in sorted(by_peer.items(), key=lambda t: -headline(t[1])):
            print(f"  {d:12s} {name:24s} {_fmt(s)}")
        best = {m: max(by_peer.items(), key=lambda t: t[1][m]) for m in ("HOTA", "IDF1", "MOTA")}
        print(f"  {d:12s} best peer per column: " + ", ".join(f"{m} {100 * s[m]:.2f} ({name})"
                                                             for m, (name, s) in best.items()))


if __name__ == "__main__":
    main()
