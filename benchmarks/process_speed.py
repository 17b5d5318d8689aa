"""Whole-process times: ``import lookalike``, ``lookalike trackers --names``, and ``lookalike track -t
sort`` on the MOT15 sequences beside the reference SORT's own script doing the same job.

Run with ``make bench`` or ``python benchmarks/process_speed.py [--rounds 3]``. Every figure is
the CPU time (user + system) of a fresh process (median over rounds, the two trackers
interleaved), start-up, file reading and writing included: on an idle machine that is its wall
time, on a shared one the time spent waiting for a core is left out.
"""

from __future__ import annotations

import argparse
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from _common import SHARED_DATA, report_target

BIN = Path(sys.executable).parent
HERE = Path(__file__).resolve().parent


def wall(cmd: list[str]) -> float:
    """CPU seconds (user + system) a command takes from start to exit (it must succeed); on an idle
    machine this is its wall time, on a shared one the time spent waiting for a core is left out."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    elapsed = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return min(cpu, elapsed) if cpu > 0 else elapsed


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--data", default=str(SHARED_DATA / "mot15"))
    parser.add_argument("--rounds", type=int, default=3)
    args = parser.parse_args()
    lookalike = str(BIN / "lookalike")
    imports = statistics.median(wall([sys.executable, "-c", "import lookalike"]) for _ in range(2 * args.rounds))
    print(f"python -c 'import lookalike': {imports:.3f} s")
    report_target("import lookalike (s)", imports, 0.25, higher_is_better=False, unit=" s")
    names = statistics.median(wall([lookalike, "trackers", "--names"]) for _ in range(args.rounds))
    print(f"lookalike trackers --names: {names:.3f} s")
    report_target("lookalike trackers --names (s)", names, 0.5, higher_is_better=False, unit=" s")
    data = Path(args.data)
    if not data.is_dir():
        print(f"MOT15 data not found at {data}: whole-process comparison skipped")
        return 0
    try:
        import sort.sort  # noqa: F401
    except ImportError:
        print("reference SORT not installed: whole-process comparison skipped (make bench installs it)")
        return 0
    times: dict[str, list[float]] = {"lookalike track -t sort": [], "reference SORT script": []}
    with tempfile.TemporaryDirectory() as tmp:
        for _ in range(args.rounds):
            times["lookalike track -t sort"].append(wall([lookalike, "track", "-t", "sort", str(data), "-o",
                                                         f"{tmp}/ours"]))
            times["reference SORT script"].append(wall([sys.executable, str(HERE / "_reference_sort_script.py"),
                                                       str(data), f"{tmp}/reference"]))
    median = {name: statistics.median(t) for name, t in times.items()}
    for name, seconds in median.items():
        print(f"{name:26s} {seconds:6.2f} s (whole process CPU time, 7 sequences)")
    report_target("lookalike track -t sort vs the reference script, whole process (x)",
                  median["reference SORT script"] / median["lookalike track -t sort"], 3.0)
    return 0


if __name__ == "__main__":
    sys.exit(main())
