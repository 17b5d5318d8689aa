"""Peak memory of ``lookalike track --points`` against the number of points a frame: linear, under 500 MB at 10,000.

Writes a ``frame,x,y`` CSV of ``--points`` random walkers (1 px noise, 5 % missed) spread over a square whose side
grows with the square root of their number (so their spacing stays the same), ``--frames`` frames each, runs
``lookalike track --points FILE -t TRACKER -o out.txt`` on each in a fresh Python process and prints that process's
peak resident memory (``ru_maxrss``), wall time and result rows. ``--offline N`` adds ``--targets N --offline``.

``python benchmarks/points_memory.py [--points 1000,10000] [--frames 20] [--tracker boxtrack] [--src DIR]``
"""

from __future__ import annotations

import argparse
import sys
import tempfile
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import report_target  # noqa: E402
from track_memory import MEASURE  # noqa: E402

LIMIT_MIB = 500.0


def write_points(path: Path, n: int, frames: int, seed: int = 0) -> None:
    rng = np.random.default_rng(seed)
    pos = rng.uniform(0, 40 * np.sqrt(n), (n, 2))
    vel = rng.normal(0, 2, (n, 2))
    with path.open("w") as fh:
        fh.write("frame,x,y\n")
        for k in range(frames):
            pos += vel + rng.normal(0, 0.3, (n, 2))
            keep = rng.random(n) >= 0.05
            seen = pos[keep] + rng.normal(0, 1.0, (int(keep.sum()), 2))
            fh.writelines(f"{k + 1},{x:.2f},{y:.2f}\n" for x, y in seen)


def main() -> int:
    import subprocess
    import time

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--points", default="1000,10000", help="Comma-separated points a frame.")
    parser.add_argument("--frames", type=int, default=20)
    parser.add_argument("--tracker", default="boxtrack")
    parser.add_argument("--offline", type=int, default=None, help="also --targets N --offline")
    parser.add_argument("--src", default=None, help="PYTHONPATH of the code to measure (default: this one).")
    args = parser.parse_args()
    worst = 0.0
    with tempfile.TemporaryDirectory() as tmp:
        for n in (int(v) for v in args.points.split(",")):
            csv = Path(tmp) / f"p{n}.csv"
            write_points(csv, n, args.frames)
            closed = [] if args.offline is None else ["--targets", str(args.offline), "--offline"]
            extra = ["-t", args.tracker, *closed]
            out = Path(tmp) / "out.txt"
            out.unlink(missing_ok=True)
            env = None if args.src is None else {**__import__("os").environ, "PYTHONPATH": args.src}
            t0 = time.perf_counter()
            proc = subprocess.run([sys.executable, "-c", MEASURE, "track", "--points", str(csv), "-o",
                                   str(out), *extra], capture_output=True, text=True, env=env)
            seconds = time.perf_counter() - t0
            line = next((ln for ln in proc.stdout.splitlines() if ln.startswith("MAXRSS_KIB")), None)
            if proc.returncode != 0 or line is None or not out.exists():
                print(f"{n:>7,} points a frame: failed ({proc.returncode}): {proc.stdout[-300:]}{proc.stderr[-300:]}")
                return 1
            mib = int(line.split()[1]) / 1024
            worst = max(worst, mib)
            rows = sum(1 for _ in out.open())
            print(f"{n:>7,} points a frame x {args.frames} frames, {args.tracker}"
                  f"{'' if args.offline is None else f' --targets {args.offline} --offline'}: peak RSS {mib:7.1f} MiB, "
                  f"{seconds:6.1f} s, {rows:,} result rows", flush=True)
    mode = "offline" if args.offline is not None else "online"
    passed = report_target(f"points {args.tracker} {mode}, peak memory at up to {n:,} points a frame", worst,
                           LIMIT_MIB, higher_is_better=False, unit=" MiB")
    return 0 if passed else 1


if __name__ == "__main__":
    sys.exit(main())
