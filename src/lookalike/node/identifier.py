"""Socket-free core of the node: checks reports and frames, runs the tracker, builds team states. Times are the
messages' simulated times; a report reaches the tracker with the next frame, stamped with that frame's time."""

from __future__ import annotations

import math
from collections import deque
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, TypeVar

import numpy as np

from lookalike.node.messages import (
    MAX_ROBOTS,
    DetectionsMessage,
    HeadingReport,
    RobotEstimate,
    TeamState,
    check_bounds,
    numbers_of,
)
from lookalike.trackers.kernels.world import filled
from lookalike.trackers.parts.identity.labels import label_list
from lookalike.types import Beacons, Detections, Frame, Tracks, TrackSnapshot

_T = TypeVar("_T")


@dataclass(frozen=True)
class IdentifierConfig:
    """Message acceptance rules.

    Attributes:
        n_robots: robots in the team; ids ``0 .. n_robots-1`` are accepted.
        max_report_age_s: a report sent more than this before the latest frame is late (seconds).
        max_queued_per_robot: reports of one robot kept for the next frame (beyond: oldest dropped).
        max_queued: reports of all robots kept for the next frame (beyond: new ones dropped).
        max_frame_jump_s: a frame more than this after the last one (seconds) is ``time_ahead`` while the camera is
            alive.
        max_report_ahead_s: a report sent more than this after the last frame (seconds) is ``time_ahead``; a robot
            whose last report is that far ahead of a new frame is forgotten (``robot_resets``)."""

    n_robots: int = 3
    max_report_age_s: float = 1.0
    max_queued_per_robot: int = 64
    max_queued: int = 4096
    max_frame_jump_s: float = 10.0
    max_report_ahead_s: float = 1.0

    def __post_init__(self) -> None:
        if not 1 <= self.n_robots <= MAX_ROBOTS:
            raise ValueError(f"IdentifierConfig.n_robots (--robots) must be in 1 .. {MAX_ROBOTS}, got {self.n_robots}")
        for name in ("max_report_age_s", "max_frame_jump_s", "max_report_ahead_s"):
            if not (getattr(self, name) > 0 and math.isfinite(getattr(self, name))):
                option = " (--max-report-age)" if name == "max_report_age_s" else ""
                raise ValueError(f"IdentifierConfig.{name}{option} must be a finite number > 0, got "
                                 f"{getattr(self, name)}")
        if self.max_queued_per_robot < 1 or self.max_queued < 1:
            raise ValueError(f"max_queued_per_robot and max_queued must be >= 1, got "
                             f"{self.max_queued_per_robot} and {self.max_queued}")


