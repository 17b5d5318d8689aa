"""The warm blob command of ``benchmarks/blob_video_speed.py`` (cached detections) for two versions of the package,
interleaved, several times each: median frames/s of CPU time per clip and version, and whether their result files
are byte-equal. Each version is a ``git worktree`` (``git worktree add /tmp/w/before COMMIT``). Run from the
repository root with ../shared/data beside it::

    OMP_NUM_THREADS=1 .venv/bin/python research/speed/warm_pair.py /tmp/w/before /tmp/w/after --rounds 5
"""

from __future__ import annotations

import argparse
import filecmp
import os
import resource
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

DATA = Path(__file__).resolve().parents[2].parent / "shared" / "data"
CLIPS = {"test_A": (DATA / "zebrafish" / "test_A.avi", 8, 501), "hexbug": (DATA / "hexbug" / "training010.mp4", 3, 101)}
ONE_CORE = {k: "1" for k in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "NUMBA_NUM_THREADS", "OPENCV_FOR_THREADS_NUM")}


def child_cpu() -> float:
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("versions", nargs=2, type=Path, help="two worktrees (their src/ is put on PYTHONPATH)")
    parser.add_argument("--rounds", type=int, default=5)
    args = parser.parse_args()
    rates: dict[tuple[str, Path], list[float]] = {}
    with tempfile.TemporaryDirectory() as tmp:
        for rnd in range(args.rounds + 1):  # round 0 fills each clip's cache (not counted)
            for clip, (video, n, frames) in CLIPS.items():
                for version in args.versions:
                    env = {**os.environ, **ONE_CORE, "PYTHONPATH": str(version / "src"),
                           "LOOKALIKE_CACHE": str(Path(tmp) / clip)}
                    out = Path(tmp) / f"{clip}-{version.name}.txt"
                    before = child_cpu()
                    subprocess.run([sys.executable, "-m", "lookalike", "track", "--video", str(video), "--detector",
                                    "blob", "-t", "boxtrack", "--targets", str(n), "--online", "-o", str(out)],
                                   env=env, check=True, capture_output=True)
                    if rnd:
                        rates.setdefault((clip, version), []).append(frames / (child_cpu() - before))
        for clip in CLIPS:
            a, b = (Path(tmp) / f"{clip}-{v.name}.txt" for v in args.versions)
            print(f"{clip}: result files byte-equal: {filecmp.cmp(a, b, shallow=False)}")
    for (clip, version), r in rates.items():
        print(f"{clip} {version.name}: median {statistics.median(r):.1f} frames/s of CPU over {len(r)} runs "
              f"({', '.join(f'{x:.0f}' for x in r)})")


if __name__ == "__main__":
    main()
