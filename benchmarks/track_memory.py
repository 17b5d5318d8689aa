"""Peak memory of ``lookalike track`` against the number of frames: it must not grow with them.

Writes synthetic MOTChallenge detection files (``--targets`` boxes bouncing in a 1920×1080 frame with
1 px noise, 10 % missed, one false box every other frame) of each ``--frames`` length, runs
``lookalike track -t TRACKER det.txt -o out.txt`` on each in a fresh Python process and prints that
process's peak resident memory (``ru_maxrss``). The streaming frame loop (:func:`lookalike.loop.run`
with :class:`lookalike.io.DetectionStream` and :class:`lookalike.io.MotWriter`) keeps it constant;
issue 17 asks for 100,000 frames within 20 MiB of 10,000.

``python benchmarks/track_memory.py [--frames 10000,100000] [--tracker sort] [--src DIR]``
(``--src`` runs the code at another checkout's ``src`` instead, e.g. an older commit, for comparison).
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

MEASURE = """
import resource, sys
from lookalike.cli import app
try:
    app(sys.argv[1:], standalone_mode=False)
finally:
    print("MAXRSS_KIB", resource.getrusage(resource.RUSAGE_SELF).ru_maxrss)
"""


def write_detections(path: Path, frames: int, targets: int, seed: int = 0) -> None:
    """A det.txt of ``frames`` frames, written in blocks (never held whole in memory)."""
    rng = np.random.default_rng(seed)
    size = np.array([1920.0, 1080.0])
    box = np.array([40.0, 90.0])
    pos = rng.uniform(0, 1, (targets, 2)) * (size - box)
    vel = rng.uniform(-4, 4, (targets, 2))
    with path.open("w") as fh:
        for k in range(frames):
            pos += vel
            bounce = (pos < 0) | (pos > size - box)
            vel[bounce] *= -1
            pos = np.clip(pos, 0, size - box)
            keep = rng.random(targets) >= 0.1
            seen = pos[keep] + rng.normal(0, 1.0, (int(keep.sum()), 2))
            lines = [f"{k + 1},-1,{x:.2f},{y:.2f},{box[0]:.1f},{box[1]:.1f},{rng.uniform(0.6, 1):.3f},-1,-1,-1\n"
                     for x, y in seen]
            if k % 2 == 0:
                x, y = rng.uniform(0, 1, 2) * (size - box)
                lines.append(f"{k + 1},-1,{x:.2f},{y:.2f},{box[0]:.1f},{box[1]:.1f},"
                             f"{rng.uniform(0.3, 0.7):.3f},-1,-1,-1\n")
            fh.writelines(lines)


def peak_rss_mib(det: Path, out: Path, tracker: str, src: str | None) -> tuple[float, float]:
    """Peak resident memory (MiB) and wall time (s) of one ``lookalike track`` run in a fresh process."""
    env = dict(os.environ)
    if src:
        env["PYTHONPATH"] = src
    t0 = time.perf_counter()
    proc = subprocess.run([sys.executable, "-c", MEASURE, "track", "-t", tracker, str(det), "-o", str(out)],
                          capture_output=True, text=True, env=env)
    seconds = time.perf_counter() - t0
    line = next((ln for ln in proc.stdout.splitlines() if ln.startswith("MAXRSS_KIB")), None)
    if proc.returncode != 0 or line is None:
        raise SystemExit(f"track failed ({proc.returncode}): {proc.stderr[-2000:]}")
    return int(line.split()[1]) / 1024, seconds


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--frames", default="10000,100000", help="Comma-separated frame counts.")
    parser.add_argument("--targets", type=int, default=8)
    parser.add_argument("--tracker", default="sort")
    parser.add_argument("--src", default=None, help="PYTHONPATH of the code to measure (default: this one).")
    parser.add_argument("--limit-mib", type=float, default=20.0, help="Allowed growth from the first to the last.")
    args = parser.parse_args()
    counts = [int(v) for v in args.frames.split(",")]
    peaks = []
    with tempfile.TemporaryDirectory() as tmp:
        for n in counts:
            det = Path(tmp) / f"det{n}.txt"
            write_detections(det, n, args.targets)
            mib, seconds = peak_rss_mib(det, Path(tmp) / f"out{n}.txt", args.tracker, args.src)
            rows = sum(1 for _ in (Path(tmp) / f"out{n}.txt").open())
            peaks.append(mib)
            print(f"{args.tracker}: {n:>7,} frames ({det.stat().st_size / 2**20:6.1f} MiB det.txt, "
                  f"{rows:,} result rows): "
                  f"peak RSS {mib:7.1f} MiB, {seconds:6.1f} s", flush=True)
    growth = peaks[-1] - peaks[0]
    ok = growth <= args.limit_mib
    print(f"growth from {counts[0]:,} to {counts[-1]:,} frames: {growth:+.1f} MiB "
          f"({'within' if ok else 'over'} {args.limit_mib:g} MiB)")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
