"""Issue 18: the batched send. With a multicast group the node sends each team state once."""

import socket
import threading

import pytest

from lookalike.node import DetectionsMessage, Endpoint, HeadingReport, NodeConfig, NodeServer, TeamState
from tests.test_node_identifier import HeadingMatcher


def _free_port():
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
        s.bind(("", 0))
        return s.getsockname()[1]


def test_one_send_per_frame_reaches_every_robot():
    group = ("239.255.77.3", _free_port())
    try:
        node = NodeServer(HeadingMatcher(), NodeConfig(group=group, status_interval_s=0))
        robots = [Endpoint(node.address, group=group) for _ in range(3)]
    except OSError as exc:  # a host without multicast on loopback
        pytest.skip(f"no loopback multicast here: {exc}")
    stop = threading.Event()
    thread = threading.Thread(target=node.serve, args=(stop.is_set, 0.01))
    thread.start()
    try:
        with Endpoint(node.address) as camera:
            for j, robot in enumerate(robots):
                robot.send(HeadingReport(robot=j, seq=0, t_sent=0.0, heading=float(j)))
            camera.send(DetectionsMessage(frame=1, time=0.1, position=((0.0, 0.0), (1.0, 0.0), (2.0, 0.0)),
                                          heading=(0.0, 1.0, 2.0), score=(1.0, 1.0, 1.0)))
            got = [robot.receive(5.0) for robot in robots]
        assert all(isinstance(g, TeamState) and g.frame == 1 for g in got)
        assert got[0].labels == (0, 1, 2)
    finally:
        stop.set()
        thread.join()
        for robot in robots:
            robot.close()
        node.close()
    assert node.counters.events["published"] == 1  # one datagram for the three robots


@pytest.mark.parametrize("group", [("10.0.0.1", 7000), ("239.1.1.1", 0), ("not-an-ip", 7000)])
def test_group_must_be_multicast(group):
    with pytest.raises(ValueError, match="multicast"):
        NodeConfig(group=group)
