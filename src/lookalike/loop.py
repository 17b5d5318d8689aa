"""The one frame loop: ``run(tracker, frames, sink)`` feeds frames to a tracker in order and hands each
``(frame, tracks)`` to ``sink`` at once, keeping nothing per frame; it times ``update`` alone."""

from __future__ import annotations

import time
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from typing import Any, Protocol

import numpy as np

from lookalike.types import Frame
from lookalike.types.mot_table import stack_rows, tracks_to_rows


class Updating(Protocol):
    """What the loop needs of a tracker (``frame``: usually a :class:`~lookalike.types.Frame`)."""

    def update(self, frame: Any) -> Any:
        """Process one frame; return the tracks reported for it (iterable of ``TrackSnapshot``)."""
        ...


Sink = Callable[[Any, Any], None]


@dataclass
class RunStats:
    """What one :func:`run` did: frames processed and seconds spent in the tracker's ``update``."""

    frames: int = 0
    seconds: float = 0.0

    @property
    def fps(self) -> float:
        """Frames per second of the tracker alone (inf when no time was measured)."""
        return self.frames / self.seconds if self.seconds > 0 else float("inf")


def run(tracker: Updating, frames: Iterable[Any], sink: Sink | None = None, *,
        stats: RunStats | None = None) -> RunStats:
    """Run ``tracker`` over ``frames`` in order, calling ``sink(frame, tracks)`` after every frame; returns the
    stats, accumulated into ``stats`` if given."""
    stats = RunStats() if stats is None else stats
    for frame in frames:
        t0 = time.perf_counter()
        tracks = tracker.update(frame)
        stats.seconds += time.perf_counter() - t0
        stats.frames += 1
        if sink is not None:
            sink(frame, tracks)
    return stats


def expect(tracker: Any, frames: int) -> None:
    """Tell ``tracker`` that about ``frames`` frames follow (all its sequences together), when it takes the hint
    (``expect``: ``boxtrack``, to decide whether its compiled kernels pay)."""
    hint = getattr(tracker, "expect", None)
    if hint is not None:
        hint(frames)


def warm_up(make: Callable[[], Updating], frames: Iterable[Any], n: int = 10) -> None:
    """Run a throw-away tracker from ``make()`` over the first ``n`` of ``frames``, so that one-off costs (imports,
    numba compiles) stay out of a frames/s figure."""
    tracker = make()
    for k, frame in enumerate(frames):
        if k >= n:
            break
        tracker.update(frame)


class RowCollector:
    """A sink that keeps the MOTChallenge rows of every frame in memory (small sequences: benches)."""

    def __init__(self) -> None:
        self._chunks: list[np.ndarray] = []

    def __call__(self, frame: Frame, tracks: Any) -> None:
        self._chunks.append(tracks_to_rows(frame.index, tracks))

    def rows(self) -> np.ndarray:
        """All rows so far, ``(n, 10)``."""
        return stack_rows(self._chunks)


class Sinks:
    """Several sinks called in turn (e.g. a file writer and a progress bar)."""

    def __init__(self, *sinks: Sink | None) -> None:
        self._sinks = [s for s in sinks if s is not None]

    def __call__(self, frame: Frame, tracks: Any) -> None:
        for sink in self._sinks:
            sink(frame, tracks)


__all__ = ["RowCollector", "RunStats", "Sink", "Sinks", "Updating", "expect", "run"]
