"""Messages that reach the node without ``decode`` (made in Python, or converted from ROS 2) are held to the wire's
bounds: one outside them is rejected as ``invalid`` and changes nothing, so it cannot break the tracker for the
frames after it."""

from __future__ import annotations

import math

import numpy as np
import pytest

from lookalike.node import DetectionsMessage, HeadingReport, IdentifierConfig, MessageError, TeamIdentifier, TeamState
from lookalike.node.server import NodeConfig, NodeCore
from tests.test_node_identifier import HeadingMatcher


class _Node(NodeCore):
    """The node's core without a transport: published team states are kept."""

    def __init__(self, tracker: object) -> None:
        super().__init__(tracker, NodeConfig(status_interval_s=0), IdentifierConfig(n_robots=3))
        self.published: list[TeamState] = []

    def poll(self, timeout_s: float) -> int:
        return 0

    def _publish(self, team: TeamState) -> None:
        self.published.append(team)


class _Fragile(HeadingMatcher):
    """Breaks for good (as a learned tracker's state does) once it sees a number beyond the wire's bounds."""

    broken = False

    def update(self, frame):
        values = np.concatenate([frame.detections.position.ravel(), frame.detections.heading])
        self.broken = self.broken or not bool(np.all(np.abs(values) <= 1e12))
        if self.broken:
            raise ValueError("matrix contains invalid numeric entries")
        return super().update(frame)


def _frame(k: int, **changes: object) -> DetectionsMessage:
    fields: dict[str, object] = {"frame": k, "time": 0.1 * k, "position": ((1.0, 0.0), (2.0, 0.0), (3.0, 0.0)),
                                 "heading": (-2.0, 0.0, 2.0), "score": (1.0, 1.0, 1.0)}
    fields.update(changes)
    return DetectionsMessage(**fields)  # type: ignore[arg-type]


BAD_FRAMES = [
    {"position": ((1e300, 0.0), (2.0, 0.0), (3.0, 0.0))}, {"position": ((math.nan, 0.0), (2.0, 0.0), (3.0, 0.0))},
    {"heading": (math.inf, 0.0, 2.0)}, {"heading": (0.0, 2.0)}, {"score": (1.0, 1.0, "1")},
    {"heading_std": (-0.1, 0.1, 0.1)}, {"time": math.nan}, {"frame": -1}, {"position": ((1.0, 0.0, 0.0),) * 3},
]


@pytest.mark.parametrize("changes", BAD_FRAMES)
def test_a_frame_outside_the_bounds_is_rejected_and_the_node_goes_on(changes):
    node = _Node(_Fragile())
    for j, h in enumerate([0.0, 2.0, -2.0]):
        node.handle_message(HeadingReport(robot=j, seq=0, t_sent=0.05, heading=h), ("robot", j), 0.0)
    node.handle_message(_frame(1, **changes), "camera", 0.0)
    assert node.counters.rejected == {"invalid": 1}
    assert node.counters.events["tracker_errors"] == 0 and not node.published
    node.handle_message(_frame(2), "camera", 0.0)  # (the queued reports are still there for it)
    assert node.counters.events["frames"] == 1 and node.counters.events["tracker_errors"] == 0
    assert node.published[-1].labels == (2, 0, 1)
    assert len(node.identifier.tracker.frames[0].beacons) == 3


@pytest.mark.parametrize("report", [
    HeadingReport(robot=-1, seq=0, t_sent=0.05, heading=0.0), HeadingReport(robot=0, seq=-3, t_sent=0.05, heading=0.0),
    HeadingReport(robot=0, seq=0, t_sent=math.nan, heading=0.0), HeadingReport(robot=0, seq=0, t_sent=0.05,
                                                                                   heading=1e300),
    HeadingReport(robot=True, seq=0, t_sent=0.05, heading=0.0),
])
def test_a_report_outside_the_bounds_is_rejected_and_touches_no_robot(report):
    identifier = TeamIdentifier(HeadingMatcher(), IdentifierConfig(n_robots=3))
    with pytest.raises(MessageError) as caught:
        identifier.add_report(report)
    assert caught.value.reason == "invalid" and "report." in caught.value.detail
    assert identifier.queued == 0
    # (robot -1 is not the last robot: that robot's next report is still its first)
    assert identifier.add_report(HeadingReport(robot=2, seq=0, t_sent=0.05, heading=0.0)) == "reports"
    node = _Node(HeadingMatcher())
    node.handle_message(report, ("robot", 0), 0.0)
    assert node.counters.rejected == {"invalid": 1} and node.counters.events["reports"] == 0


def test_numpy_numbers_made_in_python_are_accepted():
    identifier = TeamIdentifier(HeadingMatcher(), IdentifierConfig(n_robots=3))
    report = HeadingReport(robot=np.int64(1), seq=np.int32(4), t_sent=np.float64(0.05), heading=np.float32(0.5))
    assert identifier.add_report(report) == "reports"
    outcome, team = identifier.add_frame(_frame(np.int64(1), time=np.float64(0.1)))
    assert outcome == "frames" and team is not None
