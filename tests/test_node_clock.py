"""The node trusts message times only within reason: a frame or report far ahead of the camera's clock is dropped
and counted, frames from another sender do not replace a live camera, lockouts expire, and the node follows a
camera again within one camera timeout of a hostile clock."""

import time
from contextlib import contextmanager

from hypothesis import HealthCheck, Phase, given, settings
from hypothesis import strategies as st

from lookalike.node import (
    DetectionsMessage,
    Endpoint,
    HeadingReport,
    IdentifierConfig,
    StatusRequest,
    TeamIdentifier,
    TeamState,
)
from tests.test_node_identifier import HeadingMatcher, _frame
from tests.test_node_server import running_node

BIG_SEQ = 2**63 - 1


def _report(robot, seq, t, heading=0.0):
    return HeadingReport(robot=robot, seq=seq, t_sent=t, heading=heading)


def test_a_frame_far_ahead_is_dropped_and_the_camera_goes_on():
    node = TeamIdentifier(HeadingMatcher(), IdentifierConfig(max_frame_jump_s=10.0))
    assert node.add_frame(_frame(1, [0.0]))[0] == "frames"
    assert node.add_frame(_frame(2, [0.0], t=1e12)) == ("time_ahead", None)
    assert node.add_frame(_frame(3, [0.0]))[0] == "frames"  # the camera's next frame: still its clock
    assert node.add_frame(_frame(4, [0.0], t=0.3 + 9.9))[0] == "frames"  # a jump within the bound
    node.camera_lost = True  # a camera that was lost may come back at any time
    assert node.add_frame(_frame(5, [0.0], t=500.0))[0] == "frames" and node.restarts == 0


def test_a_report_far_ahead_cannot_lock_a_robot_out():
    node = TeamIdentifier(HeadingMatcher(), IdentifierConfig(n_robots=2, max_report_ahead_s=1.0))
    node.add_frame(_frame(1, []))
    assert node.add_report(_report(0, BIG_SEQ, 1e12)) == "time_ahead"
    assert node.add_report(_report(0, 0, 0.12)) == "reports"  # the robot's own reports still count
    # Before any frame there is no clock to judge by: the report is taken, and forgotten at the first frame.
    fresh = TeamIdentifier(HeadingMatcher(), IdentifierConfig(n_robots=2, max_report_ahead_s=1.0))
    assert fresh.add_report(_report(0, BIG_SEQ, 1e12)) == "reports"
    assert fresh.add_report(_report(0, 1, 0.05)) == "late"
    assert fresh.add_frame(_frame(1, []))[0] == "frames" and fresh.robot_resets == 1
    assert fresh.add_report(_report(0, 1, 0.15)) == "reports"


@contextmanager
def _node(camera_timeout_s=2.0):
    """A node publishing every team state to ``node.listener``, served by a background thread."""
    listener = Endpoint(("127.0.0.1", 9))
    try:
        with running_node(camera_timeout_s=camera_timeout_s, publish=(listener.address,)) as server:
            server.listener = listener
            yield server
    finally:
        listener.close()


def _answered(listener, frame, timeout_s=0.5):
    """Whether the team state of camera frame ``frame`` reaches ``listener`` within ``timeout_s``."""
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        msg = listener.receive(deadline - time.monotonic())
        if isinstance(msg, TeamState) and msg.frame == frame:
            return True
    return False


def _camera_frame(k):
    return DetectionsMessage(frame=k, time=k / 30, position=((1.0, 0.0),), heading=(0.5,), score=(1.0,))


def _play(node, hostile_between, frames=60, start=1):
    """A robot reports and a camera sends ``frames`` frames at 30 Hz; ``hostile_between(k, sender)`` sends
    messages from another socket before frame ``k``. Returns how many camera frames were answered."""
    answered = 0
    with Endpoint(node.address) as robot, Endpoint(node.address) as camera, Endpoint(node.address) as other:
        for k in range(start, start + frames):
            hostile_between(k, other)
            robot.send(_report(0, k, k / 30 - 0.01, heading=0.5))
            camera.send(_camera_frame(k))
            answered += _answered(node.listener, k)
            other.drain()
            robot.drain()
    return answered


def test_one_datagram_far_ahead_does_not_stall_the_node():
    def hostile(k, other):
        if k == 5:
            other.send(DetectionsMessage(frame=k + 1, time=1e12, position=(), heading=(), score=()))
        if k == 6:
            other.send(_report(0, BIG_SEQ, 1e12))
            other.send(_report(1, BIG_SEQ, k / 30 + 0.5))  # within the bound: robot 1's lockout expires

    with _node() as node:
        answered = _play(node, hostile, frames=450)
        counters = node.counters.snapshot()
    assert answered >= 0.99 * 450, answered
    assert counters["other_camera"] == 1 and counters["time_ahead"] == 1 and counters["reports"] >= 449


def test_the_node_recovers_within_one_camera_timeout_from_a_hostile_clock():
    timeout_s = 0.3
    with _node(camera_timeout_s=timeout_s) as node:
        with Endpoint(node.address) as hostile:  # a sender that comes first, with a clock far ahead
            hostile.send(DetectionsMessage(frame=10**9, time=1e12, position=(), heading=(), score=()))
            assert _answered(node.listener, 10**9)
        with Endpoint(node.address) as camera:
            t0, k = time.monotonic(), 1
            while True:
                camera.send(_camera_frame(k))
                if _answered(node.listener, k, timeout_s=1 / 30):
                    break
                k += 1
                assert time.monotonic() - t0 < 3 * timeout_s, "the node did not follow the camera"
            recovered_s = time.monotonic() - t0
        counters = node.counters.snapshot()
    assert recovered_s <= timeout_s + 0.2, recovered_s
    assert counters["camera_lost"] == 1 and counters["camera_restarts"] == 1


_numbers = st.floats(-1e12, 1e12, allow_nan=False) | st.floats(-5.0, 20.0, allow_nan=False)
_detections = st.integers(0, 3).flatmap(lambda n: st.builds(
    DetectionsMessage, frame=st.integers(0, BIG_SEQ), time=_numbers,
    position=st.lists(st.tuples(st.floats(-1e3, 1e3), st.floats(-1e3, 1e3)), min_size=n, max_size=n).map(tuple),
    heading=st.lists(st.floats(-3.14, 3.14), min_size=n, max_size=n).map(tuple),
    score=st.lists(st.floats(0, 1), min_size=n, max_size=n).map(tuple)))
_reports = st.builds(HeadingReport, robot=st.integers(0, 5), seq=st.integers(0, BIG_SEQ), t_sent=_numbers,
                     heading=st.floats(-3.14, 3.14))
# (k >= 2: after the camera's first frame, once the node knows its camera)
_hostile = st.lists(st.tuples(st.integers(2, 100), st.one_of(_detections, _reports, st.just(StatusRequest()))),
                    min_size=1, max_size=8)


@settings(max_examples=12, deadline=None, suppress_health_check=[HealthCheck.too_slow],
          phases=[Phase.explicit, Phase.reuse, Phase.generate])  # (no shrinking: a failure prints its messages)
@given(messages=_hostile)
def test_any_valid_messages_between_a_cameras_frames_leave_it_answered(messages):
    by_frame: dict[int, list] = {}
    for k, message in messages:
        by_frame.setdefault(k, []).append(message)

    def hostile(k, other):
        for message in by_frame.get(k, []):
            other.send(message)

    with _node() as node:
        answered = _play(node, hostile, frames=100)
    assert answered >= 99, (answered, messages)