class TeamIdentifier:
    """Accepts heading reports and detection frames in arrival order and identifies the team; ``add_report`` and
    ``add_frame`` return the counter the message falls under (``"reports"``/``"frames"`` when accepted), and raise
    ``MessageError`` (reason ``invalid``, nothing changed) for a message outside the wire's bounds."""

    def __init__(self, tracker: Any, config: IdentifierConfig | None = None) -> None:
        self.tracker, self.config = tracker, config or IdentifierConfig()
        n = self.config.n_robots
        self._last_seq = np.full(n, -1)
        self._last_sent = np.full(n, -math.inf)
        self._pending: list[deque[tuple[int, HeadingReport]]] = [deque() for _ in range(n)]
        self._queued = 0  # reports in all the queues
        # the queued reports as columns in arrival order (robot, send time, heading), made as they arrive;
        # ``_columns_plain``: every one a finite report of a robot >= 0; ``_columns_whole``: no report dropped
        self._columns: tuple[list[int], list[float], list[float]] = ([], [], [])
        self._columns_plain = self._columns_whole = True
        self._arrival = 0  # arrival number of the next report (keeps the frame's reports in arrival order)
        self.queue_dropped = 0
        self._last_update = [math.nan] * n  # frame time a detection last updated each robot
        self.last_frame: int | None = None
        self.last_time = -math.inf
        self.camera_lost = False
        self.restarts = 0
        self.robot_resets = 0  # robots whose sequence and clock were forgotten (ahead of a new frame)

    def add_report(self, report: HeadingReport) -> str:
        """Queue ``report`` for the next frame, or say why it is dropped."""
        check_bounds(report)
        j = report.robot
        if j >= self.config.n_robots:
            return "unknown_robot"
        if (self.last_frame is not None and not self.camera_lost
                and report.t_sent > self.last_time + self.config.max_report_ahead_s):
            return "time_ahead"  # (judged against the camera's clock: never taken as the robot's "now")
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
        queue = self._pending[j]
        if len(queue) >= self.config.max_queued_per_robot:
            queue.popleft()
            self._queued -= 1
            self.queue_dropped += 1
            self._columns_whole = False
        elif self._queued >= self.config.max_queued:
            return "queue_full"
        self._last_seq[j], self._last_sent[j] = report.seq, report.t_sent
        queue.append((self._arrival, report))
        self._arrival += 1
        self._queued += 1
        robots, sent, heading = self._columns
        robots.append(j)
        sent.append(report.t_sent)
        heading.append(report.heading)
        if not _plain_report(report):
            self._columns_plain = False
        return "reports"

    @property
    def queued(self) -> int:
        """Reports waiting for the next frame."""
        return self._queued

    def _take_reports(self) -> list[HeadingReport]:
        """Empty the queues; the reports in arrival order."""
        if self._queued == 0:
            self._clear_reports()
            return []
        items = [item for queue in self._pending if queue for item in queue]
        self._clear_reports()
        if len(items) > 1:
            items.sort(key=_first)
        return [report for _, report in items]

    def _clear_reports(self) -> None:
        """Empty the queues and their columns."""
        self._columns = ([], [], [])
        self._columns_plain = self._columns_whole = True
        if self._queued:
            for queue in self._pending:
                queue.clear()
            self._queued = 0

    def add_frame(self, message: DetectionsMessage) -> tuple[str, TeamState | None]:
        """Track one camera frame with the reports queued since the previous one."""
        if numbers_of(message) is None:  # (``decode`` checked the others)
            check_bounds(message)
        if self.last_frame is not None:
            if message.frame == self.last_frame or message.time == self.last_time:
                return "duplicate", None
            if message.time < self.last_time:
                if not self.camera_lost:
                    return "frame_backwards", None
                self.restart()
            elif message.time - self.last_time > self.config.max_frame_jump_s and not self.camera_lost:
                return "time_ahead", None
        self.camera_lost = False
        self._forget_robots_ahead_of(message.time)
        frame = self._frame(message)
        snapshots = self.tracker.update(frame)
        self.last_frame, self.last_time = message.frame, message.time
        return "frames", self._team_state(frame, snapshots)

    def _forget_robots_ahead_of(self, time: float) -> None:
        """Forget robots whose last report is more than ``max_report_ahead_s`` after the frame ``time``."""
        ahead = self._last_sent > time + self.config.max_report_ahead_s
        if ahead.any():
            self._last_sent[ahead] = -math.inf
            self._last_seq[ahead] = -1
            self.robot_resets += int(ahead.sum())

    def prepare(self) -> None:
        """Between frames: call the tracker's ``prepare()``, when it has one."""
        prepare = getattr(self.tracker, "prepare", None)
        if prepare is not None:
            prepare()

    def restart(self) -> None:
        """The camera came back with an earlier time: reset the tracker and the frame clock."""
        self.tracker.reset()
        self.restarts += 1
        self._take_reports()
        self._last_update = [math.nan] * self.config.n_robots
        self._last_sent[:] = -math.inf
        self._last_seq[:] = -1
        self.last_frame, self.last_time = None, -math.inf

    def _frame(self, message: DetectionsMessage) -> Frame:
        """The tracker's frame: the message's detections and the queued reports."""
        n = len(message.position)
        spread = message.heading_std
        decoded = numbers_of(message)
        if decoded is not None:  # (decode's checks made: one array, the columns its views)
            values = np.array(decoded)
            position, heading, score = values[:2 * n].reshape(n, 2), values[2 * n:3 * n], values[3 * n:4 * n]
            std = None if spread is None else values[4 * n:5 * n]
            checked = True
        else:
            position = np.array(message.position, dtype=float).reshape(n, 2)
            heading = np.array(message.heading, dtype=float)
            score = np.array(message.score, dtype=float)
            std = None if spread is None else np.array(spread, dtype=float)
            try:  # (finite numbers sum to a finite total, barring overflow; anything else is checked below)
                total: float = sum(message.heading) + sum(message.score) + sum(map(sum, message.position))
                if spread is not None and std is not None:
                    total += sum(spread) if std.shape == (n,) and (not n or std.min() >= 0) else math.nan
            except TypeError:
                total = math.nan
            checked = heading.shape == score.shape == (n,) and math.isfinite(total)
        if checked:
            detections = _trusted(Detections, xywh=np.zeros((n, 4)), score=score, position=position,
                                  heading=heading, heading_std=std, feature=None, label=None)
        else:
            detections = Detections(position=position, heading=heading, score=score, heading_std=std)
        (robots, sent, headings), plain = self._columns, self._columns_plain
        if not self._columns_whole:  # (a report was dropped from a full queue: the columns of those left)
            reports = self._take_reports()
            robots, sent = [r.robot for r in reports], [r.t_sent for r in reports]
            headings = [r.heading for r in reports]
            plain = all(map(_plain_report, reports))
        else:
            self._clear_reports()
        if not robots:
            beacons = Beacons.empty()
        else:
            agent_id = np.array(robots, dtype=int)
            t_sent = np.array(sent, dtype=float)
            heading = np.array(headings, dtype=float)
            t_received = filled(len(robots), float(message.time))
            if plain:  # (checked as the reports arrived)
                beacons = _trusted(Beacons, agent_id=agent_id, t_sent=t_sent, t_received=t_received, heading=heading)
            else:
                beacons = Beacons(agent_id=agent_id, t_sent=t_sent, t_received=t_received, heading=heading)
        if isinstance(message.frame, int) and message.frame >= 0 and math.isfinite(message.time):
            return _trusted(Frame, index=message.frame, time=message.time, detections=detections, beacons=beacons,
                            image=None)
        return Frame(index=message.frame, time=message.time, detections=detections, beacons=beacons)

    def _team_state(self, frame: Frame, snapshots: Sequence[TrackSnapshot]) -> TeamState:
        n = len(frame.detections)
        best: dict[int, _Row] = {}
        for row in _rows(snapshots, self.config.n_robots):
            j = row[0]
            if j not in best or _rank(row) > _rank(best[j]):
                best[j] = row
        robots = []
        last_update, time = self._last_update, float(frame.time)
        for j in sorted(best):
            _, det_index, prob, x, y, heading = best[j]
            if det_index >= 0 or math.isnan(last_update[j]):
                last_update[j] = time
            if not (math.isfinite(x) and math.isfinite(y)):
                continue
            robot = object.__new__(RobotEstimate)  # (RobotEstimate checks nothing: its fields set directly)
            robot.__dict__.update(id=int(j), position=(x, y), heading=_finite_or_none(heading),
                                  confidence=_finite_or_none(prob), age=time - last_update[j])
            robots.append(robot)
        labels = label_list(n, snapshots)
        return TeamState(frame=frame.index, time=frame.time, robots=tuple(robots), labels=tuple(labels))


