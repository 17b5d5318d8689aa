"""The observer node over DDS with ROS 2's topic and type names (the ``ros`` extra; no ROS installation): headings
in as ``sensor_msgs/Imu`` per robot, the camera's detections as ``vision_msgs/Detection2DArray``, identified
positions out as ``geometry_msgs/PoseArray`` and ``lookalike_msgs/TeamIdentity``. :class:`DdsPeer` is the other
side (robots and camera) in Python. The mapping is :mod:`lookalike.io.rosmap`.

Quality of service: the node reads best-effort (it matches both reliable and best-effort publishers, as ROS 2's
sensor-data profile is) and writes reliable, both volatile, keep-last ``depth``; samples are plain CDR (XCDR1), as
ROS 2's middlewares send them."""

from __future__ import annotations

import logging
import math
import time
from dataclasses import dataclass, field
from typing import Any

from lookalike._optional import needs
from lookalike.io.rosmap import Topics, dds_topic, heading_topic, quaternion, seconds, stamp, stamp_ns, yaw
from lookalike.node.counters import log_event
from lookalike.node.identifier import IdentifierConfig
from lookalike.node.messages import (
    INVALID,
    MAX_DETECTIONS,
    DetectionsMessage,
    HeadingReport,
    RobotEstimate,
    TeamState,
)
from lookalike.node.server import NodeConfig, NodeCore, _preload

MAX_DOMAIN_ID = 232  # DDS domain ids 0 .. 232 (ROS_DOMAIN_ID)


@dataclass(frozen=True)
class DdsConfig:
    """DDS settings of the node or a peer.

    Attributes:
        domain_id: the DDS domain (ROS 2's ``ROS_DOMAIN_ID``), 0 .. 232.
        topics: the ROS 2 topic names and the published frame id.
        depth: keep-last history depth of every reader and writer (samples)."""

    domain_id: int = 0
    topics: Topics = field(default_factory=Topics)
    depth: int = 64

    def __post_init__(self) -> None:
        if not 0 <= self.domain_id <= MAX_DOMAIN_ID:
            raise ValueError(f"DDS domain id (--domain-id) must be in 0 .. {MAX_DOMAIN_ID}, got {self.domain_id}")
        if self.depth < 1:
            raise ValueError(f"depth must be >= 1, got {self.depth}")


class _Dds:
    """The cyclonedds names this module uses, imported once on first use (the ``ros`` extra)."""

    def __init__(self) -> None:
        with needs("cyclonedds"):
            from cyclonedds.core import InstanceState, Policy, Qos, ReadCondition, SampleState, ViewState, WaitSet
            from cyclonedds.domain import DomainParticipant
            from cyclonedds.pub import DataWriter
            from cyclonedds.sub import DataReader
            from cyclonedds.topic import Topic

            from lookalike.node import ros_types
        self.types = ros_types
        self.DomainParticipant, self.Topic, self.DataReader, self.DataWriter = (
            DomainParticipant, Topic, DataReader, DataWriter)
        self.WaitSet, self.ReadCondition = WaitSet, ReadCondition
        self.any_state = SampleState.Any | ViewState.Any | InstanceState.Any
        self.Qos, self.Policy = Qos, Policy

    def qos(self, reliable: bool, depth: int) -> Any:
        p = self.Policy
        return self.Qos(p.Reliability.Reliable(max_blocking_time=100_000_000) if reliable else p.Reliability.BestEffort,
                        p.Durability.Volatile, p.History.KeepLast(depth),
                        p.DataRepresentation(use_cdrv0_representation=True))


_dds: _Dds | None = None


def _load() -> _Dds:
    global _dds
    if _dds is None:
        _dds = _Dds()
    return _dds


