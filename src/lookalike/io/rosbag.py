"""Robot runs as rosbag2 files (the ``ros`` extra, through ``rosbags``; no ROS installation).

A bag holds, with ROS 2's message types (:mod:`lookalike.io.rosmap` has the topic names):

- ``/robot_{id}/imu`` (``sensor_msgs/Imu``): each robot's heading reports; header stamp = send time, yaw of the
  orientation = heading, the bag's log time = when the observer received it;
- ``/lookalike/detections`` (``vision_msgs/Detection2DArray``): the camera's world-frame detections per frame
  (``results[0].pose.pose``: observer-frame position and visual heading; ``hypothesis.score``);
- ``/camera/image_raw`` (``sensor_msgs/Image``, ``bgr8``): the rendered camera frames, when written;
- ``/observer/pose`` (``geometry_msgs/PoseStamped``, frame ``field``): the observer's x, y (m) and yaw (rad);
- ``/lookalike/truth`` (``geometry_msgs/PoseArray``): every robot's true observer-frame position and heading, in id
  order, and ``/lookalike/truth_record`` (``std_msgs/String``): the frame's truth as in the ``.jsonl`` format.

Stamps and log times are the run's seconds (simulated runs start at 0). A frame's reports are those logged after
the previous frame and up to its own time. Bags written here carry the simulator's configuration in their metadata
(``custom_data``), so reading one gives back the same :class:`~lookalike.sim.RobotSequence` as its ``.jsonl``."""

from __future__ import annotations

import json
import math
from collections.abc import Iterable, Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Literal

import numpy as np

from lookalike._optional import needs
from lookalike.io.robot_sequences import FORMAT, VERSION, _assemble
from lookalike.io.rosmap import (
    DETECTION_ARRAY,
    IMU,
    POSE_ARRAY,
    VISION_MSGS,
    Topics,
    heading_topic,
    quaternion,
    seconds,
    stamp,
    stamp_ns,
    yaw,
)
from lookalike.sim import RobotSequence, RobotWorldConfig

CAMERA_TOPIC = "/camera/image_raw"
OBSERVER_TOPIC = "/observer/pose"
TRUTH_TOPIC = "/lookalike/truth"
TRUTH_RECORD_TOPIC = "/lookalike/truth_record"
IMAGE, POSE_STAMPED, STRING = "sensor_msgs/msg/Image", "geometry_msgs/msg/PoseStamped", "std_msgs/msg/String"
HEADER_KEY = "lookalike.header"  # the bag metadata's custom_data key holding the .jsonl header
BAG_VERSION: Literal[8] = 8  # rosbag2 metadata version written (the lowest rosbags writes)


def _typestore() -> Any:
    with needs("rosbags"):
        from rosbags.typesys import Stores, get_types_from_msg, get_typestore
    store = get_typestore(Stores.ROS2_HUMBLE)
    for name, text in VISION_MSGS.items():
        store.register(get_types_from_msg(text, name))
    return store


def _ns(t: float) -> int:
    sec, nanosec = stamp(t)
    return sec * 1_000_000_000 + nanosec


