"""Choose boxtrack's parameters on the first half of each sequence (never on what is scored).

Each MOT15 sequence (or the pigs) is cut to frames 1..⌊N/2⌋ — detections and ground truth — and
every combination of the grid is tracked and scored there (CLEAR/identity/HOTA combined over the
sequences). Rows are sorted by HOTA + IDF1 + MOTA, the criterion used for boxtrack's defaults and
for the pigs' score thresholds in ``lookalike bench real``. ``--per-sequence`` also prints the best
combination of each sequence on its own first half (``SEQUENCE_PARAMS`` of ``lookalike bench real``).
``--sequence-params`` starts every combination from the per-sequence parameters (as the ``boxtrack``
entry of ``lookalike bench real``; the grid overrides them) instead of the defaults.
``--offline KEY=V1,...`` instead tracks once with ``lookalike bench real``'s parameters (per dataset
and per sequence) and grids the offline post-processing (``trackers.offline``; ``OFFLINE_PARAMS``).

    .venv/bin/python benchmarks/real_boxtrack_grid.py --dataset mot15 \\
        --grid high_score=0.7,0.8,0.9 --grid birth_score=0.8,0.9,0.95 --grid match_iou=0.2,0.3
    .venv/bin/python benchmarks/real_boxtrack_grid.py --dataset pigs --set max_targets=23 \\
        --grid high_score=0.5,0.7,0.8,0.9 --grid birth_score=0.5,0.7,0.8,0.9
    .venv/bin/python benchmarks/real_boxtrack_grid.py --dataset mot15 --per-sequence \\
        --grid high_score=0.7,0.8,0.9,0.95 --grid birth_score=0.8,0.9,0.95,0.98 --grid birth_quantile=none,0.5 \\
        --grid n_init=2,3 --grid max_age_s=1,2 --grid report=filtered,detection --grid match_iou=0.2,0.3
    .venv/bin/python benchmarks/real_boxtrack_grid.py --dataset mot15 --offline link_gap_s=0,1,2,4 \\
        --offline link_distance=0.5,1,2 --offline coast_s=0,0.5 --offline fill_gap_s=0,0.5,1,2
"""

from __future__ import annotations

import argparse
import itertools
import sys
from pathlib import Path

from lookalike.cli.bench_real import load_datasets
from lookalike.cli.bench_real_data import DATASETS, RealSequence, cut_sequence
from lookalike.cli.bench_real_run import Entry, run_jobs, score_rows, track_rows
from lookalike.eval import combine, headline
from lookalike.trackers.offline import OfflineConfig, postprocess
from lookalike.trackers.registry import parse_parameter

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import SHARED_DATA, parameter_grid


def first_half(seq: RealSequence) -> RealSequence:
    """The sequence cut to frames ``1..⌊length/2⌋`` (detections and ground truth)."""
    return cut_sequence(seq, "first")


def _values(text: str) -> list[float | None]:
    return [None if v.strip().lower() == "none" else float(v) for v in text.split(",")]


def offline_grid(seqs: list[RealSequence], grid: list[str]) -> list[tuple[dict, dict]]:
    """``(scores combined over seqs, offline parameters)`` for every combination of ``grid``
    (``KEY=V1,V2,...``), the online rows tracked once with ``lookalike bench real``'s parameters."""
    keys = [g.partition("=")[0].strip() for g in grid]
    values = [_values(g.partition("=")[2]) for g in grid]
    rows = [track_rows(Entry("boxtrack", "boxtrack"), s) for s in seqs]  # the open-set entry
    out = []
    for combo in itertools.product(*values):
        params = {k: (int(v) if k == "velocity_frames" else v) for k, v in zip(keys, combo)}
        cfg = OfflineConfig(**params)
        out.append((combine([score_rows(s, postprocess(r, s.frame_rate, cfg)) for s, r in zip(seqs, rows)]),
                    params))
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--dataset", choices=DATASETS, default="mot15")
    parser.add_argument("--grid", action="append", default=[], help="KEY=V1,V2,... (repeatable)")
    parser.add_argument("--set", action="append", default=[], help="KEY=VALUE fixed for every run")
    parser.add_argument("--full", action="store_true", help="score whole sequences (for the report only)")
    parser.add_argument("--workers", type=int, default=1)
    parser.add_argument("--offline", action="append", default=[],
                        help="KEY=V1,V2,... of trackers.offline.OfflineConfig (repeatable): grid the post-processing")
    parser.add_argument("--sequence-params", action="store_true",
                        help="start from lookalike bench real's per-sequence parameters (SEQUENCE_PARAMS), "
                             "the grid overriding them (as the 'boxtrack' entry; default: as 'boxtrack-global')")
    parser.add_argument("--per-sequence", action="store_true",
                        help="also print the best combination of each sequence alone (its first half)")
    args = parser.parse_args()
    try:
        seqs = load_datasets(SHARED_DATA, [args.dataset])
    except FileNotFoundError as exc:
        sys.exit(str(exc))
    if not args.full:
        seqs = [first_half(s) for s in seqs]
    if args.offline:
        scored_offline = offline_grid(seqs, args.offline)
        print(f"{'HOTA':>6} {'IDF1':>6} {'MOTA':>6}  offline parameters")
        for c, params in sorted(scored_offline, key=lambda t: headline(t[0])):
            print(f"{100 * c['HOTA']:6.2f} {100 * c['IDF1']:6.2f} {100 * c['MOTA']:6.2f}  {params}")
        return
    fixed = dict(parse_parameter("boxtrack", a) for a in args.set)
    combos = [{**c, **fixed} for c in parameter_grid("boxtrack", args.grid)]
    # defaults plus the grid; the per-sequence choices of ``lookalike bench real`` only with --sequence-params
    entries = [Entry(str(k), "boxtrack", params=p, per_sequence=args.sequence_params) for k, p in enumerate(combos)]
    results = run_jobs(entries, seqs, workers=args.workers)
    scored = []
    for k, params in enumerate(combos):
        runs = [results[i * len(entries) + k] for i in range(len(seqs))]
        c = combine([r["scores"] for r in runs])
        scored.append((100 * headline(c), c, params))
    print(f"{'HOTA':>6} {'IDF1':>6} {'MOTA':>6}  parameters ({'whole' if args.full else 'first half of each'} sequence)")
    for _, c, params in sorted(scored, key=lambda t: t[0]):
        print(f"{100 * c['HOTA']:6.2f} {100 * c['IDF1']:6.2f} {100 * c['MOTA']:6.2f}  {params}")
    if args.per_sequence:
        print("best per sequence (HOTA + IDF1 + MOTA of that sequence; first combination on ties):")
        for i, seq in enumerate(seqs):
            runs = [results[i * len(entries) + k]["scores"] for k in range(len(combos))]
            best = max(range(len(combos)), key=lambda k: (headline(runs[k]), -k))
            s = runs[best]
            print(f"{seq.name}: {100 * s['HOTA']:.2f} {100 * s['IDF1']:.2f} {100 * s['MOTA']:.2f}  {combos[best]}")


if __name__ == "__main__":
    main()
