"""Time HOTA + CLEAR + Identity over the 7 MOT17 training sequences: lookalike vs TrackEval.

    .venv-bench/bin/python benchmarks/eval_speed.py [--trackeval-python /tmp/tev/bin/python] [--repeats 3]

TrackEval (PyPI ``trackeval``, pinned in constraints-bench.txt) needs numpy < 2: ``make bench`` runs
this in .venv-bench where it is importable; elsewhere pass ``--trackeval-python``. Two measurements of
CPU time (on a shared machine the waits for a core are left out; the whole-process wall times are
printed too), rounds interleaved (lookalike, TrackEval, lookalike, ...), medians:

- in process: ``evaluate_folders`` vs TrackEval's ``Evaluator`` (both read the files and score);
- whole process: ``python -m lookalike eval --benchmark MOT17`` (start-up, imports, table printed) vs a
  fresh interpreter importing TrackEval and doing the same work. Both run as installed packages do:
  bytecode compiled once (pip compiles a wheel's modules at install, as TrackEval's are) and reused,
  in a private ``PYTHONPYCACHEPREFIX`` warmed by one untimed run of each command. Without that, a
  shell with ``PYTHONDONTWRITEBYTECODE=1`` recompiles lookalike's sources (an editable install) on
  every start but not TrackEval's; ``--compile-each-run`` measures that way.

It prints both times, the ratios against the issue-18 target (>= 6x) and the largest difference over
every shared value (they must agree to 1e-6).
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from _common import SHARED_DATA, report_target

MOT17 = SHARED_DATA / "mot17"


def _lengths() -> dict[str, int]:
    out = {}
    for seq in sorted((MOT17 / "gt").iterdir()):
        for line in (seq / "seqinfo.ini").read_text().splitlines():
            if line.startswith("seqLength="):
                out[seq.name] = int(line.split("=")[1])
    return out


def run_lookalike(repeats: int) -> tuple[list[float], dict[str, dict[str, float]]]:
    from lookalike.eval.folders import evaluate_folders

    times, result = [], {}
    for _ in range(repeats):
        t0 = time.process_time()
        result = evaluate_folders(MOT17 / "gt", MOT17 / "tracker_output", benchmark="MOT17")
        times.append(time.process_time() - t0)
    result.pop("COMBINED")
    return times, result


def installed_env(cache: str) -> dict[str, str]:
    """This environment as an installed package runs in: bytecode written to and read from ``cache``
    (a folder) instead of never written (``PYTHONDONTWRITEBYTECODE``)."""
    env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
    env["PYTHONPYCACHEPREFIX"] = cache
    return env


def whole_process(command: list[str], env: dict[str, str] | None = None) -> tuple[float, float]:
    """CPU seconds (user + system) and wall seconds of a fresh process running ``command`` (it must
    succeed) in ``env`` (default: this one); on a shared machine the CPU time leaves out the waits for a core."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    subprocess.run(command, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, env=env)
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime), wall


def run_trackeval_here(repeats: int) -> tuple[list[float], dict[str, dict[str, float]]]:
    import numpy as np
    import trackeval

    lengths = _lengths()
    with tempfile.TemporaryDirectory() as tmp:
        (Path(tmp) / "tracker").mkdir()
        (Path(tmp) / "tracker" / "data").symlink_to(MOT17 / "tracker_output")
        dataset_config = {
            "GT_FOLDER": str(MOT17 / "gt"), "TRACKERS_FOLDER": tmp, "TRACKERS_TO_EVAL": ["tracker"],
            "BENCHMARK": "MOT17", "SPLIT_TO_EVAL": "train", "SKIP_SPLIT_FOL": True,
            "SEQ_INFO": lengths, "DO_PREPROC": True, "PRINT_CONFIG": False,
        }
        eval_config = {
            "USE_PARALLEL": False, "PRINT_RESULTS": False, "PRINT_ONLY_COMBINED": False,
            "PRINT_CONFIG": False, "TIME_PROGRESS": False, "DISPLAY_LESS_PROGRESS": True,
            "OUTPUT_SUMMARY": False, "OUTPUT_DETAILED": False, "PLOT_CURVES": False,
            "OUTPUT_EMPTY_CLASSES": False,
        }
        times, res = [], None
        for _ in range(repeats):
            t0 = time.process_time()
            evaluator = trackeval.Evaluator(eval_config)
            dataset = trackeval.datasets.MotChallenge2DBox(dataset_config)
            metrics = [trackeval.metrics.HOTA(), trackeval.metrics.CLEAR(), trackeval.metrics.Identity()]
            res, _ = evaluator.evaluate([dataset], metrics)
            times.append(time.process_time() - t0)
    values: dict[str, dict[str, float]] = {}
    for seq, per_class in res["MotChallenge2DBox"]["tracker"].items():
        if seq == "COMBINED_SEQ":
            continue
        flat = {}
        for family in per_class["pedestrian"].values():
            for key, v in family.items():
                if np.ndim(v) == 1 and len(v) == 19:
                    for label, x in zip(range(5, 100, 5), v):
                        flat[f"{key}___{label}"] = float(x)
                elif np.ndim(v) == 0:
                    flat[key] = float(v)
        values[seq] = flat
    return times, values


