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
    from lookalike.trackers.kernels.world import pairs

    rng = np.random.default_rng(seed)
    k, d = int(rng.integers(0, 9)), int(rng.integers(0, 9))
    cost = rng.choice([0.0, 0.1, 0.25, 0.3, 0.5, 2.0, np.inf], (k, d)) * rng.uniform(0.5, 1.5, (k, d))
    for max_cost in (0.3, np.inf):
        allowed = cost <= max_cost if np.isfinite(max_cost) else cost < np.inf
        rows, cols = pairs(cost, allowed, max_cost)
        expected = assign_pairs(np.where(allowed, cost, np.inf), max_cost)
        np.testing.assert_array_equal(np.stack([rows, cols], axis=1).reshape(-1, 2), expected)
        unit = np.minimum(cost, 1.0)  # (costs in [0, 1]: the unit shortcut)
        allowed = unit <= max_cost
        rows, cols = pairs(unit, allowed, min(max_cost, 1.0), unit=True)
        expected = assign_pairs(np.where(allowed, unit, np.inf), min(max_cost, 1.0))
        np.testing.assert_array_equal(np.stack([rows, cols], axis=1).reshape(-1, 2), expected)


def _plain_associate(tracker, det):
    """The association and update before the batched path: motion.kalman's functions, the solver."""
    from lookalike.association.solver import assign
    from lookalike.motion import gating_distance, kalman
    from lookalike.trackers.parts.world_tracker import H

    t = tracker._tracks
    det_of_track = np.full(len(t), -1, dtype=int)
    if len(t) and len(det):
        noise = tracker._space.R(t.mean[:, :2])
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

    seq = team_sequence("m10n7", 5, 3.0)  # 305 detections of robots
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


class _PlainIdentity:
    """The identifier's samples and hysteresis before the track table: a dict of sample windows per
    track and a dict of held agents (its agent headings come from the identifier under test)."""

    def __init__(self, ident):
        self.ident, self.samples, self.agent = ident, {}, {}

    def begin(self):
        for samples in self.samples.values():
            samples[self.ident._slot] = np.nan

    def observe(self, track_id, heading):
        w = self.ident.config.window_frames
        self.samples.setdefault(track_id, np.full(w, np.nan))[self.ident._slot] = heading

    def drop(self, ids):
        for t in ids:
            self.samples.pop(t, None)
            self.agent.pop(t, None)

    def assign(self, track_ids):
        from lookalike.association.solver import assign

        cfg, w = self.ident.config, self.ident.config.window_frames
        if not track_ids:
            return {}
        samples = np.stack([self.samples.get(t, np.full(w, np.nan)) for t in track_ids])
        agent = self.ident.agent_headings(self.ident._times)
        d = (1.0 - np.cos(samples[:, :, None] - agent[None])) / 2.0
        valid = np.isfinite(d)
        count = valid.sum(axis=1)
        total = np.where(valid, d, 0.0).sum(axis=1)
        cost = np.divide(total, count, out=np.full(count.shape, np.inf), where=count > 0)
        biased = cost.copy()
        for row, t in enumerate(track_ids):
            a = self.agent.get(t)
            if a is not None and np.isfinite(biased[row, a]):
                biased[row, a] = max(biased[row, a] - cfg.hysteresis, 0.0)
        matches, _, _ = assign(biased, cfg.max_cost)
        result = {track_ids[row]: (int(a), float(1.0 - cost[row, a])) for row, a in matches}
        self.agent = {t: a for t, (a, _) in result.items()} | {
            t: a for t, a in self.agent.items() if t not in track_ids}
        return result


