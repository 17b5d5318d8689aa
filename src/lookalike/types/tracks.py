"""``TrackSnapshot``: the immutable state of one track after a frame, and its lifecycle status."""

from __future__ import annotations

import enum
from dataclasses import dataclass

import numpy as np


class TrackStatus(enum.Enum):
    """Lifecycle of a track."""

    TENTATIVE = "tentative"
    CONFIRMED = "confirmed"
    LOST = "lost"


@dataclass(frozen=True, eq=False)
class TrackSnapshot:
    """A track as output by a tracker for one frame.

    Attributes:
        track_id: 1-based id, unique within one tracker run.
        status: lifecycle status.
        xywh: ``(4,)`` box in pixels, or None for world-only trackers.
        position: ``(2,)`` ground position in metres, or None.
        velocity: velocity of the state (pixels/s or metres/s), or None.
        heading: absolute heading in radians, or None.
        agent_id: identified agent (0-based), or None.
        identity_prob: confidence of ``agent_id`` in [0, 1], or None.
        detection_index: index of the detection that updated the track this frame, or -1.
    """

    track_id: int
    status: TrackStatus
    xywh: np.ndarray | None = None
    position: np.ndarray | None = None
    velocity: np.ndarray | None = None
    heading: float | None = None
    agent_id: int | None = None
    identity_prob: float | None = None
    detection_index: int = -1
