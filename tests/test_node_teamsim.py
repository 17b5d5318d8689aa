"""The simulated team's building blocks: shared sequence, camera messages, robot schedules, clock."""

import time

import numpy as np
import pytest

from lookalike.node import TeamState, decode, encode
from lookalike.node.teamsim import SimClock, camera_messages, robot_reports, team_sequence
from tests.node_scoring import online_identification


@pytest.fixture(scope="module")
def sequence():
    return team_sequence("m5n3", 3, 5.0, loss=0.2, delay_s=0.05, jitter_s=0.1)


def test_team_sequence_is_shared_and_configured(sequence):
    again = team_sequence("m5n3", 3, 5.0, loss=0.2, delay_s=0.05, jitter_s=0.1)
    assert len(sequence) == 151 and sequence.config.network.loss_prob == 0.2
    assert np.array_equal(sequence.arrays.det_position, again.arrays.det_position)
    assert np.array_equal(sequence.arrays.reports.t_received, again.arrays.reports.t_received)
    with pytest.raises(ValueError, match="duration_s"):
        team_sequence("m5n3", 0, 0.0)
    with pytest.raises(ValueError, match="preset"):
        team_sequence("m9n9", 0, 1.0)


def test_camera_messages_carry_detections_but_not_labels(sequence):
    messages = camera_messages(sequence)
    assert len(messages) == len(sequence)
    for k in (0, 50, 150):
        frame, msg = sequence.frame(k), messages[k]
        assert msg.frame == k and msg.time == frame.time
        assert np.allclose(msg.position, frame.detections.position.reshape(-1, 2))
        assert np.allclose(msg.heading, frame.detections.heading)
        assert decode(encode(msg)) == msg
        assert b"label" not in encode(msg)


def test_robot_reports_follow_the_simulated_network(sequence):
    r = sequence.arrays.reports
    for j in range(3):
        schedule = robot_reports(sequence, j)
        assert len(schedule) == int((r.agent_id == j).sum())
        arrivals = [t for t, _ in schedule]
        assert arrivals == sorted(arrivals)
        for t, report in schedule:
            assert report.robot == j and t >= report.t_sent + 0.05 - 1e-9
        # Sequence numbers follow send order; losses leave gaps (20% loss over ~50 reports).
        by_send = sorted(report.seq for _, report in schedule)
        assert len(set(by_send)) == len(by_send) and by_send[-1] + 1 > len(by_send)
    with pytest.raises(ValueError, match="robot 3"):
        robot_reports(sequence, 3)


def test_online_identification_scores_the_published_labels(sequence):
    truth = sequence.true_labels()
    perfect = [TeamState(frame=k, time=0.0, robots=(), labels=tuple(int(v) for v in truth[k])) for k in range(20)]
    rate, frames = online_identification(sequence, perfect)
    assert (rate, frames) == (1.0, 20)
    wrong = [TeamState(frame=k, time=0.0, robots=(), labels=tuple({-1: 0, 0: 1, 1: 2, 2: -1}[int(v)] for v in truth[k]))
             for k in range(20) if len(truth[k])]
    assert online_identification(sequence, wrong)[0] == 0.0


def test_sim_clock():
    clock = SimClock(epoch=time.time() - 1.0, speed=4.0)
    assert 3.9 < clock.now() < 10.0
    assert clock.wait_until(0.0)
    assert not SimClock(epoch=time.time() + 100.0).wait_until(1.0, stop=lambda: True)
    with pytest.raises(ValueError, match="speed"):
        SimClock(epoch=0.0, speed=0.0)
