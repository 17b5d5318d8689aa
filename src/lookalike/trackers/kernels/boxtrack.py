"""Optional compiled kernels (numba) for :class:`~lookalike.trackers.boxtrack.BoxTrack`
(:mod:`lookalike.trackers.kernels.boxtrack_numba`): the prediction with the frame's IoU matrix and clutter count,
the gated IoU stages of the association plan, the Kalman update with the track bookkeeping, and the report
with the lifecycle's survivors.

At a few detections a frame the numpy path's time is mostly the overhead of its many small numpy calls; the
kernels do the same floating-point operations one track or pair at a time, in the same order and precision
(no fused multiply-adds), so the rows are bit for bit those of the numpy path (``tests/test_boxtrack_kernels.py``
compares both). They are used when numba is installed (the ``fast`` extra) unless ``LOOKALIKE_BOXTRACK_NUMBA=0``;
numba is imported when the first BoxTrack is built, never by ``import lookalike``. Start-up cost:
docs/experiments/speed.md (boxtrack).
"""

from __future__ import annotations

from types import ModuleType

from lookalike._compiled import KernelSwitch


def _load() -> ModuleType:
    from lookalike.trackers.kernels import boxtrack_numba

    return boxtrack_numba


_SWITCH: KernelSwitch[ModuleType] = KernelSwitch("LOOKALIKE_BOXTRACK_NUMBA", _load)
use_compiled = _SWITCH.use_compiled  # (trackers built from now on)
compiled = _SWITCH.compiled  # the kernels' module, or None when they are off or numba is not installed
module = _SWITCH.kernels  # the kernels' module whatever the switch says, None when numba is not installed