# (agent id, detection index, identity probability, x, y, heading) of an identified track
_Row = tuple[int, int, float | None, float, float, float | None]


def _rows(snapshots: Sequence[TrackSnapshot], n_robots: int) -> list[_Row]:
    """The identified tracks with a position and an agent id in ``0 .. n_robots-1``, in order."""
    if isinstance(snapshots, Tracks):
        t = snapshots
        if t.agent_id is None or t.position is None or not len(t):
            return []
        agent = t.agent_id.tolist()
        rows = [i for i, a in enumerate(agent) if 0 <= a < n_robots]
        if not rows:
            return []
        prob: list[Any] = [None] * len(t) if t.identity_prob is None else t.identity_prob.tolist()
        heading = [None] * len(t) if t.heading is None else t.heading.tolist()
        det, pos = t.detection_index.tolist(), t.position.tolist()
        return [(agent[i], det[i], None if prob[i] is None or math.isnan(prob[i]) else prob[i],
                 float(pos[i][0]), float(pos[i][1]), heading[i]) for i in rows]
    out: list[_Row] = []
    for s in snapshots:
        j = s.agent_id
        if j is None or not 0 <= j < n_robots or s.position is None:
            continue
        pos = np.asarray(s.position, dtype=float)
        out.append((int(j), s.detection_index, s.identity_prob, float(pos[0]), float(pos[1]), s.heading))
    return out


def _trusted(cls: type[_T], **fields: Any) -> _T:
    """An instance of the frozen dataclass ``cls`` with ``fields`` set as given (read-only arrays), unvalidated."""
    obj = object.__new__(cls)
    for value in fields.values():
        if isinstance(value, np.ndarray):
            value.flags.writeable = False
    obj.__dict__.update(fields)  # (the fields a frozen dataclass's __init__ sets, in one call)
    return obj


def _plain_report(report: HeadingReport) -> bool:
    """Whether ``report`` has a robot id >= 0 and finite numbers (as every decoded report has)."""
    try:
        return report.robot >= 0 and math.isfinite(report.t_sent + report.heading)
    except TypeError:
        return False


def _first(item: tuple[int, HeadingReport]) -> int:
    return item[0]


def _rank(row: _Row) -> tuple[bool, float]:
    return row[1] >= 0, row[2] if row[2] is not None else 0.0


def _finite_or_none(value: float | None) -> float | None:
    return None if value is None or not math.isfinite(value) else float(value)
