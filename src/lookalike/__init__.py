"""lookalike: real-time tracking and identification of look-alike targets.

The public API is what ``__all__`` lists; everything else is reachable through the subpackages.
Names are imported on first use, so ``import lookalike`` itself loads nothing heavy.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from lookalike._lazy import lazy_attributes
from lookalike._version import __version__

if TYPE_CHECKING:
    from lookalike.io import find_sequences, frames_from_table, read_mot, tracks_to_rows, write_mot
    from lookalike.trackers import Sort, make_tracker, tracker_names, tracker_parameters
    from lookalike.types import Beacons, Detections, Frame, TrackSnapshot, TrackStatus

_HOME = {name: home for home, names in {
    "lookalike.io": ("find_sequences", "frames_from_table", "read_mot", "tracks_to_rows", "write_mot"),
    "lookalike.trackers": ("Sort", "make_tracker", "tracker_names", "tracker_parameters"),
    "lookalike.types": ("Beacons", "Detections", "Frame", "TrackSnapshot", "TrackStatus"),
}.items() for name in names}


__getattr__, __dir__ = lazy_attributes("lookalike", _HOME, globals())


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
