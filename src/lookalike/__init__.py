"""lookalike: real-time tracking and identification of look-alike targets.

The public API is what ``__all__`` lists; everything else is reachable through the subpackages.
Names are imported on first use, so ``import lookalike`` itself loads nothing heavy.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from lookalike.io import find_sequences, frames_from_table, read_mot, tracks_to_rows, write_mot
    from lookalike.trackers import Sort, make_tracker, tracker_names, tracker_parameters
    from lookalike.types import Beacons, Detections, Frame, TrackSnapshot, TrackStatus

__version__ = "0.1.0"

_HOME = {
    "find_sequences": "lookalike.io",
    "frames_from_table": "lookalike.io",
    "read_mot": "lookalike.io",
    "tracks_to_rows": "lookalike.io",
    "write_mot": "lookalike.io",
    "Sort": "lookalike.trackers",
    "make_tracker": "lookalike.trackers",
    "tracker_names": "lookalike.trackers",
    "tracker_parameters": "lookalike.trackers",
    "Beacons": "lookalike.types",
    "Detections": "lookalike.types",
    "Frame": "lookalike.types",
    "TrackSnapshot": "lookalike.types",
    "TrackStatus": "lookalike.types",
}


def __getattr__(name: str) -> Any:
    home = _HOME.get(name)
    if home is None:
        raise AttributeError(f"module 'lookalike' has no attribute {name!r}")
    value = getattr(importlib.import_module(home), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_HOME))


__all__ = [
    "Beacons",
    "Detections",
    "Frame",
    "Sort",
    "TrackSnapshot",
    "TrackStatus",
    "__version__",
    "find_sequences",
    "frames_from_table",
    "make_tracker",
    "read_mot",
    "tracker_names",
    "tracker_parameters",
    "tracks_to_rows",
    "write_mot",
]