def write_bag(path: str | Path, sequence: RobotSequence, images: Iterable[np.ndarray] | None = None,
              topics: Topics | None = None) -> Path:
    """Write ``sequence`` (and its rendered ``images``, BGR ``uint8``, one per frame, when given) as a rosbag2 folder
    at ``path`` (it must not exist); returns the path."""
    with needs("rosbags"):
        from rosbags.rosbag2 import Writer
    topics = topics or Topics()
    store, path = _typestore(), Path(path)
    if path.exists():
        raise ValueError(f"{path} exists: a bag is written into a new folder")
    t = store.types
    a, r = sequence.arrays, sequence.arrays.reports
    n = sequence.config.n_agents
    header = {"format": FORMAT, "version": VERSION, "seed": sequence.seed, "n_frames": len(a),
              "reports_sent": r.n_sent, "config": sequence.config.to_dict()}

    def hdr(time_s: float, frame_id: str) -> Any:
        return t["std_msgs/msg/Header"](stamp=t["builtin_interfaces/msg/Time"](*stamp(time_s)), frame_id=frame_id)

    def pose(x: float, y: float, heading: float) -> Any:
        return t["geometry_msgs/msg/Pose"](position=t["geometry_msgs/msg/Point"](x=x, y=y, z=0.0),
                                          orientation=t["geometry_msgs/msg/Quaternion"](*quaternion(heading)))

    image_iter = iter(images) if images is not None else None
    with Writer(path, version=BAG_VERSION) as writer:
        writer.set_custom_data(HEADER_KEY, json.dumps(header))
        conn = {name: writer.add_connection(topic, kind, typestore=store) for name, topic, kind in (
            ("detections", topics.detections, DETECTION_ARRAY), ("observer", OBSERVER_TOPIC, POSE_STAMPED),
            ("truth", TRUTH_TOPIC, POSE_ARRAY), ("record", TRUTH_RECORD_TOPIC, STRING))}
        imu = [writer.add_connection(heading_topic(topics.heading, j), IMU, typestore=store) for j in range(n)]
        if image_iter is not None:
            conn["camera"] = writer.add_connection(CAMERA_TOPIC, IMAGE, typestore=store)

        def put(name: Any, log_s: float, msg: Any, kind: str) -> None:
            target = conn[name] if isinstance(name, str) else name
            writer.write(target, _ns(log_s), store.serialize_cdr(msg, kind))

        zeros9, zeros36 = np.zeros(9), np.zeros(36)
        for k in range(len(a)):
            time_s = float(a.time[k])
            for i in range(r.frame_offsets[k], r.frame_offsets[k + 1]):
                msg = t[IMU](header=hdr(float(r.t_sent[i]), f"robot_{int(r.agent_id[i])}"),
                             orientation=t["geometry_msgs/msg/Quaternion"](*quaternion(float(r.heading[i]))),
                             orientation_covariance=zeros9, angular_velocity=t["geometry_msgs/msg/Vector3"](0, 0, 0),
                             angular_velocity_covariance=zeros9,
                             linear_acceleration=t["geometry_msgs/msg/Vector3"](0, 0, 0),
                             linear_acceleration_covariance=zeros9)
                put(imu[int(r.agent_id[i])], float(r.t_received[i]), msg, IMU)
            if image_iter is not None:
                image = np.ascontiguousarray(next(image_iter), dtype=np.uint8)
                h, w = image.shape[:2]
                put("camera", time_s, t[IMAGE](header=hdr(time_s, "camera"), height=h, width=w, encoding="bgr8",
                                               is_bigendian=0, step=w * 3, data=image.reshape(-1)), IMAGE)
            count = int(a.det_valid[k].sum())
            detections = []
            for p, h_, s in zip(a.det_position[k, :count], a.det_heading[k, :count], a.det_score[k, :count]):
                covariance = zeros36.copy()
                covariance[35] = float(sequence.config.sensor.heading_std_rad) ** 2
                result = t["vision_msgs/msg/ObjectHypothesisWithPose"](
                    hypothesis=t["vision_msgs/msg/ObjectHypothesis"](class_id="robot", score=float(s)),
                    pose=t["geometry_msgs/msg/PoseWithCovariance"](pose=pose(float(p[0]), float(p[1]), float(h_)),
                                                                    covariance=covariance))
                box = t["vision_msgs/msg/BoundingBox2D"](
                    center=t["vision_msgs/msg/Pose2D"](position=t["vision_msgs/msg/Point2D"](0.0, 0.0), theta=0.0),
                    size_x=0.0, size_y=0.0)
                detections.append(t["vision_msgs/msg/Detection2D"](header=hdr(time_s, topics.frame_id),
                                                                   results=[result], bbox=box, id=""))
            put("detections", time_s, t[DETECTION_ARRAY](header=hdr(time_s, topics.frame_id), detections=detections),
                DETECTION_ARRAY)
            ox, oy, oyaw = (float(v) for v in a.observer[k])
            put("observer", time_s, t[POSE_STAMPED](header=hdr(time_s, "field"), pose=pose(ox, oy, oyaw)),
                POSE_STAMPED)
            put("truth", time_s, t[POSE_ARRAY](header=hdr(time_s, topics.frame_id), poses=[
                pose(float(x), float(y), float(h_)) for (x, y), h_ in zip(a.true_position[k], a.true_heading[k])]),
                POSE_ARRAY)
            record = {"label": a.det_label[k, :count].tolist(), "position": a.true_position[k].tolist(),
                      "heading": a.true_heading[k].tolist(), "visible": a.visible[k].tolist(),
                      "occlusion": a.occlusion[k].tolist(), "field_position": a.field_position[k].tolist(),
                      "observer": a.observer[k].tolist(), "n_false_positives": int(a.n_false_positives[k]),
                      "n_misses": int(a.n_misses[k])}
            put("record", time_s, t[STRING](data=json.dumps(record)), STRING)
    return path


@dataclass(frozen=True)
class BagRun:
    """A bag read back: the run as a sequence (reports, detections, truth where the bag has them) and the camera
    frames' log times (ns), for :func:`bag_images`."""

    sequence: RobotSequence
    camera_topic: str | None
    frame_ns: tuple[int, ...]


