"""Socket-free core of the node: checks reports and frames, runs the tracker, builds team states.

Clocks: every time here is *simulated* time carried by the messages (``t_sent`` of a report,
``time`` of a frame); the node never reads a clock of its own for them. A report is delivered to
the tracker with the next frame and stamped ``t_received`` = that frame's time. Simulated time may
therefore run faster than wall time, as long as every process scales it the same way.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from lookalike.node.messages import (
    DetectionsMessage,
    HeadingReport,
    RobotEstimate,
    TeamState,
)
from lookalike.trackers.identity import labels_from_tracks
from lookalike.types import Beacons, Detections, Frame, TrackSnapshot


@dataclass(frozen=True)
class IdentifierConfig:
    """Message acceptance rules.

    Attributes:
        n_robots: robots in the team; ids ``0 .. n_robots-1`` are accepted.
        max_report_age_s: a report sent more than this before the latest frame is late (seconds).
    """

    n_robots: int = 3
    max_report_age_s: float = 1.0

    def __post_init__(self) -> None:
        if self.n_robots < 1:
            raise ValueError(f"n_robots must be >= 1, got {self.n_robots}")
        if not self.max_report_age_s > 0:
            raise ValueError(f"max_report_age_s must be > 0, got {self.max_report_age_s}")


class TeamIdentifier:
    """Accepts heading reports and detection frames in arrival order and identifies the team.

    ``add_report`` and ``add_frame`` return the name of the counter the message falls under
    (``"reports"``/``"frames"`` when accepted); ``add_frame`` also returns the team state.
    """

    def __init__(self, tracker: Any, config: IdentifierConfig | None = None) -> None:
        self.tracker = tracker
        self.config = config or IdentifierConfig()
        n = self.config.n_robots
        self._last_seq = np.full(n, -1)
        self._last_sent = np.full(n, -math.inf)
        self._pending: list[HeadingReport] = []
        self._last_update = np.full(n, math.nan)  # frame time a detection last updated each robot
        self.last_frame: int | None = None
        self.last_time = -math.inf
        self.camera_lost = False
        self.restarts = 0

    def add_report(self, report: HeadingReport) -> str:
        """Queue ``report`` for the next frame, or say why it is dropped."""
        j = report.robot
        if j >= self.config.n_robots:
            return "unknown_robot"
        last_seq, last_sent = self._last_seq[j], self._last_sent[j]
        if report.seq == last_seq:
            return "duplicate"
        if report.seq < last_seq and report.t_sent <= last_sent:
            return "late"  # overtaken by a newer report of the same robot
        if report.seq > last_seq and report.t_sent < last_sent:
            return "time_backwards"
        # (seq < last_seq with a newer send time: the robot restarted its counter; accept.)
        if report.t_sent < self.last_time - self.config.max_report_age_s:
            return "late"
        self._last_seq[j], self._last_sent[j] = report.seq, report.t_sent
        self._pending.append(report)
        return "reports"

    def add_frame(self, message: DetectionsMessage) -> tuple[str, TeamState | None]:
        """Track one camera frame with the reports queued since the previous one."""
        if self.last_frame is not None:
            if message.frame == self.last_frame or message.time == self.last_time:
                return "duplicate", None
            if message.time < self.last_time:
                if not self.camera_lost:
                    return "frame_backwards", None
                self.restart()
        self.camera_lost = False
        frame = self._frame(message)
        snapshots = self.tracker.update(frame)
        self.last_frame, self.last_time = message.frame, message.time
        return "frames", self._team_state(frame, snapshots)

    def restart(self) -> None:
        """The camera came back with an earlier time: reset the tracker and the frame clock."""
        self.tracker.reset()
        self.restarts += 1
        self._pending.clear()
        self._last_update[:] = math.nan
        self._last_sent[:] = -math.inf
        self._last_seq[:] = -1
        self.last_frame, self.last_time = None, -math.inf

    def _frame(self, message: DetectionsMessage) -> Frame:
        n = len(message.position)
        detections = Detections(
            position=np.asarray(message.position, dtype=float).reshape(n, 2),
            heading=np.asarray(message.heading, dtype=float),
            score=np.asarray(message.score, dtype=float),
            heading_std=None if message.heading_std is None else np.asarray(message.heading_std, dtype=float),
        )
        reports, self._pending = self._pending, []
        beacons = Beacons(
            agent_id=np.array([r.robot for r in reports], dtype=int),
            t_sent=np.array([r.t_sent for r in reports], dtype=float),
            t_received=np.full(len(reports), message.time),
            heading=np.array([r.heading for r in reports], dtype=float),
        )
        return Frame(index=message.frame, time=message.time, detections=detections, beacons=beacons)

    def _team_state(self, frame: Frame, snapshots: Sequence[TrackSnapshot]) -> TeamState:
        n = len(frame.detections)
        best: dict[int, TrackSnapshot] = {}
        for s in snapshots:
            j = s.agent_id
            if j is None or not 0 <= j < self.config.n_robots or s.position is None:
                continue
            if j not in best or _rank(s) > _rank(best[j]):
                best[j] = s
        robots = []
        for j in sorted(best):
            s = best[j]
            if s.detection_index >= 0 or math.isnan(self._last_update[j]):
                self._last_update[j] = frame.time
            pos = np.asarray(s.position, dtype=float)
            if not np.isfinite(pos).all():
                continue
            robots.append(RobotEstimate(
                id=int(j), position=(float(pos[0]), float(pos[1])),
                heading=_finite_or_none(s.heading), confidence=_finite_or_none(s.identity_prob),
                age=float(frame.time - self._last_update[j]),
            ))
        labels = labels_from_tracks(n, snapshots)
        return TeamState(frame=frame.index, time=frame.time, robots=tuple(robots),
                         labels=tuple(int(v) for v in labels))


def _rank(s: TrackSnapshot) -> tuple[bool, float]:
    return s.detection_index >= 0, s.identity_prob if s.identity_prob is not None else 0.0


def _finite_or_none(value: float | None) -> float | None:
    return None if value is None or not math.isfinite(value) else float(value)
