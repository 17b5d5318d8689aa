"""Time of the closed set's chain MILP (``solve_chains``) with a proofreader's corrections, on the 8-animal hard arena
of ``benchmarks/proofread_curve.py`` (seed 304 by default).

``capture`` runs the simulated proofreader with propagation for a few corrections and pickles every
``solve_chains`` problem it poses; ``time`` solves the captured problems that carry marks with the current code and
writes each one's chains and objective, and with ``--against`` compares them with an earlier ``time`` output. Run::

    python research/proofread/solve_speed.py capture /tmp/p304.pkl --seed 304 --corrections 3
    python research/proofread/solve_speed.py time /tmp/p304.pkl /tmp/new.pkl [--against /tmp/old.pkl]
"""

from __future__ import annotations

import argparse
import pickle
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "benchmarks"))

from lookalike.trackers.offline import closed_set  # noqa: E402


def objective(p: dict[str, Any], chains: list[list[int]]) -> float:
    """The MILP's objective of ``chains`` (lower is better)."""
    src, dst, cost = p["links"]
    at = {(int(s), int(d)): float(c) for s, d, c in zip(src, dst, cost)}
    total = 0.0
    for ch in chains:
        total -= sum(float(p["lengths"][t]) - p["tracklet_cost"] for t in ch)
        total += sum(at[(a, b)] for a, b in zip(ch[:-1], ch[1:]))
        total += float(p["start_cost"][ch[0]]) + float(p["end_cost"][ch[-1]])
    return total


def capture(out: str, seed: int, corrections: int) -> None:
    from proofread_curve import HARD, arena_case, proofread

    problems: list[dict[str, Any]] = []
    solve = closed_set.solve_chains

    def recording(lengths: np.ndarray, links: Any, n_chains: int, tracklet_cost: float, time_limit_s: float = 60.0,
                  start_cost: Any = None, end_cost: Any = None, marks: Any = (), excluded: Any = ()) -> Any:
        t0 = time.perf_counter()
        chains = solve(lengths, links, n_chains, tracklet_cost, time_limit_s, start_cost, end_cost, marks, excluded)
        problems.append({"lengths": lengths, "links": links, "n_chains": n_chains, "tracklet_cost": tracklet_cost,
                         "start_cost": start_cost, "end_cost": end_cost,
                         "marks": [(list(on), list(off)) for on, off in marks], "excluded": list(excluded),
                         "seconds": time.perf_counter() - t0})
        print(f"solve {len(problems)}: {len(marks)} marks, {problems[-1]['seconds']:.1f} s", flush=True)
        Path(out).write_bytes(pickle.dumps(problems))  # kept as it goes: the run can be stopped at any point
        return chains

    case = arena_case(seed, **HARD)  # type: ignore[arg-type]
    closed_set.solve_chains = recording  # type: ignore[assignment]
    try:
        print("IDF1 curve", proofread(case, True, corrections))
    finally:
        closed_set.solve_chains = solve  # type: ignore[assignment]


def time_solves(problems_path: str, out: str, against: str | None) -> None:
    problems = [p for p in pickle.loads(Path(problems_path).read_bytes()) if p["marks"]]
    results = []
    for k, p in enumerate(problems):
        t0 = time.perf_counter()
        try:
            chains = closed_set.solve_chains(p["lengths"], p["links"], p["n_chains"], p["tracklet_cost"], 600.0,
                                             p["start_cost"], p["end_cost"], p["marks"], p["excluded"])
        except ValueError:
            chains = None
        dt = time.perf_counter() - t0
        obj = objective(p, chains) if chains is not None else float("nan")
        results.append({"chains": sorted(chains) if chains is not None else None, "objective": obj, "seconds": dt})
        print(f"problem {k}: {len(p['marks'])} marks, {len(p['lengths'])} tracklets, {len(p['links'][0])} links: "
              f"{dt:.2f} s, objective {obj:.4f}", flush=True)
    Path(out).write_bytes(pickle.dumps(results))
    print(f"total {sum(r['seconds'] for r in results):.1f} s over {len(results)} solves with marks")
    if against:
        old = pickle.loads(Path(against).read_bytes())
        for k, (a, b) in enumerate(zip(old, results)):
            same_obj = (a["chains"] is None) == (b["chains"] is None) and (
                a["chains"] is None or abs(a["objective"] - b["objective"]) <= 1e-6 * max(1.0, abs(a["objective"])))
            print(f"problem {k}: {a['seconds']:.2f} s -> {b['seconds']:.2f} s, objective equal {same_obj}, "
                  f"chains equal {a['chains'] == b['chains']}")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n", 1)[0])
    ap.add_argument("mode", choices=("capture", "time"))
    ap.add_argument("paths", nargs="+")
    ap.add_argument("--seed", type=int, default=304)
    ap.add_argument("--corrections", type=int, default=3)
    ap.add_argument("--against", default=None)
    args = ap.parse_args()
    if args.mode == "capture":
        capture(args.paths[0], args.seed, args.corrections)
    else:
        time_solves(args.paths[0], args.paths[1], args.against)


if __name__ == "__main__":
    main()
