"""lookalike: real-time tracking and identification of look-alike targets.

The public API is what ``__all__`` lists; everything else is reachable through the subpackages.
"""

from lookalike.io import find_sequences, frames_from_table, read_mot, tracks_to_rows, write_mot
from lookalike.trackers import Sort, make_tracker, tracker_names, tracker_parameters
from lookalike.types import Beacons, Detections, Frame, TrackSnapshot, TrackStatus

__version__ = "0.1.0"

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