@pytest.mark.parametrize("seed", range(6))
def test_identifier_table_equals_the_plain_dicts(seed):
    from lookalike.trackers.parts.identity import BeaconIdentifier
    from lookalike.trackers.parts.identity import IdentifierConfig as BeaconConfig
    from lookalike.types import Beacons

    rng = np.random.default_rng(seed)
    ident = BeaconIdentifier(BeaconConfig(n_agents=4, window_frames=6, max_cost=0.4, hysteresis=0.1))
    plain = _PlainIdentity(ident)
    alive, next_id, heading, assigned = [], 1, rng.uniform(-3, 3, 4), 0
    for f in range(80):
        heading += rng.normal(0, 0.2, 4)
        ids = rng.choice(4, rng.integers(0, 5), replace=False)
        ident.begin_frame(f / 10, Beacons(agent_id=ids, t_sent=np.full(len(ids), f / 10 - 0.05),
                                          t_received=np.full(len(ids), f / 10), heading=heading[ids]))
        plain.begin()
        for _ in range(int(rng.integers(0, 4))):  # births (more than the table's first 7 rows in all)
            alive.append(next_id)
            next_id += 1
        dead = [t for t in alive if rng.random() < 0.08]
        ident.drop(dead)
        plain.drop(dead)
        alive = [t for t in alive if t not in dead]
        for t in alive:
            if rng.random() < 0.8:
                h = float(heading[t % 4] + rng.normal(0, 0.3))
                ident.observe(t, h)
                plain.observe(t, h)
        asked = [t for t in alive if rng.random() < 0.9] + [10_000]  # (one track never observed)
        result = ident.assign(asked)
        assert result == plain.assign(asked)
        assigned += len(result)
    assert next_id > 20 and assigned > 50


def test_reports_built_outside_decode_are_still_validated():
    from lookalike.node import HeadingReport

    node = _node()
    with pytest.raises(ValueError, match="heading"):  # (as it arrives: it never reaches a frame)
        node.add_report(HeadingReport(robot=0, seq=0, t_sent=0.0, heading=math.nan))
    assert node.add_frame(DetectionsMessage(frame=0, time=0.1, position=(), heading=(), score=()))[0] == "frames"


@pytest.mark.parametrize("seed", range(10))
def test_team_bytes_equal_json_dumps(seed):
    import json

    from lookalike.node import RobotEstimate, TeamState, decode, encode
    from lookalike.node.messages import _team_bytes

    rng = np.random.default_rng(seed)

    def number():
        scaled = float(rng.normal() * 10.0 ** rng.integers(-8, 8))
        return float(rng.choice([0.0, -0.0, 1e-300, 1e12, -3.5, 1 / 3, scaled]))

    robots = tuple(RobotEstimate(id=int(j), position=(number(), number()),
                                 heading=None if rng.random() < 0.3 else number(),
                                 confidence=None if rng.random() < 0.3 else number(), age=number())
                   for j in range(int(rng.integers(0, 8))))
    team = TeamState(frame=int(rng.integers(0, 2**62)), time=number(), robots=robots,
                     labels=tuple(int(v) for v in rng.integers(-1, 7, int(rng.integers(0, 12)))))
    body = {"v": 1, "type": "team", "frame": team.frame, "time": team.time, "labels": list(team.labels),
            "robots": [{"id": r.id, "position": list(r.position), "heading": r.heading, "confidence": r.confidence,
                        "age": r.age} for r in robots]}
    expected = json.dumps(body, separators=(",", ":"), allow_nan=False).encode()
    assert _team_bytes(team) == expected == encode(team)
    assert decode(expected) == team


@pytest.mark.parametrize("team", [
    "TeamState(frame=0, time=math.nan, robots=())",
    "TeamState(frame=0, time=0.0, robots=(RobotEstimate(id=0, position=(math.inf, 0.0), heading=None, "
    "confidence=None, age=0.0),))",
    "TeamState(frame=0, time=0.0, robots=(RobotEstimate(id=0, position=(0.0, 0.0), heading=math.nan, "
    "confidence=None, age=0.0),))",
])
def test_team_encoding_still_refuses_non_finite_numbers(team):
    from lookalike.node import RobotEstimate, TeamState, encode  # noqa: F401 (used by eval)

    with pytest.raises(ValueError, match="non-finite"):
        encode(eval(team))


def test_team_encoding_of_other_number_types_goes_through_json():
    from lookalike.node import RobotEstimate, TeamState, encode

    team = TeamState(frame=3, time=1, robots=(RobotEstimate(id=0, position=(1, 2.5), heading=None, confidence=True,
                                                            age=0.0),), labels=(0, -1))
    assert encode(team) == (b'{"v":1,"type":"team","frame":3,"time":1,"labels":[0,-1],"robots":[{"id":0,'
                            b'"position":[1,2.5],"heading":null,"confidence":true,"age":0.0}]}')