@contextmanager
def _reader(path: Path) -> Iterator[Any]:
    """rosbags' reader of the bag at ``path``, open in the block; ``ValueError`` naming ``path`` when it is no
    rosbag2 folder."""
    with needs("rosbags"):
        from rosbags.rosbag2 import Reader, ReaderError
    try:
        reader = Reader(path)
        reader.open()
    except (ReaderError, FileNotFoundError) as exc:
        raise ValueError(f"{path}: not a readable rosbag2 folder ({exc})") from None
    try:
        yield reader
    finally:
        reader.close()


def _check_type(path: Path, reader: Any, topic: str, msgtype: str) -> None:
    """``ValueError`` unless every connection of ``topic`` carries ``msgtype`` messages."""
    found = {c.msgtype for c in reader.connections if c.topic == topic}
    if found - {msgtype}:
        raise ValueError(f"{path}: topic {topic} has {', '.join(sorted(found))} messages; {msgtype} expected")


def bag_topics(path: str | Path) -> dict[str, str]:
    """Topic → ROS 2 message type of every connection of the bag at ``path`` (rosbags' own reader)."""
    with _reader(Path(path)) as reader:
        return {c.topic: c.msgtype for c in reader.connections}


def read_bag(path: str | Path, camera_topic: str | None = None, heading_topics: Sequence[str] | None = None,
             topics: Topics | None = None) -> BagRun:
    """Read a rosbag2 run. Frames: the messages of ``camera_topic`` when given, else of the detections topic.
    ``heading_topics``: robot ``j``'s ``sensor_msgs/Imu`` topic is the ``j``-th (default: the template's topics
    ``/robot_0/imu``, ``/robot_1/imu``, ... present in the bag). Raises ``ValueError`` naming what is missing, a
    topic of another message type, or a path that is no rosbag2 folder."""
    topics, path = topics or Topics(), Path(path)
    store = _typestore()
    with _reader(path) as reader:
        present = {c.topic: c for c in reader.connections}
        if heading_topics is None:
            heading_topics = []
            while heading_topic(topics.heading, len(heading_topics)) in present:
                heading_topics.append(heading_topic(topics.heading, len(heading_topics)))
        frame_topic = camera_topic or topics.detections
        missing = [name for name in (frame_topic, *heading_topics) if name not in present]
        if missing or not heading_topics:
            raise ValueError(f"{path}: no topic {', '.join(missing) or 'of robot headings'}; the bag has "
                             f"{', '.join(sorted(present))}")
        for name in heading_topics:
            _check_type(path, reader, name, IMU)
        if camera_topic is not None:
            _check_type(path, reader, camera_topic, IMAGE)
        robot_of = {name: j for j, name in enumerate(heading_topics)}
        wanted = [present[name] for name in {frame_topic, *heading_topics, topics.detections, OBSERVER_TOPIC,
                                             TRUTH_RECORD_TOPIC} if name in present]
        custom = reader.storage.metadata.custom or {}
        frames: list[tuple[int, int]] = []  # (log time, stamp) of each frame, ns
        reports: list[list[tuple[int, float, float, float]]] = [[]]  # per frame: robot, t_sent, t_received, heading
        by_stamp: dict[str, dict[int, Any]] = {topics.detections: {}, TRUTH_RECORD_TOPIC: {}}
        observer: list[tuple[float, tuple[float, float, float]]] = []
        for connection, log_ns, raw in reader.messages(connections=wanted):
            msg = store.deserialize_cdr(raw, connection.msgtype)
            name = connection.topic
            if name in robot_of:
                q, s = msg.orientation, msg.header.stamp
                reports[-1].append((robot_of[name], seconds(s.sec, s.nanosec), log_ns * 1e-9,
                                    yaw(q.x, q.y, q.z, q.w)))
            if name == OBSERVER_TOPIC:
                q, s = msg.pose.orientation, msg.header.stamp
                observer.append((seconds(s.sec, s.nanosec), (msg.pose.position.x, msg.pose.position.y,
                                                             yaw(q.x, q.y, q.z, q.w))))
            elif name in by_stamp and name != frame_topic:
                by_stamp[name][_stamp_of(msg, log_ns)] = msg
            if name == frame_topic:
                frames.append((log_ns, _stamp_of(msg, log_ns)))
                if name in by_stamp:
                    by_stamp[name][frames[-1][1]] = msg
                reports.append([])
    header = json.loads(custom[HEADER_KEY]) if HEADER_KEY in custom else None
    sequence = _sequence(header, frames, reports[:len(frames)], by_stamp[topics.detections],
                         by_stamp[TRUTH_RECORD_TOPIC], observer, len(heading_topics))
    return BagRun(sequence, camera_topic, tuple(ns for ns, _ in frames))


def _stamp_of(msg: Any, log_ns: int) -> int:
    """A message's header stamp in nanoseconds; its log time for a message without a header."""
    s = getattr(getattr(msg, "header", None), "stamp", None)
    return stamp_ns(s.sec, s.nanosec) if s is not None else log_ns


