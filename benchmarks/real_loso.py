"""boxtrack on sequences it has never seen: parameters chosen by leave-one-sequence-out on real data.

For every sequence of a dataset (MOT15's 7 by default), boxtrack's parameters are chosen from a grid
on the *other* sequences (whole, best HOTA + IDF1 + MOTA combined over them) and then scored on the
left-out one, which no choice looked at. The left-out scores are combined over the sequences (as
TrackEval combines) and printed beside the peers, which run once with their documented defaults (they
choose nothing), as is lookalike's ``sort``. The online tracker and its offline post-processing (``boxtrack-offline``, the
dataset's ``OFFLINE_PARAMS``) are chosen separately from the same tracking runs. This is the check
behind "the same ranking on unseen sequences" with real detections: it says how the way boxtrack's
parameters are chosen carries to a sequence outside the choice.

    .venv-bench/bin/python benchmarks/real_loso.py --workers 2
    .venv-bench/bin/python benchmarks/real_loso.py --grid high_score=0.8,0.9 --grid n_init=2,3 --peers none
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any

from lookalike.cli.bench_peers import PEERS, peer_status
from lookalike.cli.bench_real import load_datasets
from lookalike.cli.bench_real_data import DATASETS, RealSequence
from lookalike.cli.bench_real_run import OFFLINE_PARAMS, Entry, run_jobs, score_rows, track_rows
from lookalike.eval import combine, headline, leave_one_out
from lookalike.parallel import JobPool
from lookalike.trackers.offline import OfflineConfig, postprocess

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import SHARED_DATA, parameter_grid

DEFAULT_GRID = ("high_score=0.7,0.8,0.9,0.95", "birth_score=0.9,0.95,0.98", "n_init=2,3", "match_iou=0.2,0.3",
                "max_age_s=1,2")


def track_both(job: tuple[dict[str, Any], RealSequence]) -> tuple[dict[str, float], dict[str, float]]:
    """Scores of boxtrack with ``params`` on the sequence: online, and post-processed offline."""
    params, seq = job
    rows = track_rows(Entry("boxtrack", "boxtrack", params=params, per_sequence=False), seq, dataset_params={})
    offline = postprocess(rows, seq.frame_rate, OfflineConfig(**OFFLINE_PARAMS.get(seq.dataset, {})))
    return score_rows(seq, rows), score_rows(seq, offline)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--dataset", default="mot15", choices=DATASETS)
    parser.add_argument("--grid", action="append", default=[], help="KEY=V1,V2,... (repeatable; "
                        f"default: {' '.join(DEFAULT_GRID)})")
    parser.add_argument("--peers", default=",".join(PEERS), help="comma-separated peers, or 'none'")
    parser.add_argument("--workers", type=int, default=1)
    args = parser.parse_args()
    try:
        seqs = load_datasets(SHARED_DATA, [args.dataset])
    except FileNotFoundError as exc:
        sys.exit(f"{exc} (this benchmark needs ../shared/data)")
    if len(seqs) < 2:
        sys.exit(f"{args.dataset}: leaving one sequence out needs at least two sequences, it has {len(seqs)}")
    combos = parameter_grid("boxtrack", args.grid or DEFAULT_GRID)
    print(f"{len(combos)} combinations × {len(seqs)} sequences ({args.dataset}), leave one sequence out",
          flush=True)
    jobs = [(p, s) for p in combos for s in seqs]
    with JobPool(min(args.workers, len(jobs))) as pool:
        results = pool.map(track_both, jobs)
    online = [[results[k * len(seqs) + i][0] for i in range(len(seqs))] for k in range(len(combos))]
    offline = [[results[k * len(seqs) + i][1] for i in range(len(seqs))] for k in range(len(combos))]
    rows: list[tuple[str, dict[str, float]]] = []
    for label, table in (("boxtrack (left out)", online), ("boxtrack-offline (left out)", offline)):
        held, chosen = leave_one_out(table)
        rows.append((label, held))
        print(f"{label}: chosen on the other sequences")
        for seq, k in zip(seqs, chosen):
            print(f"  {seq.name:16s} {combos[k]}")
    default_runs = [track_both(({}, s)) for s in seqs]
    rows += [("boxtrack (defaults)", combine([r[0] for r in default_runs])),
             ("boxtrack-offline (defaults)", combine([r[1] for r in default_runs]))]
    wanted = [] if args.peers == "none" else [p.strip() for p in args.peers.split(",") if p.strip()]
    peers = [p for p, why in peer_status(wanted).items() if why is None] if wanted else []
    # lookalike's SORT (nothing to choose) and the peers, once each with their defaults
    entries = [Entry("sort", "sort")] + [Entry(p, p, kind="peer") for p in peers]
    fixed = run_jobs(entries, seqs, workers=args.workers)
    for k, e in enumerate(entries):
        runs = [fixed[i * len(entries) + k] for i in range(len(seqs))]
        if all("scores" in r for r in runs):
            rows.append((e.label, combine([r["scores"] for r in runs])))
    print(f"\n{'tracker':30s} {'HOTA':>6} {'IDF1':>6} {'MOTA':>6}")
    for label, s in sorted(rows, key=lambda t: -headline(t[1])):
        print(f"{label:30s} {100 * s['HOTA']:6.2f} {100 * s['IDF1']:6.2f} {100 * s['MOTA']:6.2f}")


if __name__ == "__main__":
    main()
