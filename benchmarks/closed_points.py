"""Identical animals given as anonymous points: closed set of N offline (``lookalike track --points FILE
--targets N --offline``'s library path) on simulated arenas, scored with ``evaluate_points``.

An arena: N identical points on correlated random walks (speed 1.5-4.5 px/frame, turning, bouncing off
the walls of a 400 px square), observed with 1 px noise, 5% of the points missed, 0.1 false points a
frame, 600 frames at 25 frames/s. Seeds 0-9 are where closed-set choices may be made; seeds 100-109 are
unseen by them (``--seeds``). ``--set KEY=VALUE`` overrides a ``ClosedSetConfig`` field; ``--vel-noise``
boxtrack's velocity noise for the points (default ``POINT_VEL_NOISE``, chosen on seeds 0-29). Run::

    python benchmarks/closed_points.py [--seeds 100-109] [--targets 5] [--set smooth_s=0] [--vel-noise 0.00625]
"""

from __future__ import annotations

import argparse
import time

import numpy as np
from closed_pigs import parse_overrides

from lookalike.eval import combine, evaluate_points
from lookalike.io.points import POINT_VEL_NOISE, PointFrames, points_to_rows, rows_to_points
from lookalike.trackers.offline.closed_set import ClosedSetConfig, assign_identities, online_rows

FPS = 25.0
RADIUS_PX = 10.0


def arena(n: int = 5, frames: int = 600, size: float = 400.0, speed: float = 3.0, turn: float = 0.3,
          noise: float = 1.0, miss: float = 0.05, clutter: float = 0.1,
          seed: int = 0) -> tuple[PointFrames, np.ndarray]:
    """Points per frame and ground truth rows ``(frame, id, x, y)`` of one simulated arena (px, frames)."""
    rng = np.random.default_rng(seed)
    pos = rng.uniform(50, size - 50, (n, 2))
    ang = rng.uniform(0, 2 * np.pi, n)
    sp = speed * rng.uniform(0.5, 1.5, n)
    gt, pts = [], []
    for k in range(frames):
        ang += rng.normal(0, turn, n)
        step = np.column_stack([np.cos(ang), np.sin(ang)]) * sp[:, None] * rng.uniform(0, 2, n)[:, None]
        pos = pos + step
        for d in range(2):
            out = (pos[:, d] < 0) | (pos[:, d] > size)
            pos[out, d] = np.clip(pos[out, d], 0, size)
            ang[out] = ang[out] + np.pi
        seen = rng.random(n) >= miss
        p = pos[seen] + rng.normal(0, noise, (int(seen.sum()), 2))
        c = rng.uniform(0, size, (rng.poisson(clutter), 2))
        pts.append(np.vstack([p, c]))
        gt += [(k + 1, i + 1, *pos[i]) for i in range(n)]
    return PointFrames(pts), np.array(gt)


def seeds_of(text: str) -> list[int]:
    lo, _, hi = text.partition("-")
    return list(range(int(lo), int(hi or lo) + 1))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n", 1)[0])
    ap.add_argument("--seeds", default="0-9", help="arena seeds, A-B (0-9: choices; 100-109: unseen)")
    ap.add_argument("--targets", type=int, default=5)
    ap.add_argument("--set", action="append", default=[], dest="overrides")
    ap.add_argument("--vel-noise", type=float, default=POINT_VEL_NOISE,
                    help="boxtrack's velocity noise for the points (0.00625: boxtrack's own, before the point rule)")
    args = ap.parse_args()
    cfg = ClosedSetConfig(**parse_overrides(args.overrides))  # type: ignore[arg-type]
    results, t0 = [], time.process_time()
    for seed in seeds_of(args.seeds):
        pf, gt = arena(n=args.targets, seed=seed)
        det = points_to_rows(pf)
        rows = assign_identities(online_rows(det, FPS, len(pf), n_init=1, vel_noise=args.vel_noise), args.targets, FPS,
                                 cfg)
        f, i, xy = rows_to_points(rows)
        results.append(evaluate_points(gt[:, 0].astype(int), gt[:, 1].astype(int), gt[:, 2:4], f, i, xy,
                                       radius=RADIUS_PX, num_frames=len(pf)))
        print(f"  seed {seed:4d}  IDF1 {100 * results[-1]['IDF1']:6.2f}  IDSW {int(results[-1]['IDSW'])}", flush=True)
    s = combine(results)
    print(f"points arenas of {args.targets}, seeds {args.seeds}: IDF1 {100 * s['IDF1']:.2f}  "
          f"HOTA {100 * s['HOTA']:.2f}  IDSW {int(s['IDSW'])}  ({time.process_time() - t0:.0f} s CPU)")


if __name__ == "__main__":
    main()
