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


@pytest.mark.parametrize("seed", range(30))
def test_pairs_equal_the_solver(seed):
    from lookalike.association.solver import assign_pairs
    from lookalike.trackers.world_kernels import pairs

    rng = np.random.default_rng(seed)
    k, d = int(rng.integers(0, 9)), int(rng.integers(0, 9))
    cost = rng.choice([0.0, 0.1, 0.25, 0.3, 0.5, 2.0, np.inf], (k, d)) * rng.uniform(0.5, 1.5, (k, d))
    for max_cost in (0.3, np.inf):
        allowed = cost <= max_cost if np.isfinite(max_cost) else cost < np.inf
        rows, cols = pairs(cost, allowed, max_cost)
        expected = assign_pairs(np.where(allowed, cost, np.inf), max_cost)
        np.testing.assert_array_equal(np.stack([rows, cols], axis=1).reshape(-1, 2), expected)


def _plain_associate(tracker, det):
    """The association and update before the batched path: motion.kalman's functions, the solver."""
    from lookalike.association.solver import assign
    from lookalike.motion import gating_distance, kalman
    from lookalike.trackers.kalman_ha import H

    t = tracker._tracks
    det_of_track = np.full(len(t), -1, dtype=int)
    if len(t) and len(det):
        noise = tracker._noise(t.mean[:, :2])
        d2 = gating_distance(t.mean, t.cov, det.position, H, noise)
        matches, _, _ = assign(np.where(d2 <= tracker._gate, d2, np.inf))
        rows = matches[:, 0]
        det_of_track[rows] = matches[:, 1]
        if len(rows):
            t.mean[rows], t.cov[rows] = kalman.update(t.mean[rows], t.cov[rows], det.position[matches[:, 1]],
                                                      H, noise[rows])
    return det_of_track


@pytest.mark.parametrize("name", ["kalman_ha", "kalman_ha2"])
def test_batched_association_equals_the_plain_one(name):
    import copy

    from lookalike.node.teamsim import team_sequence

    seq = team_sequence("m10n7", 4, 3.0)
    tracker = make_tracker(name, n_agents=7)
    update = tracker._associate_and_update
    checked = 0

    def both(det):
        nonlocal checked
        plain = copy.deepcopy(tracker._tracks)
        saved, tracker._tracks = tracker._tracks, plain
        expected = _plain_associate(tracker, det)
        tracker._tracks = saved
        out = update(det)
        np.testing.assert_array_equal(out, expected)
        np.testing.assert_array_equal(tracker._tracks.mean, plain.mean)
        np.testing.assert_array_equal(tracker._tracks.cov, plain.cov)
        checked += int((out >= 0).sum())
        return out

    tracker._associate_and_update = both
    for frame in seq.frames():
        tracker.update(frame)
    assert checked > 200
