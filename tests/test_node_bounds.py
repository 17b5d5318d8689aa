"""Issue 19, node rows: every field bounded, bounded report queues, nothing a peer sends escapes."""

import json

import pytest

from lookalike.node import (
    SCHEMA_VERSION,
    DetectionsMessage,
    HeadingReport,
    IdentifierConfig,
    MessageError,
    TeamIdentifier,
    decode,
)
from lookalike.node import messages as m
from lookalike.node.server import NodeServer
from tests.test_node_identifier import HeadingMatcher


def _raw(**body):
    return json.dumps({"v": SCHEMA_VERSION, **body}).encode()


def _report(**changes):
    body = {"type": "report", "robot": 0, "seq": 1, "t_sent": 0.0, "heading": 0.0}
    body.update(changes)
    return _raw(**body)


@pytest.mark.parametrize("seq", [2**63, 2**64, 10**30, 10**100])
def test_seq_beyond_64_bits_is_rejected_not_fatal(seq):
    """Row 1: "seq": 9223372036854775808 killed the node with an OverflowError."""
    with pytest.raises(MessageError) as err:
        decode(_report(seq=seq))
    assert err.value.reason == m.INVALID and "seq" in err.value.detail
    node = NodeServer(HeadingMatcher())
    try:
        node.handle(_report(seq=seq), ("127.0.0.1", 9), 0.0)
        node.handle(_report(seq=2**63 - 1), ("127.0.0.1", 9), 0.0)  # the largest one is fine
        c = node.counters.snapshot()
        assert c["rejected"] == {m.INVALID: 1} and c["reports"] == 1
    finally:
        node.close()


@pytest.mark.parametrize("body", [
    {"t_sent": 10**400}, {"t_sent": -10**400}, {"heading": 1e300}, {"robot": -1}, {"robot": 2**63},
    {"heading": True}, {"seq": 1.5}, {"extra" * 40: 1},
])
def test_report_fields_out_of_bounds(body):
    with pytest.raises(MessageError) as err:
        decode(_report(**body))
    assert err.value.reason == m.INVALID
    assert len(str(err.value)) < 300  # details quote at most a short excerpt of the value


def test_detection_and_team_bounds():
    n = m.MAX_DETECTIONS + 1
    big = _raw(type="detections", frame=0, time=0.0, position=[[0.0, 0.0]] * n, heading=[0.0] * n, score=[1.0] * n)
    with pytest.raises(MessageError):
        decode(big)
    with pytest.raises(MessageError):
        decode(_raw(type="detections", frame=2**63, time=0.0, position=[], heading=[], score=[]))
    with pytest.raises(MessageError):
        decode(_raw(type="detections", frame=0, time=0.0, position=[[0, 0]], heading=[0], score=[1],
                    heading_std=[-0.1]))
    with pytest.raises(MessageError):
        decode(_raw(type="team", frame=0, time=0.0, robots=[], labels=[2**63]))
    with pytest.raises(MessageError):
        decode(_raw(type="status", counters={"x" * 100: 1}))
    with pytest.raises(MessageError):
        decode(_raw(type="status", counters={"a": {"b": {"c": {"d": {"e": {}}}}}}))


def test_report_queues_are_bounded_and_drops_counted():
    """Row 2: 400k valid reports with no camera frame grew memory without bound."""
    node = TeamIdentifier(HeadingMatcher(n_robots=3),
                          IdentifierConfig(n_robots=3, max_queued_per_robot=8, max_queued=30))
    outcomes = [node.add_report(HeadingReport(robot=k % 3, seq=k // 3, t_sent=0.001 * k, heading=0.0))
                for k in range(3000)]
    assert node.queued == 24
    assert outcomes.count("reports") == 3000
    assert node.queue_dropped == 3000 - 3 * 8
    _, team = node.add_frame(DetectionsMessage(frame=0, time=3.0, position=(), heading=(), score=()))
    assert team is not None and node.queued == 0
    beacons = node.tracker.frames[-1].beacons
    assert len(beacons) == 24  # the 8 newest of each robot, in arrival order
    assert list(beacons.t_sent) == sorted(beacons.t_sent)
    assert set(beacons.t_sent.round(3)) == {round(0.001 * k, 3) for k in range(3000 - 24, 3000)}


def test_total_queue_bound_counts_queue_full():
    node = TeamIdentifier(HeadingMatcher(n_robots=4),
                          IdentifierConfig(n_robots=4, max_queued_per_robot=5, max_queued=12))
    outcomes = [node.add_report(HeadingReport(robot=j, seq=k, t_sent=0.01 * k, heading=0.0))
                for j in range(4) for k in range(5)]
    assert outcomes.count("reports") == 12 and outcomes.count("queue_full") == 8
    assert node.queued == 12


def test_server_counts_queue_drops():
    node = NodeServer(HeadingMatcher(), identifier_config=IdentifierConfig(n_robots=3, max_queued_per_robot=4))
    try:
        for k in range(100):
            node.handle(_report(seq=k, t_sent=0.01 * k), ("127.0.0.1", 1000 + k), 0.0)
        c = node.counters.snapshot()
        assert c["reports"] == 100 and c["queue_dropped"] == 96 and node.identifier.queued == 4
    finally:
        node.close()


@pytest.mark.parametrize("config", [{"max_queued": 0}, {"max_queued_per_robot": 0}, {"n_robots": 10**6}])
def test_identifier_config_bounds(config):
    with pytest.raises(ValueError):
        IdentifierConfig(**config)


def test_flood_from_a_thousand_ports_stays_bounded():
    """Row 2 as reported: valid reports from 1,000 ports and no camera frame."""
    config = IdentifierConfig(n_robots=3)
    node = NodeServer(HeadingMatcher(), identifier_config=config)
    try:
        for k in range(10_000):
            node.handle(_report(robot=k % 3, seq=k, t_sent=0.001 * k), ("127.0.0.1", 20_000 + k % 1000), 0.0)
        c = node.counters.snapshot()
        assert c["reports"] == 10_000
        assert node.identifier.queued == 3 * config.max_queued_per_robot
        assert c["queue_dropped"] == 10_000 - node.identifier.queued
        assert len(node._buckets) <= node.config.max_senders
    finally:
        node.close()
