"""How the node's messages map onto ROS 2 messages, without any ROS or DDS package: topic names, type names, the
identity message's definition, and the conversions of stamps and yaw angles. The transports that use them are
:mod:`lookalike.node.dds` (live topics) and :mod:`lookalike.io.rosbag` (rosbag2 files).

Frames: positions are metres in the observer frame (``frame_id`` ``"observer"`` by default), yaw in radians about
its z axis; stamps are the simulated or camera seconds of the node's messages."""

from __future__ import annotations

import math
from dataclasses import dataclass

HEADING_TOPIC = "/robot_{id}/imu"  # sensor_msgs/Imu per robot (``{id}``: the robot id, 0-based)
DETECTIONS_TOPIC = "/lookalike/detections"  # vision_msgs/Detection2DArray
POSES_TOPIC = "/lookalike/poses"  # geometry_msgs/PoseArray
IDENTITY_TOPIC = "/lookalike/identity"  # lookalike_msgs/TeamIdentity
FRAME_ID = "observer"

IMU = "sensor_msgs/msg/Imu"
DETECTION_ARRAY = "vision_msgs/msg/Detection2DArray"
POSE_ARRAY = "geometry_msgs/msg/PoseArray"
TEAM_IDENTITY = "lookalike_msgs/msg/TeamIdentity"

TEAM_IDENTITY_MSG = """\
# Identified robots after one camera frame (lookalike's observer node).
std_msgs/Header header        # stamp: the camera frame's time; frame_id: the observer frame
uint64 frame                  # the node's count of the camera frames it accepted, from 0
int32[] ids                   # robot id (0-based) of each pose
geometry_msgs/Pose[] poses    # position in metres (z = 0); orientation: yaw about z (identity when unknown)
float64[] confidence          # identification confidence in [0, 1] per pose (NaN: unknown)
float64[] age                 # seconds since a detection last updated each pose
int32[] labels                # per detection of the frame, the robot id it was identified as (-1: none)
"""
"""The ROS 2 interface definition (``lookalike_msgs/msg/TeamIdentity.msg``) of the identity message."""

VISION_MSGS = {
    "vision_msgs/msg/Point2D": "float64 x\nfloat64 y\n",
    "vision_msgs/msg/Pose2D": "vision_msgs/Point2D position\nfloat64 theta\n",
    "vision_msgs/msg/BoundingBox2D": "vision_msgs/Pose2D center\nfloat64 size_x\nfloat64 size_y\n",
    "vision_msgs/msg/ObjectHypothesis": "string class_id\nfloat64 score\n",
    "vision_msgs/msg/ObjectHypothesisWithPose": "vision_msgs/ObjectHypothesis hypothesis\n"
                                                "geometry_msgs/PoseWithCovariance pose\n",
    "vision_msgs/msg/Detection2D": "std_msgs/Header header\nvision_msgs/ObjectHypothesisWithPose[] results\n"
                                   "vision_msgs/BoundingBox2D bbox\nstring id\n",
    "vision_msgs/msg/Detection2DArray": "std_msgs/Header header\nvision_msgs/Detection2D[] detections\n",
}
"""The vision_msgs 4 (ROS 2 Humble and later) definitions lookalike uses, dependencies first."""


def dds_topic(ros_topic: str) -> str:
    """The DDS topic of a ROS 2 topic as ROS 2's DDS middlewares name it (``/a/b`` → ``rt/a/b``)."""
    if not ros_topic.startswith("/"):
        ros_topic = "/" + ros_topic
    return "rt" + ros_topic


def dds_type(ros_type: str) -> str:
    """The DDS type name of a ROS 2 message type (``pkg/msg/Name`` → ``pkg::msg::dds_::Name_``)."""
    package, kind, name = ros_type.split("/")
    return f"{package}::{kind}::dds_::{name}_"


def heading_topic(template: str, robot: int) -> str:
    """Robot ``robot``'s heading topic from a template with ``{id}``."""
    return template.format(id=robot)


def stamp(seconds: float) -> tuple[int, int]:
    """``builtin_interfaces/Time`` ``(sec, nanosec)`` of ``seconds`` (rounded to the nanosecond)."""
    total = round(seconds * 1e9)
    sec, nanosec = divmod(total, 1_000_000_000)
    return int(sec), int(nanosec)


def seconds(sec: int, nanosec: int) -> float:
    """Seconds of a ``builtin_interfaces/Time``."""
    return sec + nanosec * 1e-9


def stamp_ns(sec: int, nanosec: int) -> int:
    """A ``builtin_interfaces/Time`` as integer nanoseconds (the sequence number of a heading report)."""
    return sec * 1_000_000_000 + nanosec


def quaternion(yaw: float) -> tuple[float, float, float, float]:
    """``(x, y, z, w)`` of a rotation by ``yaw`` radians about z."""
    return 0.0, 0.0, math.sin(yaw / 2.0), math.cos(yaw / 2.0)


def yaw(x: float, y: float, z: float, w: float) -> float:
    """The yaw (radians, about z, in (-pi, pi]) of the quaternion ``(x, y, z, w)``; NaN when it is not finite or
    zero."""
    if not all(map(math.isfinite, (x, y, z, w))) or x * x + y * y + z * z + w * w == 0.0:
        return math.nan
    return math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))


@dataclass(frozen=True)
class Topics:
    """The ROS 2 topics of one node (ROS names; :func:`dds_topic` gives the DDS names).

    Attributes:
        heading: per-robot ``sensor_msgs/Imu`` topic template, ``{id}`` the robot id.
        detections: the camera's ``vision_msgs/Detection2DArray``.
        poses: identified positions out, ``geometry_msgs/PoseArray``.
        identity: identified robots out, ``lookalike_msgs/TeamIdentity``.
        frame_id: the observer frame named in the published headers."""

    heading: str = HEADING_TOPIC
    detections: str = DETECTIONS_TOPIC
    poses: str = POSES_TOPIC
    identity: str = IDENTITY_TOPIC
    frame_id: str = FRAME_ID

    def __post_init__(self) -> None:
        if "{id}" not in self.heading:
            raise ValueError(f"heading topic {self.heading!r} must contain {{id}} (the robot id)")
