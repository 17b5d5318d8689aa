"""Optional numba kernels of the HOG detector (:mod:`lookalike.vision.hog_numba`), bit for bit the numpy path's
results; used when numba is installed unless ``LOOKALIKE_HOG_NUMBA=0``."""

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
