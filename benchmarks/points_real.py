"""Real anonymous points: the HexBug head points (all 100 CSVs in ``hexbug/``) fed to the point path as
anonymous points, tracked as ``lookalike track --points FILE --targets N [--offline]`` does (points as
boxes of half their typical spacing, boxtrack with ``POINT_VEL_NOISE``; N = the ids in the clip's CSV),
and scored against the same CSV's ids with ``evaluate_points``.

Nobody chose anything on these clips: the point path's rules were chosen on simulated arenas
(``benchmarks/closed_points.py`` seeds 0-29). ``--vel-noise`` replaces the point velocity noise
(``0.00625``: boxtrack's own VEL_NOISE, the path before the point rule). The points are exact
(hand-annotated heads), so the score radius is small: ``--radius`` px (default 20). The input has the
CSV's orientation, as has the truth, so (x, y) or (y, x) does not matter. Run::

    .venv/bin/python benchmarks/points_real.py [--online] [--vel-noise 0.00625] [--limit 20]
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from lookalike.bench.datasets import read_hexbug_points, resolve_data_root
from lookalike.eval import combine, evaluate_points
from lookalike.io.points import POINT_VEL_NOISE, PointFrames, points_to_rows, rows_to_points
from lookalike.trackers.offline.closed_set import assign_identities, online_rows

FPS = 25.0  # lookalike track --points' default frame rate (no --fps)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n", 1)[0])
    ap.add_argument("--data", default=None, help="data root (default: the shared data)")
    ap.add_argument("--vel-noise", type=float, default=POINT_VEL_NOISE)
    ap.add_argument("--online", action="store_true", help="online closed set (--targets N without --offline)")
    ap.add_argument("--radius", type=float, default=20.0, help="score radius (px)")
    ap.add_argument("--limit", type=int, default=0, help="first K clips only (0: all)")
    args = ap.parse_args()
    try:
        root = resolve_data_root(args.data) / "hexbug"
    except FileNotFoundError as exc:
        raise SystemExit(f"points_real: {exc}") from None
    clips = sorted(root.glob("*.csv"))[:args.limit or None]
    if not clips:
        raise SystemExit(f"{root}: no HexBug CSVs")
    results, t0 = [], time.process_time()
    for csv in clips:
        frame, ident, xy = read_hexbug_points(csv)
        n_frames, n = int(frame.max()), len(np.unique(ident))
        pf = PointFrames([xy[frame == k] for k in range(1, n_frames + 1)])
        det = points_to_rows(pf)
        if args.online:
            rows = online_rows(det, FPS, n_frames, max_targets=n, vel_noise=args.vel_noise)
        else:
            rows = assign_identities(online_rows(det, FPS, n_frames, n_init=1, vel_noise=args.vel_noise), n, FPS)
        f, i, p = rows_to_points(rows)
        results.append(evaluate_points(frame, ident, xy, f, i, p, radius=args.radius, num_frames=n_frames))
        print(f"  {csv.stem:16s} {n} ids {n_frames:4d} frames  IDF1 {100 * results[-1]['IDF1']:6.2f}  "
              f"IDSW {int(results[-1]['IDSW'])}", flush=True)
    s = combine(results)
    mean = 100 * float(np.mean([r["IDF1"] for r in results]))
    mode = "online closed set" if args.online else "offline closed set"
    print(f"HexBug head points (unseen), {len(results)} clips, {mode}, vel_noise {args.vel_noise:g}: "
          f"IDF1 {100 * s['IDF1']:.2f} (mean per clip {mean:.2f})  HOTA {100 * s['HOTA']:.2f}  "
          f"IDSW {int(s['IDSW'])}  ({time.process_time() - t0:.0f} s CPU)")


if __name__ == "__main__":
    main()
