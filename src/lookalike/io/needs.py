"""What a tracker needs beyond boxes and scores (its ``needs`` phrase, or :data:`BUILTIN_NEEDS`), so a command can
refuse early in one line."""

from __future__ import annotations

from lookalike.trackers.registry import tracker_class

_ROBOTS = ("ground positions, headings and heading reports of robots (a `lookalike simulate` sequence, "
           "or --video V --pipeline robots --reports FILE)")
_APPEARANCE = "appearance features from the pixels: give the video with --video VIDEO"
BUILTIN_NEEDS = {
    "deepsort": _APPEARANCE,
    "diversort": _APPEARANCE,
    "kalman_ha": _ROBOTS,
    "kalman_ha2": _ROBOTS,
    "jpda": _ROBOTS,
    "lstm": _ROBOTS,
}


def _need(name: str) -> str | None:
    declared = getattr(tracker_class(name), "needs", None)
    return declared if isinstance(declared, str) else BUILTIN_NEEDS.get(name)


def box_input_problem(name: str, *, video: bool = False) -> str | None:
    """None when tracker ``name`` can run on boxes (with a video when ``video``), else a line naming what it needs."""
    need = _need(name)
    if need is None or (video and need == _APPEARANCE):
        return None
    return f"tracker {name!r} cannot run on boxes alone; it needs {need}"


def input_kind(name: str) -> str:
    """What tracker ``name`` reads: ``boxes``, ``boxes + video`` or ``robot positions``."""
    need = _need(name)
    if need is None:
        return "boxes"
    return "boxes + video" if need == _APPEARANCE else "robot positions"


__all__ = ["BUILTIN_NEEDS", "box_input_problem", "input_kind"]
