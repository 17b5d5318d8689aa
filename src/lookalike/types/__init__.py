"""Data types at every boundary: detections, beacons, frames and track snapshots."""

from lookalike.types.beacons import Beacons
from lookalike.types.detections import Detections
from lookalike.types.frame import Frame
from lookalike.types.tracks import Tracks, TrackSnapshot, TrackStatus

__all__ = ["Beacons", "Detections", "Frame", "TrackSnapshot", "TrackStatus", "Tracks"]