def _sequence(header: dict[str, Any] | None, frames: list[tuple[int, int]],
              reports: list[list[tuple[int, float, float, float]]], detections: dict[int, Any],
              records: dict[int, Any], observer: list[tuple[float, tuple[float, float, float]]],
              n_robots: int) -> RobotSequence:
    """The frames as ``.jsonl`` rows, assembled as :func:`lookalike.io.read_robot_sequence` does."""
    rows, most = [], 1
    pose_i, pose = 0, (0.0, 0.0, 0.0)
    for k, (_, time_ns) in enumerate(frames):
        time_s = seconds(*divmod(time_ns, 1_000_000_000))
        while pose_i < len(observer) and observer[pose_i][0] <= time_s + 1e-9:
            pose = observer[pose_i][1]
            pose_i += 1
        position, heading, score = [], [], []
        det = detections.get(time_ns)
        for d in det.detections if det is not None else ():
            p = d.results[0].pose.pose
            position.append([p.position.x, p.position.y])
            heading.append(yaw(p.orientation.x, p.orientation.y, p.orientation.z, p.orientation.w))
            score.append(d.results[0].hypothesis.score)
        most = max(most, len(position))
        record = json.loads(records[time_ns].data) if time_ns in records else _no_truth(n_robots, len(position), pose)
        got = reports[k]
        rows.append({"frame": k, "time": time_s,
                     "detections": {"position": position, "heading": heading, "score": score,
                                    "label": record.pop("label")},
                     "beacons": {"agent_id": [g[0] for g in got], "t_sent": [g[1] for g in got],
                                 "t_received": [g[2] for g in got], "heading": [g[3] for g in got]},
                     "truth": record})
    if header is None:
        config = RobotWorldConfig(n_agents=n_robots, max_detections=most)
        header = {"seed": 0, "reports_sent": sum(map(len, reports)), "config": config.to_dict()}
    config = RobotWorldConfig.from_dict(header["config"])
    return _assemble(config, header, rows, len(rows), int(config.n_agents), int(config.max_detections))


def _no_truth(n: int, detections: int, observer: tuple[float, float, float]) -> dict[str, Any]:
    """A frame record for a bag without truth: unknown positions (NaN), every detection unlabelled."""
    nan = [math.nan, math.nan]
    return {"label": [-1] * detections, "position": [nan] * n, "heading": [math.nan] * n, "visible": [False] * n,
            "occlusion": [0.0] * n, "field_position": [nan] * n, "observer": list(observer),
            "n_false_positives": 0, "n_misses": 0}


def read_labelled_bag(path: str | Path) -> RobotSequence:
    """A bag with per-detection labels (its ``/lookalike/truth_record`` topic, as ``simulate --bag`` writes) as a
    sequence, for training; ``ValueError`` naming the bag when it has no labels or cannot be read."""
    if TRUTH_RECORD_TOPIC not in bag_topics(path):
        raise ValueError(f"{path}: no labels (topic {TRUTH_RECORD_TOPIC} of std_msgs/String, the frames' truth "
                         "records as `lookalike simulate --bag` writes them)")
    return read_bag(path).sequence


def bag_images(path: str | Path, camera_topic: str = CAMERA_TOPIC) -> Iterator[np.ndarray]:
    """The ``sensor_msgs/Image`` frames of ``camera_topic`` in log-time order, as BGR ``uint8`` arrays
    (``bgr8``, ``rgb8`` and ``mono8`` images)."""
    store = _typestore()
    with _reader(Path(path)) as reader:
        wanted = [c for c in reader.connections if c.topic == camera_topic]
        if not wanted:
            raise ValueError(f"{path}: no topic {camera_topic}")
        _check_type(Path(path), reader, camera_topic, IMAGE)
        for connection, _, raw in reader.messages(connections=wanted):
            msg = store.deserialize_cdr(raw, connection.msgtype)
            rows = np.asarray(msg.data, dtype=np.uint8).reshape(msg.height, msg.step)
            if msg.encoding == "mono8":
                gray = rows[:, :msg.width]
                yield np.repeat(gray[:, :, None], 3, axis=2)
                continue
            if msg.encoding not in ("bgr8", "rgb8"):
                raise ValueError(f"{path}: {camera_topic} has {msg.encoding} images; bgr8, rgb8 or mono8 expected")
            image = rows[:, :msg.width * 3].reshape(msg.height, msg.width, 3)
            yield image[:, :, ::-1].copy() if msg.encoding == "rgb8" else image


__all__ = ["BagRun", "CAMERA_TOPIC", "OBSERVER_TOPIC", "TRUTH_RECORD_TOPIC", "TRUTH_TOPIC", "bag_images",
           "bag_topics", "read_bag", "read_labelled_bag", "write_bag"]
