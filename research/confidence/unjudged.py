"""Rows the look could not judge as doubtful (``unjudged-rule.md``): the development run or the confirmation. Run from
the repository root::

    OMP_NUM_THREADS=1 .venv/bin/python research/confidence/unjudged.py dev | tee research/confidence/unjudged-dev.txt
    OMP_NUM_THREADS=1 .venv/bin/python research/confidence/unjudged.py confirm \
        | tee research/confidence/unjudged-confirm.txt
"""

from __future__ import annotations

import sys
import tempfile
from pathlib import Path

import numpy as np
from fit import switch_share
from look import arenas, hexbug, test_a

from lookalike.trackers.offline.confidence import DOUBTFUL_BELOW, LOOK_COEFFICIENT, logistic


def shares(items, unjudged: bool) -> tuple[int, int, float]:
    """(switches inside a doubtful range, switches, share of rows inside one) with the shipped confidence; with
    ``unjudged``, a row the look could not judge counts as doubtful (its probability as 0 for the ranges)."""
    probs = []
    for _, base, look in items:
        p = logistic(np.column_stack([base + LOOK_COEFFICIENT * np.nan_to_num(look)]), (0.0, 1.0))
        probs.append(np.where(np.isnan(look), 0.0, p) if unjudged else p)
    return switch_share([r for r, _, _ in items], probs, DOUBTFUL_BELOW)


def report(name: str, items) -> tuple[float, float, float]:
    out = []
    for arm in (False, True):
        inside, total, rows = shares(items, arm)
        print(f"  {name} {'with' if arm else 'without':7s} unjudged rows doubtful: switches in a range "
              f"{inside}/{total} rows in a range {rows:.1%}", flush=True)
        out.append(inside / max(total, 1))
    return out[0], out[1], rows


def main() -> None:
    work = Path(tempfile.mkdtemp(prefix="unjudged-"))
    if sys.argv[1] == "dev":
        kept = True
        for name, items in (("arenas 0-9, 4000-4019", arenas([*range(10), *range(4000, 4020)], work)),
                            ("hexbug", hexbug(work))):
            before, after, rows = report(name, items)
            kept &= after > before and rows <= 0.25
        print(f"keep rule {'met: kept' if kept else 'not met: not kept'}")
    else:
        report("fresh arenas 12000-12019", arenas(list(range(12000, 12020)), work))
        report("test_A (idtracker.ai, 15 px)", test_a(work))


if __name__ == "__main__":
    main()
