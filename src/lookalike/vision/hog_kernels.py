"""Optional compiled kernels (numba) for the HOG detector (:mod:`lookalike.vision.hog_numba`): grey conversion,
cell histograms from OpenCV's gradient magnitude and angle, their float32 integral, and the block-descriptor columns
a cascade stage reads.

Each kernel does the floating-point operations of the numpy path one pixel, cell or window at a time, in the same
order and precision (float32 binning, float64 sums in each cell's raster order, the 36-term block norms in numpy's
pairwise order, no fused multiply-adds), so detections are bit for bit the same; ``tests/test_hog_kernels.py``
compares both paths. They are used when numba is installed (the ``fast`` extra) unless ``LOOKALIKE_HOG_NUMBA=0``.
Start-up: importing numba and loading the cached kernels costs about 0.6 s of CPU time in the first detector call
of a process; right after installation the first call compiles them (about 6 s) into numba's cache.
"""

from __future__ import annotations

import os
from collections.abc import Callable
from typing import Any

_STATE: dict[str, Any] = {}


def use_compiled(flag: bool | None) -> None:
    """Force the compiled kernels on (``True``, if numba is installed) or off (``False``); ``None``: the default
    (on when numba imports and ``LOOKALIKE_HOG_NUMBA`` is not ``0``)."""
    _STATE.pop("forced", None)
    if flag is not None:
        _STATE["forced"] = bool(flag)


def compiled() -> dict[str, Callable[..., None]] | None:
    """The compiled kernels by name, or ``None`` when they are off or numba is not installed."""
    forced = _STATE.get("forced")
    if forced is False or (forced is None and os.environ.get("LOOKALIKE_HOG_NUMBA", "1") == "0"):
        return None
    if "kernels" not in _STATE:
        _STATE["kernels"] = _build()
    return _STATE["kernels"]  # type: ignore[no-any-return]


def _build() -> dict[str, Callable[..., None]] | None:
    try:
        from lookalike.vision import hog_numba
    except ImportError:
        return None
    return {"cell_hist": hog_numba.cell_hist, "integral32": hog_numba.integral32,
            "block_columns": hog_numba.block_columns, "grey": hog_numba.grey}
