"""``Frame``: everything a tracker receives at one time step."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from lookalike.types.beacons import Beacons
from lookalike.types.detections import Detections


@dataclass(frozen=True, eq=False)
class Frame:
    """One time step.

    Attributes:
        index: 0-based frame index.
        time: time stamp in seconds.
        detections: the frame's detections (may be empty).
        beacons: reports received since the previous frame (may be empty).
        image: optional ``(h, w, 3)`` uint8 BGR image."""

    index: int
    time: float
    detections: Detections = field(default_factory=Detections.empty)
    beacons: Beacons = field(default_factory=Beacons.empty)
    image: np.ndarray | None = None

    def __post_init__(self) -> None:
        try:
            index_ok = int(self.index) == self.index and self.index >= 0
        except (TypeError, ValueError):
            index_ok = False
        if not index_ok:
            raise ValueError(f"Frame.index: expected a non-negative integer, got {self.index!r}")
        try:
            time_ok = math.isfinite(float(self.time))
        except (TypeError, ValueError):
            time_ok = False
        if not time_ok:
            raise ValueError(f"Frame.time: expected a finite number of seconds, got {self.time!r}")
        if not isinstance(self.detections, Detections):
            raise ValueError(f"Frame.detections: expected Detections, got {type(self.detections).__name__}")
        if not isinstance(self.beacons, Beacons):
            raise ValueError(f"Frame.beacons: expected Beacons, got {type(self.beacons).__name__}")
