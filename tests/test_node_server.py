"""The UDP node on loopback: publishing, counters, and the fault cases of issue 8.

Every test binds ephemeral ports on 127.0.0.1, sends a bounded number of datagrams, and stops
the node itself; assertions count messages, never time them.
"""

import json
import threading
import time
from contextlib import contextmanager

import pytest

from lookalike.node import (
    DetectionsMessage,
    Endpoint,
    HeadingReport,
    IdentifierConfig,
    NodeConfig,
    NodeServer,
    Status,
    StatusRequest,
    TeamState,
    parse_address,
)
from tests.test_node_identifier import HeadingMatcher

HEADINGS = [0.0, 2.0, -2.0]


@contextmanager
def serving(server):
    """Serve ``server`` (a node) on a background thread until the block ends, then close it."""
    stop = threading.Event()
    thread = threading.Thread(target=server.serve, args=(stop.is_set, 0.01), daemon=True)
    thread.start()
    try:
        yield server
    finally:
        stop.set()
        thread.join(timeout=10)
        server.close()
    assert not thread.is_alive(), "the node did not stop"


@contextmanager
def running_node(**config):
    """A node on an ephemeral loopback port, served by a background thread until the block ends."""
    tracker = HeadingMatcher()
    with serving(NodeServer(tracker, NodeConfig(status_interval_s=0, **config), IdentifierConfig(n_robots=3))) as s:
        yield s


def _detections(k, t=None):
    return DetectionsMessage(frame=k, time=0.1 * k if t is None else t,
                             position=((1.0, 0.0), (2.0, 0.0), (3.0, 0.0)),
                             heading=(HEADINGS[2], HEADINGS[0], HEADINGS[1]), score=(1.0, 1.0, 1.0))


def _teams(endpoint, count, timeout_s=5.0):
    """Up to ``count`` team states received within ``timeout_s`` in all."""
    out, deadline = [], time.monotonic() + timeout_s
    while len(out) < count and time.monotonic() < deadline:
        msg = endpoint.receive(deadline - time.monotonic())
        if isinstance(msg, TeamState):
            out.append(msg)
    return out


def _status(node_address):
    with Endpoint(node_address) as ask:
        for _ in range(20):
            ask.send(StatusRequest())
            msg = ask.receive(0.5)
            if isinstance(msg, Status):
                return msg.counters
    raise AssertionError("no status reply")


def _wait_for(node_address, predicate, timeout_s=5.0):
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        counters = _status(node_address)
        if predicate(counters):
            return counters
        time.sleep(0.02)
    return counters


def test_parse_address():
    assert parse_address("127.0.0.1:9000") == ("127.0.0.1", 9000)
    assert parse_address("9001") == ("127.0.0.1", 9001)
    for bad in ("host:port", "127.0.0.1:70000", ":"):
        with pytest.raises(ValueError, match="address"):
            parse_address(bad)


def test_default_binds_loopback():
    with NodeServer(HeadingMatcher()) as server:
        assert server.address[0] == "127.0.0.1"


def test_robots_and_subscribers_receive_identified_positions():
    subscriber = Endpoint(("127.0.0.1", 1))
    with subscriber, running_node(publish=(subscriber.address,)) as node:
        robots = [Endpoint(node.address) for _ in range(3)]
        camera = Endpoint(node.address)
        try:
            for j, robot in enumerate(robots):
                robot.send(HeadingReport(robot=j, seq=0, t_sent=0.0, heading=HEADINGS[j]))
            _wait_for(node.address, lambda c: c["reports"] == 3)
            for k in range(1, 6):
                camera.send(_detections(k))
                assert len(_teams(subscriber, 1)) == 1
            for j, robot in enumerate(robots):
                teams = _teams(robot, 5)
                assert len(teams) == 5
                mine = [r for r in teams[-1].robots if r.id == j]
                assert mine and mine[0].position == (float((2, 0, 1).index(j) + 1), 0.0)
                assert teams[-1].labels == (2, 0, 1)
            counters = _status(node.address)
            assert counters["frames"] == 5 and counters["reports"] == 3
            assert counters["published"] == 5 * 4  # the subscriber and three robots
            assert counters["latency_ms"]["frames"] == 5
        finally:
            for e in robots + [camera]:
                e.close()


