"""Optional compiled kernels (numba) for the HOG detector (:mod:`lookalike.vision.hog_numba`): grey conversion,
cell histograms from OpenCV's gradient magnitude and angle, their float32 integral, and the block-descriptor columns
a cascade stage reads.

Each kernel does the floating-point operations of the numpy path one pixel, cell or window at a time, in the same
order and precision (float32 binning, float64 sums in each cell's raster order, the 36-term block norms in numpy's
pairwise order, no fused multiply-adds), so detections are bit for bit the same; ``tests/test_hog_kernels.py``
compares both paths. They are used when numba is installed (the ``fast`` extra) unless ``LOOKALIKE_HOG_NUMBA=0``.
Start-up: numba is imported and the cached kernels loaded in the first detector call of a process; right after
installation that call compiles them into numba's cache (figures: docs/experiments/speed.md, HOG).
"""

from __future__ import annotations

from collections.abc import Callable

from lookalike._compiled import KernelSwitch


def _load() -> dict[str, Callable[..., None]]:
    from lookalike.vision import hog_numba

    return {"cell_hist": hog_numba.cell_hist, "integral32": hog_numba.integral32,
            "block_columns": hog_numba.block_columns, "grey": hog_numba.grey}


_SWITCH: KernelSwitch[dict[str, Callable[..., None]]] = KernelSwitch("LOOKALIKE_HOG_NUMBA", _load)
use_compiled = _SWITCH.use_compiled
compiled = _SWITCH.compiled  # the compiled kernels by name, or None when they are off or numba is not installed
