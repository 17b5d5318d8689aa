"""Helpers shared by the benchmark scripts: locating ../shared/data and timing loops."""

from __future__ import annotations

import statistics
import time
from pathlib import Path
from typing import Callable

SHARED_DATA = Path(__file__).resolve().parents[1].parent / "shared" / "data"


def median_seconds(run: Callable[[], object], repeats: int = 3) -> float:
    """Median wall time of ``run()`` over ``repeats`` calls, in seconds."""
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        run()
        times.append(time.perf_counter() - t0)
    return statistics.median(times)
