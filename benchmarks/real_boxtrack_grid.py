"""Choose boxtrack's parameters on the first half of each sequence (never on what is scored).

Each MOT15 sequence (or the pigs) is cut to frames 1..⌊N/2⌋ — detections and ground truth — and
every combination of the grid is tracked and scored there (CLEAR/identity/HOTA combined over the
sequences). Rows are sorted by HOTA + IDF1 + MOTA, the criterion used for boxtrack's defaults and
for the pigs' score thresholds in ``lookalike bench real``.

    .venv/bin/python benchmarks/real_boxtrack_grid.py --dataset mot15 \\
        --grid high_score=0.7,0.8,0.9 --grid birth_score=0.8,0.9,0.95 --grid match_iou=0.2,0.3
    .venv/bin/python benchmarks/real_boxtrack_grid.py --dataset pigs --set max_targets=23 \\
        --grid high_score=0.5,0.7,0.8,0.9 --grid birth_score=0.5,0.7,0.8,0.9
"""

from __future__ import annotations

import argparse
import itertools
import sys
from pathlib import Path

from lookalike.cli.bench_real_data import RealSequence, cut_sequence, load_boxes
from lookalike.cli.bench_real_run import Entry, run_jobs
from lookalike.eval import combine
from lookalike.trackers.registry import parse_parameter

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import SHARED_DATA


def first_half(seq: RealSequence) -> RealSequence:
    """The sequence cut to frames ``1..⌊length/2⌋`` (detections and ground truth)."""
    return cut_sequence(seq, "first")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--dataset", choices=("mot15", "pigs"), default="mot15")
    parser.add_argument("--grid", action="append", default=[], help="KEY=V1,V2,... (repeatable)")
    parser.add_argument("--set", action="append", default=[], help="KEY=VALUE fixed for every run")
    parser.add_argument("--full", action="store_true", help="score whole sequences (for the report only)")
    parser.add_argument("--workers", type=int, default=1)
    args = parser.parse_args()
    root = SHARED_DATA / args.dataset
    if not root.is_dir():
        sys.exit(f"data not found at {root}")
    seqs = load_boxes(root, args.dataset)
    if not args.full:
        seqs = [first_half(s) for s in seqs]
    fixed = dict(parse_parameter("boxtrack", a) for a in args.set)
    keys, values = [], []
    for g in args.grid:
        key, _, text = g.partition("=")
        keys.append(key.strip())
        values.append([parse_parameter("boxtrack", f"{key}={v}")[1] for v in text.split(",")])
    combos = [dict(zip(keys, c), **fixed) for c in itertools.product(*values)] or [fixed]
    entries = [Entry(str(k), "boxtrack", params=p) for k, p in enumerate(combos)]
    results = run_jobs(entries, seqs, workers=args.workers)
    scored = []
    for k, params in enumerate(combos):
        runs = [results[i * len(entries) + k] for i in range(len(seqs))]
        c = combine([r["scores"] for r in runs])
        scored.append((100 * (c["HOTA"] + c["IDF1"] + c["MOTA"]), c, params))
    print(f"{'HOTA':>6} {'IDF1':>6} {'MOTA':>6}  parameters ({'whole' if args.full else 'first half of each'} sequence)")
    for _, c, params in sorted(scored, key=lambda t: t[0]):
        print(f"{100 * c['HOTA']:6.2f} {100 * c['IDF1']:6.2f} {100 * c['MOTA']:6.2f}  {params}")


if __name__ == "__main__":
    main()