def test_faults_are_counted_and_the_node_keeps_serving():
    with running_node() as node:
        good = Endpoint(node.address)
        bad = Endpoint(node.address)
        camera = Endpoint(node.address)
        try:
            good.send(HeadingReport(robot=0, seq=1, t_sent=0.0, heading=0.0))
            bad.send_bytes(b"{not json")
            bad.send_bytes(b"\x00\x01\x02")
            bad.send_bytes(json.dumps({"v": 99, "type": "report"}).encode())
            bad.send_bytes(json.dumps({"v": 1, "type": "report", "robot": 0}).encode())
            bad.send(HeadingReport(robot=7, seq=0, t_sent=0.0, heading=0.0))  # unknown robot id
            good.send(HeadingReport(robot=0, seq=1, t_sent=0.0, heading=0.0))  # duplicate
            good.send(HeadingReport(robot=0, seq=2, t_sent=-5.0, heading=0.0))  # time going backwards
            bad.send(TeamState(frame=0, time=0.0, robots=()))  # a node-only message type
            camera.send(_detections(10))
            camera.send(_detections(10))  # duplicate frame
            camera.send(_detections(4))  # an older frame
            camera.send(_detections(11))
            c = _wait_for(node.address, lambda c: c["frames"] == 2 and c["rejected_total"] == 5)
            assert c["rejected"] == {"malformed": 2, "wrong_version": 1, "invalid": 1, "unexpected_type": 1}
            assert (c["unknown_robot"], c["duplicate"], c["time_backwards"], c["frame_backwards"]) == (1, 2, 1, 1)
            assert c["reports"] == 1 and c["frames"] == 2
            # Still serving: a robot that reports now gets the next team state.
            good.send(HeadingReport(robot=0, seq=3, t_sent=1.15, heading=0.0))
            _wait_for(node.address, lambda c: c["reports"] == 2)
            good.drain()
            camera.send(_detections(12))
            assert _teams(good, 1)
        finally:
            for e in (good, bad, camera):
                e.close()


def test_flood_from_one_sender_is_rate_limited_and_others_are_served():
    n_flood, n_frames = 10_000, 20
    with running_node(sender_rate=2000.0, sender_burst=200.0) as node:
        robot, camera = Endpoint(node.address), Endpoint(node.address)
        flooder = Endpoint(node.address)
        packet = HeadingReport(robot=1, seq=0, t_sent=0.0, heading=0.0)

        def flood():  # 10,000 datagrams in about one second, in bursts of 100
            from lookalike.node import encode
            data = encode(packet)
            for _ in range(n_flood // 100):
                for _ in range(100):
                    flooder.send_bytes(data)
                time.sleep(0.01)

        sender = threading.Thread(target=flood)
        try:
            robot.send(HeadingReport(robot=0, seq=0, t_sent=0.0, heading=0.0))
            sender.start()
            teams = []
            for k in range(1, n_frames + 1):
                robot.send(HeadingReport(robot=0, seq=k, t_sent=0.1 * k, heading=0.0))
                camera.send(_detections(k))
                teams += _teams(robot, 1, timeout_s=2.0)
            sender.join(timeout=30)
            c = _wait_for(node.address, lambda c: c["received"] >= n_flood * 0.5)
            assert not sender.is_alive()
            assert c["rate_limited"] > 0
            assert c["frames"] >= n_frames - 2 and len(teams) >= n_frames - 2
            assert c["reports"] >= n_frames - 2
            # The flooder's copies that got through are duplicates of one report, never accepted twice.
            handled = c["rate_limited"] + c["reports"] + c["frames"] + c["status_requests"]
            assert c["duplicate"] == c["received"] - handled
        finally:
            for e in (robot, camera, flooder):
                e.close()


def test_camera_dying_and_coming_back():
    with running_node(camera_timeout_s=0.2) as node:
        robot = Endpoint(node.address)
        try:
            robot.send(HeadingReport(robot=0, seq=0, t_sent=0.0, heading=0.0))
            with Endpoint(node.address) as camera:
                for k in range(1, 4):
                    camera.send(_detections(k))
                _wait_for(node.address, lambda c: c["frames"] == 3)
            c = _wait_for(node.address, lambda c: c["camera_lost"] == 1)
            assert c["camera_lost"] == 1
            robot.send(HeadingReport(robot=0, seq=1, t_sent=0.05, heading=0.0))  # the robot carries on
            with Endpoint(node.address) as camera:  # a new process, from frame 0 again
                robot.drain()
                camera.send(_detections(0))
                camera.send(_detections(1))
                teams = _teams(robot, 2)
            c = _status(node.address)
            assert c["camera_restarts"] == 1 and c["frames"] == 5 and len(teams) == 2
            assert node.identifier.tracker.resets == 1
        finally:
            robot.close()


class _Exploding(HeadingMatcher):
    """Raises on frames whose index is odd: a tracker bug the node must survive."""

    def update(self, frame):
        if frame.index % 2:
            raise RuntimeError("boom")
        return super().update(frame)


def test_a_failing_tracker_is_counted_and_the_node_goes_on():
    server = NodeServer(_Exploding(), NodeConfig(status_interval_s=0), IdentifierConfig(n_robots=3))
    stop = threading.Event()
    thread = threading.Thread(target=server.serve, args=(stop.is_set, 0.01), daemon=True)
    thread.start()
    try:
        with Endpoint(server.address) as robot, Endpoint(server.address) as camera:
            robot.send(HeadingReport(robot=0, seq=0, t_sent=0.0, heading=0.0))
            _wait_for(server.address, lambda c: c["reports"] == 1)
            for k in range(4):
                camera.send(_detections(k))
            teams = _teams(robot, 2)
            c = _wait_for(server.address, lambda c: c["tracker_errors"] == 2)
    finally:
        stop.set()
        thread.join(timeout=10)
        server.close()
    assert [t.frame for t in teams] == [0, 2]
    assert c["tracker_errors"] == 2 and c["frames"] == 2
