"""Issue 18: the node's batched per-frame path (trusted frame building, the beacon identifier's
track table) gives the results of the plain code and keeps its errors for bad input."""

import math

import numpy as np
import pytest

from lookalike.node import DetectionsMessage, IdentifierConfig, TeamIdentifier
from lookalike.trackers import make_tracker


def _node() -> TeamIdentifier:
    return TeamIdentifier(make_tracker("kalman_ha2", n_agents=2), IdentifierConfig(n_robots=2))


@pytest.mark.parametrize(("fields", "match"), [
    ({"heading": (math.nan,)}, "heading"),
    ({"score": (math.inf,)}, "score"),
    ({"position": ((1.0, math.nan),)}, "position"),
    ({"heading": (0.0, 0.1)}, "heading"),
])
def test_frames_built_outside_decode_are_still_validated(fields, match):
    message = DetectionsMessage(**{"frame": 0, "time": 0.0, "position": ((1.0, 0.0),), "heading": (0.0,),
                                   "score": (1.0,), **fields})
    with pytest.raises(ValueError, match=match):
        _node().add_frame(message)


def test_trusted_frame_arrays_are_read_only_and_typed():
    node = _node()
    frames = []
    node.tracker.update = lambda frame: frames.append(frame) or []
    node.add_frame(DetectionsMessage(frame=0, time=0.0, position=((1.0, 0.5), (2.0, -1.0)), heading=(0.0, 1.0),
                                     score=(0.9, 0.8), heading_std=(0.1, 0.1)))
    det = frames[0].detections
    assert len(det) == 2 and det.position.shape == (2, 2) and det.xywh.shape == (2, 4)
    for column in (det.position, det.heading, det.score, det.heading_std, det.xywh):
        assert column.dtype == np.float64 and not column.flags.writeable
    assert len(frames[0].beacons) == 0
