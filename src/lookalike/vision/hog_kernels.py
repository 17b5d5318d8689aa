"""Optional numba kernels for the HOG detector (:mod:`lookalike.vision.hog_numba`): grey conversion, cell histograms,
their integral, and the block-descriptor columns a cascade stage reads.

Each does the numpy path's operations one pixel, cell or window at a time in the same order and precision, so detections
are bit for bit the same (``tests/test_hog_kernels.py``). Used when numba is installed unless ``LOOKALIKE_HOG_NUMBA=0``;
loaded at a process's first detector call."""

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
