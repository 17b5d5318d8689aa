"""The simulated team's building blocks: shared sequence, camera messages, robot schedules, clock."""

import time

import numpy as np
import pytest

from lookalike.node import TeamState, decode, encode
from lookalike.node.teamsim import SimClock, camera_messages, robot_reports, run_camera, run_robot, team_sequence
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
    with pytest.raises(ValueError, match="unknown team"):
        team_sequence("m9x9", 0, 1.0)


def test_camera_messages_carry_detections_but_not_labels(sequence):
    messages = camera_messages(sequence)
    assert len(messages) == len(sequence)
    for k in (0, 50, 150):
        frame, msg = sequence.frame(k), messages[k]
        assert msg.frame == k and msg.time == frame.time
        assert np.allclose(np.reshape(msg.position, (-1, 2)), frame.detections.position.reshape(-1, 2))
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


class _Recorder:
    """An endpoint that keeps what is sent and never receives anything."""

    def __init__(self):
        self.sent = []

    def send(self, message):
        self.sent.append(message)

    def receive(self, timeout_s):
        time.sleep(min(timeout_s, 0.001))
        return None


def test_a_late_start_is_warned_and_skips_what_was_due(sequence):
    """A process started after --start-at says so and begins at the present instead of sending the past at once;
    a robot that never heard its position says so too."""
    assert SimClock(epoch=time.time() + 5.0).late_start("robot 1") == (0.0, None)
    assert SimClock(epoch=time.time()).late_start("robot 1") == (0.0, None)  # --start-at now
    start, line = SimClock(epoch=time.time() - 3.0, speed=1000.0).late_start("the camera")
    assert 3000.0 <= start < 4000.0
    assert line.startswith("warning: the camera started 3.") and "skipping the first 3" in line
    # 5 simulated seconds at speed 1000 from a clock started 4.998 s (simulated) ago: only the last frames go out.
    clock = SimClock(epoch=time.time() - 4.998 / 1000.0, speed=1000.0)
    camera = _Recorder()
    messages = camera_messages(sequence)
    assert run_camera(camera, messages, clock, start_s=4.9) == sum(m.time >= 4.9 for m in messages)
    assert min(m.time for m in camera.sent) >= 4.9
    robot = _Recorder()
    log = run_robot(robot, 0, sequence, clock, linger_s=0.0, start_s=4.0)
    assert log.reports_sent == len(robot.sent) == sum(t >= 4.0 for t, _ in robot_reports(sequence, 0))
    assert log.summary()["median_error_m"] is None
    assert log.warning().startswith("warning: robot 1 received no team state")
    log.errors_m.append(0.1)
    assert log.warning() is None


class _Unreachable(_Recorder):
    """An endpoint on a network that is down for every other message (the OS refuses the send)."""

    def send(self, message):
        if len(self.sent) % 2:
            self.sent.append(None)
            raise OSError(101, "Network is unreachable")
        self.sent.append(message)


def test_a_network_that_is_down_loses_messages_but_not_the_process(sequence):
    """robot-sim and camera-sim go on when a send fails, as on a lossy link, and count what they could not send."""
    clock = SimClock(epoch=time.time() - 5.5 / 1000.0, speed=1000.0)  # (everything is due: sent at once)
    camera, failed = _Unreachable(), []
    messages = camera_messages(sequence)
    sent = run_camera(camera, messages, clock, on_send_error=failed.append)
    assert sent + len(failed) == len(messages) and sent == len(messages) - len(messages) // 2
    assert str(failed[0]) == "[Errno 101] Network is unreachable"
    robot = _Unreachable()
    log = run_robot(robot, 0, sequence, clock, linger_s=0.0)
    assert log.reports_sent + log.send_errors == len(robot_reports(sequence, 0)) and log.send_errors > 0
    assert log.summary()["send_errors"] == log.send_errors
    assert "robot 1 could not send" in log.warning() and "Network is unreachable" in log.warning()