class _Endpoints:
    """A participant with readers and writers on the node's topics; ``wait`` then ``take`` merges the readers'
    samples in source-time order."""

    def __init__(self, config: DdsConfig, participant: Any = None) -> None:
        self.dds = _load()
        self.config = config
        self.participant = participant if participant is not None else self.dds.DomainParticipant(config.domain_id)
        self._topics: dict[str, Any] = {}
        self._readers: list[tuple[Any, Any]] = []  # (reader, what it reads)
        self.waitset = self.dds.WaitSet(self.participant)

    def topic(self, ros_topic: str, kind: type) -> Any:
        name = dds_topic(ros_topic)
        if name not in self._topics:
            self._topics[name] = self.dds.Topic(self.participant, name, kind)
        return self._topics[name]

    def reader(self, ros_topic: str, kind: type, tag: Any, reliable: bool = False) -> None:
        reader = self.dds.DataReader(self.participant, self.topic(ros_topic, kind),
                                     qos=self.dds.qos(reliable, self.config.depth))
        self._readers.append((reader, tag))
        self.waitset.attach(self.dds.ReadCondition(reader, self.dds.any_state))

    def writer(self, ros_topic: str, kind: type) -> Any:
        return self.dds.DataWriter(self.participant, self.topic(ros_topic, kind),
                                   qos=self.dds.qos(True, self.config.depth))

    def take(self, timeout_s: float) -> list[tuple[int, Any, Any, Any]]:
        """Samples received within ``timeout_s`` as ``(source time ns, tag, sender, sample)``, oldest first."""
        if not self.waitset.wait(max(0, int(timeout_s * 1e9))):
            return []
        out = []
        for reader, tag in self._readers:
            for sample in reader.take(N=self.config.depth):
                info = sample.sample_info
                if info.valid_data:
                    out.append((info.source_timestamp, tag, info.publication_handle, sample))
        out.sort(key=lambda item: item[0])
        return out


class DdsNode(NodeCore):
    """The observer node on DDS. Use as a context manager; ``serve(stop)`` loops until ``stop()`` is true.
    A detection array is frame ``k`` when it is the ``k``-th one received (from 0); a heading report's sequence
    number is its stamp in nanoseconds, so a repeated stamp is ``duplicate`` and an older one ``late``."""

    def __init__(self, tracker: object, dds_config: DdsConfig | None = None, config: NodeConfig | None = None,
                 identifier_config: IdentifierConfig | None = None, logger: logging.Logger | None = None) -> None:
        super().__init__(tracker, config, identifier_config, logger)
        self.dds_config = dds_config or DdsConfig()
        topics = self.dds_config.topics
        self.endpoints = ends = _Endpoints(self.dds_config)
        types = ends.dds.types
        for j in range(self.identifier.config.n_robots):
            ends.reader(heading_topic(topics.heading, j), types.Imu, j)
        ends.reader(topics.detections, types.Detection2DArray, "detections")
        self._poses = ends.writer(topics.poses, types.PoseArray)
        self._identity = ends.writer(topics.identity, types.TeamIdentity)
        self._frames_received = 0
        _preload()
        log_event(self.log, "listening", transport="dds", domain_id=self.dds_config.domain_id,
                  headings=heading_topic(topics.heading, 0), detections=topics.detections, poses=topics.poses,
                  identity=topics.identity)

    def poll(self, timeout_s: float) -> int:
        """Wait up to ``timeout_s`` for samples, handle them in source-time order; return how many."""
        handled = 0
        for _, tag, sender, sample in self.endpoints.take(timeout_s):
            handled += 1
            t_received = time.perf_counter()
            self._cpu_received = time.thread_time()
            if not self.accept(sender, t_received):
                continue
            try:
                message = self._report(tag, sample) if tag != "detections" else self._detections(sample)
            except ValueError as exc:
                self.counters.reject(INVALID)
                log_event(self.log, "rejected", logging.DEBUG, sender=str(sender), reason=INVALID, detail=str(exc))
                continue
            try:
                self.handle_message(message, sender, t_received)
            except Exception as exc:  # noqa: BLE001 (a bug of the node must not stop the loop)
                self.counters.add("handler_errors")
                log_event(self.log, "handler_error", logging.ERROR, sender=str(sender), error=repr(exc))
        self._timers()
        return handled

    @staticmethod
    def _report(robot: int, imu: Any) -> HeadingReport:
        s = imu.header.stamp
        q = imu.orientation
        heading = yaw(q.x, q.y, q.z, q.w)
        if not math.isfinite(heading):
            raise ValueError(f"robot {robot}: orientation is not a finite non-zero quaternion")
        return HeadingReport(robot=robot, seq=max(0, stamp_ns(s.sec, s.nanosec)),
                             t_sent=seconds(s.sec, s.nanosec), heading=heading)

    def _detections(self, array: Any) -> DetectionsMessage:
        frame = self._frames_received
        self._frames_received += 1
        if len(array.detections) > MAX_DETECTIONS:
            raise ValueError(f"{len(array.detections)} detections, at most {MAX_DETECTIONS}")
        return detections_message(frame, array)

    def _publish(self, team: TeamState) -> None:
        types = self.endpoints.dds.types
        header = types.Header(stamp=types.Time(*stamp(team.time)), frame_id=self.dds_config.topics.frame_id)
        poses = [_pose(types, r) for r in team.robots]
        nan = math.nan
        identity = types.TeamIdentity(
            header=header, frame=team.frame, ids=[r.id for r in team.robots], poses=poses,
            confidence=[nan if r.confidence is None else r.confidence for r in team.robots],
            age=[r.age for r in team.robots], labels=list(team.labels))
        for writer, sample in ((self._poses, types.PoseArray(header=header, poses=poses)), (self._identity, identity)):
            try:
                writer.write(sample)
                self.counters.add("published")
            except Exception as exc:  # noqa: BLE001 (a failed write is counted; the node goes on)
                self.counters.add("send_errors")
                log_event(self.log, "send_error", logging.WARNING, error=repr(exc))


