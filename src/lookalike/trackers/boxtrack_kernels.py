"""Optional compiled kernels (numba) for :class:`~lookalike.trackers.boxtrack.BoxTrack`
(:mod:`lookalike.trackers.boxtrack_numba`): the prediction with the frame's IoU matrix and clutter count,
the gated IoU stages of the association plan, the Kalman update with the track bookkeeping, and the report
with the lifecycle's survivors.

At ~6 detections a frame the numpy path's time is mostly the overhead of ~100 small numpy calls; the
kernels do the same floating-point operations one track or pair at a time, in the same order and precision
(no fused multiply-adds), so the rows are bit for bit those of the numpy path (``tests/test_boxtrack_kernels.py``
compares both). They are used when numba is installed (the ``fast`` extra) unless ``LOOKALIKE_BOXTRACK_NUMBA=0``;
numba is imported when the first BoxTrack is built, never by ``import lookalike``. Start-up cost:
docs/experiments/speed.md (boxtrack).
"""

from __future__ import annotations

import os
from typing import Any

_STATE: dict[str, Any] = {}


def use_compiled(flag: bool | None) -> None:
    """Force the compiled kernels on (``True``, if numba is installed) or off (``False``) for trackers built
    from now on; ``None``: the default (on when numba imports and ``LOOKALIKE_BOXTRACK_NUMBA`` is not ``0``)."""
    _STATE.pop("forced", None)
    if flag is not None:
        _STATE["forced"] = bool(flag)


def compiled() -> Any | None:
    """The kernels' module, or ``None`` when they are off or numba is not installed."""
    forced = _STATE.get("forced")
    if forced is False or (forced is None and os.environ.get("LOOKALIKE_BOXTRACK_NUMBA", "1") == "0"):
        return None
    return module()


def module() -> Any | None:
    """The kernels' module whatever the switch says (imported on first use), ``None`` when numba is not installed."""
    if "kernels" not in _STATE:
        try:
            from lookalike.trackers import boxtrack_numba
        except ImportError:
            _STATE["kernels"] = None
        else:
            _STATE["kernels"] = boxtrack_numba
    return _STATE["kernels"]
