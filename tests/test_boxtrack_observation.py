"""boxtrack's observation-centric mechanisms (as OC-SORT): a track found again after a gap is
re-filtered along the straight line between its last observation and the new one (``REUPDATE``),
and the first stage's cost may weigh the direction of the last observations (``MOMENTUM``)."""

from __future__ import annotations

from unittest.mock import patch

import numpy as np
import pytest

from lookalike.trackers import boxtrack_config, make_tracker
from lookalike.types import Detections, Frame

FPS = 30.0


def _frame(k: int, boxes: list[list[float]]) -> Frame:
    xywh = np.array(boxes, dtype=float).reshape(-1, 4)
    return Frame(index=k, time=k / FPS, detections=Detections(xywh=xywh, score=np.full(len(xywh), 0.99)))


def _speed_after_gap(reupdate: bool) -> float:
    """x speed (pixels/frame) boxtrack reports for a 100×120 px target moving 2 px/frame, found again
    after a gap of 1 s (30 frames), longer than a lost track keeps extrapolating its velocity."""
    with patch.object(boxtrack_config, "REUPDATE", reupdate):
        tracker = make_tracker("boxtrack")
        for k in range(20):
            tracker.update(_frame(k, [[100.0 + 2.0 * k, 200.0, 100.0, 120.0]]))
        for k in range(20, 50):
            tracker.update(_frame(k, []))
        out = tracker.update(_frame(50, [[200.0, 200.0, 100.0, 120.0]]))
    assert len(out.id) == 1 and out.id[0] == 1  # the same track, found again
    return float(out.velocity[0, 0]) / FPS


def test_a_track_found_again_takes_the_speed_of_the_line_between_its_observations() -> None:
    with_reupdate, without = _speed_after_gap(True), _speed_after_gap(False)
    assert with_reupdate == pytest.approx(2.0, abs=0.5)
    assert abs(with_reupdate - 2.0) < abs(without - 2.0)


def test_momentum_prefers_the_detection_ahead_of_the_track() -> None:
    """Two detections overlapping a track equally, one ahead of its motion and one behind: with the
    momentum term the one ahead continues the track."""
    with patch.object(boxtrack_config, "MOMENTUM", 0.2):
        tracker = make_tracker("boxtrack")
        for k in range(10):
            tracker.update(_frame(k, [[100.0 + 4.0 * k, 200.0, 60.0, 120.0]]))
        predicted = 100.0 + 4.0 * 10
        agreement = tracker._direction_agreement(np.array([0]), np.array([[predicted + 30 + 12.0, 260.0],
                                                                          [predicted + 30 - 12.0, 260.0]]))
    assert agreement[0, 0] > agreement[0, 1]
    assert np.all(np.abs(agreement) <= 0.5)
