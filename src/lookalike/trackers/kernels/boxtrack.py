"""Optional numba kernels for :class:`~lookalike.trackers.boxtrack.BoxTrack`
(:mod:`lookalike.trackers.kernels.boxtrack_numba`): prediction with the IoU matrix, the gated IoU stages, the Kalman
update with bookkeeping, and the report with the lifecycle.

They do the numpy path's operations one track or pair at a time in the same order, so rows are bit for bit the same
(``tests/test_boxtrack_kernels.py``). Used when numba is installed unless ``LOOKALIKE_BOXTRACK_NUMBA=0``; numba loads
when the first BoxTrack is built."""

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
