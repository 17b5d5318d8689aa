"""The tracker protocol and the config convention every tracker follows."""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from typing import Any, ClassVar, Protocol, runtime_checkable

from lookalike.types import Frame, TrackSnapshot


@runtime_checkable
class Tracker(Protocol):
    """A tracker consumes frames in time order and returns the tracks it reports for each."""

    name: ClassVar[str]
    config: Any

    def update(self, frame: Frame) -> Sequence[TrackSnapshot]:
        """Process one frame; return the tracks reported for it (a :class:`~lookalike.types.Tracks`
        batch for the built-in trackers; any sequence of snapshots is accepted)."""
        ...

    def reset(self) -> None:
        """Forget all tracks and restart ids at 1."""
        ...


def param(default: Any, doc: str) -> Any:
    """A config field with a default and a one-line description (shown by ``lookalike trackers``)."""
    return dataclasses.field(default=default, metadata={"doc": doc})


def check_positive(config: Any, *names: str, allow_zero: bool = False) -> None:
    """Raise ``ValueError`` naming the first config field that is not positive."""
    for name in names:
        value = getattr(config, name)
        if value is not None and (value < 0 or (value == 0 and not allow_zero)):
            bound = ">= 0" if allow_zero else "> 0"
            raise ValueError(f"{type(config).__name__}.{name} must be {bound}, got {value}")
