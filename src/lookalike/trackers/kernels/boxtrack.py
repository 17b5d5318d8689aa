"""Optional numba kernels for :class:`~lookalike.trackers.boxtrack.BoxTrack`
(:mod:`lookalike.trackers.kernels.boxtrack_numba`): prediction with the IoU matrix, the gated IoU stages, the Kalman
update with bookkeeping, and the report with the lifecycle.

They do the numpy path's operations one track or pair at a time in the same order, so rows are bit for bit the same
(``tests/test_boxtrack_kernels.py``). Used when numba is installed unless ``LOOKALIKE_BOXTRACK_NUMBA=0``. Importing
numba and loading the kernels costs about a second, more than they save on a short run: a run of known length loads
them at its start when it is long (:func:`expect`); otherwise trackers take the numpy path until it has taken
:data:`LOAD_AFTER_S` in the process (unless the kernels are forced on or already loaded). Run as
the ``lookalike`` program with nothing in numba's cache, :func:`warm` then compiles them in a separate process while
that run stays on the numpy path."""

from __future__ import annotations

from collections.abc import Callable
from types import ModuleType
from typing import Any, TypeVar

from lookalike._compiled import KernelSwitch

T = TypeVar("T")


def _load() -> ModuleType:
    from lookalike.trackers.kernels import boxtrack_numba

    return boxtrack_numba


def warm() -> None:
    """Compile the kernels into numba's cache by tracking a short synthetic sequence (boxes of people walking,
    scores high and low, frames without detections) with them switched on."""
    import numpy as np

    from lookalike.trackers.boxtrack import BoxTrack
    from lookalike.types import Detections, Frame

    use_compiled(True)
    rng = np.random.default_rng(0)
    tracker = BoxTrack()
    start = rng.uniform(0, 600, (12, 2))
    for k in range(60):
        if k % 17 == 16:
            tracker.update(Frame(index=k, time=k / 30))
            continue
        keep = rng.random(12) < 0.85
        xy = start[keep] + k * 2.0 + rng.normal(0, 1, (int(keep.sum()), 2))
        xywh = np.column_stack([xy, np.full((len(xy), 2), [40.0, 100.0])])
        score = rng.uniform(0.05, 1.0, len(xy))
        tracker.update(Frame(index=k, time=k / 30, detections=Detections(xywh=xywh, score=score)))


EAGER_FRAMES = 3000
"""A run announced (:func:`expect`) with at least this many frames loads the kernels at its start: about where the
0.2-0.4 ms they save a frame of a few boxes repays loading them."""

LOAD_AFTER_S = 1.0
"""Seconds of the numpy path in a process after which the kernels are loaded (about their load time on one core:
numba's import 0.35 s, the cached kernels' first calls 0.9 s; they then save about 0.4 ms a frame of 8 boxes)."""

_SWITCH: KernelSwitch[ModuleType] = KernelSwitch("LOOKALIKE_BOXTRACK_NUMBA", _load, load_after_s=LOAD_AFTER_S,
                                                 warm="lookalike.trackers.kernels.boxtrack:warm")
use_compiled = _SWITCH.use_compiled  # (trackers built from now on)
compiled = _SWITCH.compiled  # the kernels' module, or None when they are off or numba is not installed
due, timed = _SWITCH.due, _SWITCH.timed  # (whether to decide now; the numpy path, its time counted)


def expect(frames: int) -> None:
    """About ``frames`` frames follow in this process: with at least :data:`EAGER_FRAMES`, load the kernels now
    (unless switched off)."""
    if frames >= EAGER_FRAMES:
        compiled()


class PathChoice:
    """Which path one tracker's frames take: the kernels (:attr:`kernels` True), the numpy path (False), or not
    decided yet (None: the numpy path, its time counted until loading the kernels pays). ``allowed``: whether the
    tracker's settings let the kernels run at all."""

    def __init__(self, allowed: bool = True) -> None:
        self.kernels: bool | None = None if allowed else False
        self.decide()

    def decide(self) -> None:
        """Settle the path when asking costs nothing or loading pays (:func:`due`)."""
        if self.kernels is None and due():
            self.kernels = compiled() is not None

    def expect(self, frames: int) -> None:
        """About ``frames`` frames follow (:func:`expect`)."""
        expect(frames)
        self.decide()

    def numpy(self, update: Callable[[Any], T], frame: Any) -> T:
        """``update(frame)``, the numpy path, timed towards the decision while it is not made."""
        if self.kernels is not None:
            return update(frame)
        out = timed(update, frame)
        self.decide()
        return out
module = _SWITCH.kernels  # the kernels' module whatever the switch says, None when numba is not installed
