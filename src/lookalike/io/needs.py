"""What a tracker needs beyond boxes and scores (its class attribute ``needs``: :data:`~lookalike.trackers.base.
NEEDS_APPEARANCE`, :data:`~lookalike.trackers.base.NEEDS_ROBOTS` or a phrase of its own), so a command computes only
that and refuses early in one line."""

from __future__ import annotations

from lookalike.trackers.base import NEEDS_APPEARANCE
from lookalike.trackers.registry import tracker_class, tracker_names


def _need(name: str) -> str | None:
    declared = getattr(tracker_class(name), "needs", None)
    return declared if isinstance(declared, str) else None


def box_input_problem(name: str, *, video: bool = False) -> str | None:
    """None when tracker ``name`` can run on boxes (with a video when ``video``), else a line naming what it needs."""
    need = _need(name)
    if need is None or (video and need == NEEDS_APPEARANCE):
        return None
    return f"tracker {name!r} cannot run on boxes alone; it needs {need}"


def input_kind(name: str) -> str:
    """What tracker ``name`` reads: ``boxes``, ``boxes + video`` or ``robot positions``."""
    need = _need(name)
    if need is None:
        return "boxes"
    return "boxes + video" if need == NEEDS_APPEARANCE else "robot positions"


def identifier_names() -> list[str]:
    """The registered trackers that read robot positions (the robot identifiers), in registry order."""
    return [n for n in tracker_names() if input_kind(n) == "robot positions"]


__all__ = ["box_input_problem", "identifier_names", "input_kind"]