def run_trackeval(repeats: int, python: str | None) -> tuple[list[float], dict[str, dict[str, float]]] | None:
    try:
        import trackeval  # noqa: F401

        return run_trackeval_here(repeats)
    except ImportError:
        pass
    if python is None:
        print("TrackEval: not importable here (pip install trackeval 'numpy<2' in another venv and pass "
              "--trackeval-python); timing lookalike only")
        return None
    proc = subprocess.run([python, __file__, "--trackeval-json", "--repeats", str(repeats)],
                          capture_output=True, text=True, check=False)
    if proc.returncode != 0:
        print(f"TrackEval via {python} failed:\n{proc.stderr[-2000:]}")
        return None
    payload = json.loads(proc.stdout.splitlines()[-1])
    return payload["times"], payload["values"]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--trackeval-python", default=None, help="an interpreter that can import trackeval")
    parser.add_argument("--trackeval-json", action="store_true", help=argparse.SUPPRESS)
    parser.add_argument("--compile-each-run", action="store_true",
                        help="whole process: keep this shell's bytecode setting (no private warmed cache)")
    args = parser.parse_args()
    if not MOT17.is_dir():
        sys.exit(f"MOT17 data not found at {MOT17}")
    if args.trackeval_json:
        times, values = run_trackeval_here(args.repeats)
        print(json.dumps({"times": times, "values": values}))
        return
    ours_times: list[float] = []
    te_times: list[float] = []
    ours: dict[str, dict[str, float]] = {}
    te: dict[str, dict[str, float]] | None = None
    for _ in range(args.repeats):  # interleaved rounds: load from elsewhere hits both sides alike
        t, ours = run_lookalike(1)
        ours_times += t
        theirs = run_trackeval(1, args.trackeval_python)
        if theirs is None:
            break
        te_times += theirs[0]
        te = theirs[1]
    ours_s = statistics.median(ours_times)
    print(f"lookalike: {ours_s:.3f} s CPU time for HOTA+CLEAR+Identity over {len(ours)} MOT17 sequences "
          f"(median of {len(ours_times)}, files read included)")
    if te is None:
        return
    te_s = statistics.median(te_times)
    print(f"TrackEval: {te_s:.3f} s CPU time (median of {len(te_times)}, same work)")
    worst, n = 0.0, 0
    for seq, values in te.items():
        for key, v in values.items():
            if key in ours[seq]:
                worst = max(worst, abs(ours[seq][key] - v))
                n += 1
    print(f"values compared: {n}, largest absolute difference: {worst:.3g}")
    report_target("eval values equal TrackEval's (largest difference)", worst, 1e-6, higher_is_better=False)
    report_target("lookalike eval vs TrackEval, MOT17 in process (x)", te_s / ours_s, 6.0)
    python = args.trackeval_python or sys.executable
    ours_cmd = [sys.executable, "-m", "lookalike", "eval", "--gt", str(MOT17 / "gt"),
                "--results", str(MOT17 / "tracker_output"), "--benchmark", "MOT17"]
    te_cmd = [python, __file__, "--trackeval-json", "--repeats", "1"]
    ours_w, te_w = [], []
    with tempfile.TemporaryDirectory() as cache:
        env = None if args.compile_each_run else installed_env(cache)
        if env is not None:  # untimed: fills the bytecode cache, as installing does
            whole_process(ours_cmd, env)
            whole_process(te_cmd, env)
        for _ in range(args.repeats):
            ours_w.append(whole_process(ours_cmd, env))
            te_w.append(whole_process(te_cmd, env))
    ow, tw = (statistics.median(c for c, _ in runs) for runs in (ours_w, te_w))
    ow_wall, tw_wall = (statistics.median(w for _, w in runs) for runs in (ours_w, te_w))
    how = "bytecode compiled on every start as this shell has it" if env is None else "bytecode cached"
    print(f"whole process ({how}): lookalike eval {ow:.3f} s, TrackEval {tw:.3f} s CPU time (median of "
          f"{args.repeats}; wall {ow_wall:.3f} s and {tw_wall:.3f} s: {tw_wall / ow_wall:.2f}x)")
    report_target("lookalike eval vs TrackEval, MOT17 whole process (x)", tw / ow, 6.0)


if __name__ == "__main__":
    main()
