"""Helpers shared by the benchmark scripts: locating ../shared/data and timing loops."""

from __future__ import annotations

import itertools
import statistics
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

SHARED_DATA = Path(__file__).resolve().parents[1].parent / "shared" / "data"


def median_seconds(run: Callable[[], object], repeats: int = 3) -> float:
    """Median wall time of ``run()`` over ``repeats`` calls, in seconds."""
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        run()
        times.append(time.perf_counter() - t0)
    return statistics.median(times)


def parameter_grid(tracker: str, specs: list[str] | tuple[str, ...]) -> list[dict[str, Any]]:
    """Every combination of ``KEY=V1,V2,...`` specs, values parsed as ``tracker``'s parameters
    (``[{}]`` for no specs)."""
    from lookalike.trackers.registry import parse_parameter

    keys, values = [], []
    for spec in specs:
        key, _, text = spec.partition("=")
        keys.append(key.strip())
        values.append([parse_parameter(tracker, f"{key}={v}")[1] for v in text.split(",")])
    return [dict(zip(keys, combo)) for combo in itertools.product(*values)]


def report_target(name: str, value: float, target: float, *, higher_is_better: bool = True,
                  unit: str = "") -> bool:
    """Print one ``make bench`` target line, ``TARGET <name>: <value> (target >= or <= <target>) PASS|FAIL``,
    and return whether it passed."""
    passed = value >= target if higher_is_better else value <= target
    op = ">=" if higher_is_better else "<="
    print(f"TARGET {name}: {value:.3g}{unit} (target {op} {target:g}{unit}) {'PASS' if passed else 'FAIL'}",
          flush=True)
    return passed