def _pose(types: Any, robot: RobotEstimate) -> Any:
    x, y, z, w = quaternion(robot.heading) if robot.heading is not None else (0.0, 0.0, 0.0, 1.0)
    return types.Pose(position=types.Point(robot.position[0], robot.position[1], 0.0),
                      orientation=types.Quaternion(x, y, z, w))


def detections_message(frame: int, array: Any) -> DetectionsMessage:
    """A ``vision_msgs/Detection2DArray`` (any object with its fields) as frame ``frame``: each detection's
    ``results[0].pose.pose`` gives the observer-frame position (m) and visual heading (yaw, rad),
    ``results[0].hypothesis.score`` the score, and ``sqrt(covariance[35])`` the heading spread (rad; used when
    every detection has one > 0). Raises ``ValueError`` for a detection without a result or a non-finite value."""
    position, heading, score, spread = [], [], [], []
    for i, det in enumerate(array.detections):
        if not det.results:
            raise ValueError(f"detection {i} has no result (its pose is the position)")
        result = det.results[0]
        pose = result.pose.pose
        q = pose.orientation
        values = (pose.position.x, pose.position.y, yaw(q.x, q.y, q.z, q.w), result.hypothesis.score,
                  result.pose.covariance[35])
        if not all(map(math.isfinite, values)):
            raise ValueError(f"detection {i}: a position, yaw, score or covariance that is not finite")
        position.append((float(values[0]), float(values[1])))
        heading.append(float(values[2]))
        score.append(float(values[3]))
        spread.append(math.sqrt(values[4]) if values[4] > 0 else 0.0)
    s = array.header.stamp
    std = tuple(spread) if spread and min(spread) > 0 else None
    return DetectionsMessage(frame=frame, time=seconds(s.sec, s.nanosec), position=tuple(position),
                             heading=tuple(heading), score=tuple(score), heading_std=std)


