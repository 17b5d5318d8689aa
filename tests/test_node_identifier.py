"""The node's socket-free core: acceptance rules for reports and frames, team states."""

import numpy as np
from scipy.optimize import linear_sum_assignment

from lookalike.geometry import angle_diff
from lookalike.node import (
    DetectionsMessage,
    HeadingReport,
    IdentifierConfig,
    TeamIdentifier,
)
from lookalike.types import Frame, TrackSnapshot, TrackStatus


class HeadingMatcher:
    """A small real identifier for the node tests: each frame, Hungarian assignment of detections
    to the robots' latest reported headings (circular difference). Remembers every frame it saw."""

    name = "heading_matcher"

    def __init__(self, n_robots: int = 3) -> None:
        self.n_robots = n_robots
        self.reset()

    def reset(self) -> None:
        self.heading = np.full(self.n_robots, np.nan)
        self.frames: list[Frame] = []
        self.resets = getattr(self, "resets", -1) + 1

    def update(self, frame: Frame) -> list[TrackSnapshot]:
        self.frames.append(frame)
        b = frame.beacons
        self.heading[b.agent_id] = b.heading
        known = np.flatnonzero(~np.isnan(self.heading))
        det = frame.detections
        if not len(det) or not len(known):
            return []
        cost = np.abs(angle_diff(det.heading[:, None], self.heading[None, known]))
        rows, cols = linear_sum_assignment(cost)
        return [
            TrackSnapshot(track_id=int(known[c]) + 1, status=TrackStatus.CONFIRMED, position=det.position[r],
                          heading=float(det.heading[r]), agent_id=int(known[c]),
                          identity_prob=float(1 - cost[r, c] / np.pi), detection_index=int(r))
            for r, c in zip(rows, cols)
        ]


def _frame(k, headings, t=None):
    n = len(headings)
    return DetectionsMessage(frame=k, time=0.1 * k if t is None else t,
                             position=tuple((float(i), 0.0) for i in range(n)),
                             heading=tuple(headings), score=(1.0,) * n)


def test_reports_reach_the_tracker_with_the_next_frame():
    tracker = HeadingMatcher()
    node = TeamIdentifier(tracker, IdentifierConfig(n_robots=3))
    for j, h in enumerate([0.0, 2.0, -2.0]):
        assert node.add_report(HeadingReport(robot=j, seq=0, t_sent=0.05, heading=h)) == "reports"
    outcome, team = node.add_frame(_frame(1, [-2.0, 0.1, 2.1]))
    assert outcome == "frames"
    beacons = tracker.frames[0].beacons
    assert list(beacons.agent_id) == [0, 1, 2] and np.allclose(beacons.t_received, 0.1)
    assert team.labels == (2, 0, 1)
    assert [r.id for r in team.robots] == [0, 1, 2]
    assert team.robots[0].position == (1.0, 0.0) and team.robots[0].age == 0.0
    # The next frame carries no report again; robot 0 is not detected: it drops out of the state.
    outcome, team = node.add_frame(_frame(2, [2.0, -2.0]))
    assert len(tracker.frames[1].beacons) == 0
    assert team.labels == (1, 2)


def test_report_rules():
    node = TeamIdentifier(HeadingMatcher(), IdentifierConfig(n_robots=2, max_report_age_s=0.5))

    def add(robot, seq, t):
        return node.add_report(HeadingReport(robot=robot, seq=seq, t_sent=t, heading=0.0))

    assert add(0, 5, 1.0) == "reports"
    assert add(0, 5, 1.0) == "duplicate"
    assert add(0, 4, 0.9) == "late"  # overtaken by seq 5
    assert add(0, 6, 0.8) == "time_backwards"
    assert add(0, 0, 1.2) == "reports"  # the robot restarted its counter, with a newer send time
    assert add(2, 0, 1.0) == "unknown_robot"
    node.add_frame(_frame(20, [], t=2.0))
    assert add(1, 0, 1.4) == "late"  # more than 0.5 s before the last frame
    assert add(1, 1, 1.6) == "reports"


def test_frame_rules_and_camera_restart():
    tracker = HeadingMatcher()
    node = TeamIdentifier(tracker)
    assert node.add_frame(_frame(5, []))[0] == "frames"
    assert node.add_frame(_frame(5, [])) == ("duplicate", None)
    assert node.add_frame(_frame(3, [])) == ("frame_backwards", None)
    assert node.add_frame(_frame(6, []))[0] == "frames"
    node.camera_lost = True  # the server sets this when the camera falls silent
    outcome, team = node.add_frame(_frame(0, []))
    assert outcome == "frames" and team.frame == 0
    assert tracker.resets == 1 and node.restarts == 1 and not node.camera_lost
    # A camera that comes back *later* in time simply continues.
    node.camera_lost = True
    assert node.add_frame(_frame(9, []))[0] == "frames" and node.restarts == 1

