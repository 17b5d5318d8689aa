"""The set identifier where the LSTM is used: shared localiser, report jumps, the node, the labelling page."""

import numpy as np
import pytest

from lookalike.sim import preset, simulate_robots
from lookalike.trackers import make_tracker
from lookalike.trackers.set.network import SHIPPED_SET_WEIGHTS
from lookalike.types import Beacons, Detections, Frame

pytestmark = pytest.mark.skipif(not SHIPPED_SET_WEIGHTS.is_file(), reason="no shipped set weights")


def test_localiser_changes_positions_not_labels():
    seq = simulate_robots(preset("m3n2"), 90, 11)
    runs = {}
    for name in ("kalman", "lowpass"):
        tracker = make_tracker("set", n_agents=2, localiser=name)
        runs[name] = [(tracker.update(f), tracker.last_labels.copy()) for f in seq.frames()]
    moved = False
    for (tk, lk), (tl, ll) in zip(runs["kalman"], runs["lowpass"]):
        np.testing.assert_array_equal(lk, ll)
        assert all(np.isfinite(t.position).all() for t in tk)
        pos_k = {t.agent_id: t.position for t in tk}
        moved |= any(not np.allclose(pos_k[t.agent_id], t.position) for t in tl if t.agent_id in pos_k)
    assert moved


def _frame(k, headings, reported):
    n = len(headings)
    det = Detections(position=np.column_stack([np.arange(n, dtype=float) + 1.0, np.zeros(n)]),
                     heading=np.asarray(headings, float), score=np.ones(n))
    t = k / 30
    beacons = Beacons(agent_id=np.arange(len(reported)), t_sent=np.full(len(reported), t),
                      t_received=np.full(len(reported), t), heading=np.asarray(reported, float))
    return Frame(index=k, time=t, detections=det, beacons=beacons)


@pytest.mark.parametrize(("jump", "exchanged"), [(None, []), (0.5, [(0, 1)])])
def test_a_report_jump_exchanges_memories_with_the_agent_that_reported_the_new_heading(jump, exchanged):
    tracker = make_tracker("set", n_agents=2, report_jump=jump)
    for k in range(30):
        tracker.update(_frame(k, [0.0, 2.5], [0.0 + 0.01 * k, 2.5]))  # smooth turns: nothing exchanged
    assert tracker.net.m[:, 0].min() > 0.9  # both agents remembered
    calls = []
    swap = tracker.net.swap
    tracker.net.swap = lambda a, b: (calls.append((a, b)), swap(a, b))
    tracker.update(_frame(30, [0.0, 2.5], [2.5, 2.5]))  # agent 0's report turns 2.2 rad in 1/30 s, onto agent 1's
    assert calls == exchanged


def test_node_core_identifies_with_set():
    from lookalike.node import TeamIdentifier
    from lookalike.node.identifier import IdentifierConfig
    from lookalike.node.teamsim import camera_messages, robot_reports, team_sequence

    seq = team_sequence("m3n2", 5, 3.0)  # both robots detected together in 10 frames or more
    node = TeamIdentifier(make_tracker("set", n_agents=2), IdentifierConfig(n_robots=2))
    events = [(t, 0, r) for j in range(2) for t, r in robot_reports(seq, j)]
    events += [(m.time, 1, m) for m in camera_messages(seq)]
    states = []
    for _, kind, message in sorted(events, key=lambda e: (e[0], e[1])):
        if kind == 0:
            node.add_report(message)
        else:
            outcome, team = node.add_frame(message)
            assert outcome == "frames"
            states.append(team)
    assert any(len(s.robots) == 2 for s in states)
    assert all(set(s.labels) <= {-1, 0, 1} for s in states)


def test_labelling_page_starts_from_set_labels():
    from lookalike.cli.label import tracker_labels

    seq = simulate_robots(preset("m3n2"), 20, 12)
    labels = tracker_labels("set", seq)
    assert len(labels) == 20 and all(set(f) <= {-1, 0, 1} for f in labels)