class DdsPeer:
    """The robots' and camera's side in Python: ``send`` a :class:`HeadingReport` (robot ``r``'s ``sensor_msgs/Imu``)
    or a :class:`DetectionsMessage` (a ``vision_msgs/Detection2DArray``); ``receive`` the next team state (from
    ``lookalike_msgs/TeamIdentity``). Same ``send``/``receive`` as :class:`lookalike.node.Endpoint`, so the
    simulated robots and camera of :mod:`lookalike.node.teamsim` run over it unchanged."""

    def __init__(self, n_robots: int, config: DdsConfig | None = None) -> None:
        self.config = config or DdsConfig()
        topics = self.config.topics
        self.endpoints = ends = _Endpoints(self.config)
        self.types = types = ends.dds.types
        self._imu = [ends.writer(heading_topic(topics.heading, j), types.Imu) for j in range(n_robots)]
        self._detections = ends.writer(topics.detections, types.Detection2DArray)
        ends.reader(topics.identity, types.TeamIdentity, "identity", reliable=True)
        self._pending: list[TeamState] = []

    def matched(self) -> bool:
        """Whether the node's readers and writer are matched (discovery done)."""
        writers = [*self._imu, self._detections]
        readers = [reader for reader, _ in self.endpoints._readers]
        return (all(w.get_matched_subscriptions() for w in writers)
                and all(r.get_matched_publications() for r in readers))

    def wait_matched(self, timeout_s: float = 10.0) -> bool:
        """Wait until :meth:`matched` (True) or ``timeout_s`` wall seconds passed (False)."""
        deadline = time.monotonic() + timeout_s
        while not self.matched():
            if time.monotonic() > deadline:
                return False
            time.sleep(0.01)
        return True

    def send(self, message: HeadingReport | DetectionsMessage) -> None:
        """Publish a robot's heading or a camera frame; a robot outside ``0 .. n_robots-1`` raises ``ValueError``."""
        types = self.types
        if isinstance(message, HeadingReport):
            if not 0 <= message.robot < len(self._imu):  # (robot -1 would be the last robot's topic)
                raise ValueError(f"robot {message.robot}: this peer publishes robots 0 .. {len(self._imu) - 1}")
            x, y, z, w = quaternion(message.heading)
            self._imu[message.robot].write(types.Imu(
                header=types.Header(stamp=types.Time(*stamp(message.t_sent)), frame_id=f"robot_{message.robot}"),
                orientation=types.Quaternion(x, y, z, w)))
            return
        header = types.Header(stamp=types.Time(*stamp(message.time)), frame_id=self.config.topics.frame_id)
        spread = message.heading_std or (0.0,) * len(message.position)
        detections = []
        for (px, py), h, s, sd in zip(message.position, message.heading, message.score, spread):
            x, y, z, w = quaternion(h)
            covariance = [0.0] * 36
            covariance[35] = sd * sd
            pose = types.PoseWithCovariance(pose=types.Pose(types.Point(px, py, 0.0), types.Quaternion(x, y, z, w)),
                                            covariance=covariance)
            detections.append(types.Detection2D(header=header, results=[types.ObjectHypothesisWithPose(
                hypothesis=types.ObjectHypothesis(class_id="robot", score=s), pose=pose)]))
        self._detections.write(types.Detection2DArray(header=header, detections=detections))

    def receive(self, timeout_s: float) -> TeamState | None:
        """The next team state received within ``timeout_s`` wall seconds, else None."""
        deadline = time.monotonic() + timeout_s
        while not self._pending:
            for _, _, _, sample in self.endpoints.take(max(0.0, deadline - time.monotonic())):
                self._pending.append(team_state(sample))
            if self._pending or time.monotonic() >= deadline:
                break
        return self._pending.pop(0) if self._pending else None


def team_state(identity: Any) -> TeamState:
    """A ``lookalike_msgs/TeamIdentity`` as the node's :class:`TeamState`."""
    robots = []
    for j, pose, c, age in zip(identity.ids, identity.poses, identity.confidence, identity.age):
        q = pose.orientation
        h = yaw(q.x, q.y, q.z, q.w) if (q.x, q.y, q.z, q.w) != (0.0, 0.0, 0.0, 1.0) else math.nan
        robots.append(RobotEstimate(id=int(j), position=(float(pose.position.x), float(pose.position.y)),
                                    heading=h if math.isfinite(h) else None,
                                    confidence=float(c) if math.isfinite(c) else None, age=float(age)))
    s = identity.header.stamp
    return TeamState(frame=int(identity.frame), time=seconds(s.sec, s.nanosec), robots=tuple(robots),
                     labels=tuple(int(v) for v in identity.labels))


__all__ = ["DdsConfig", "DdsNode", "DdsPeer", "detections_message", "team_state"]
