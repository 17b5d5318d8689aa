"""The ROS 2 messages the DDS transport speaks, as Cyclone DDS IDL structs with ROS 2's DDS type names and field
layout (ROS 2 Humble and later; vision_msgs 4), so a ROS 2 node's middleware reads and writes the same bytes.
Importing this module needs the ``ros`` extra."""

# mypy: disable-error-code="assignment,type-arg,valid-type"
# (cyclonedds' IDL annotations, sequence[T] and array[T, n], are markers mypy cannot read as types)
# (no ``from __future__ import annotations``: the IDL layer reads the field types at class creation)

from dataclasses import dataclass, field

from lookalike._optional import needs

with needs("cyclonedds"):
    import cyclonedds.idl.annotations as annotate
    from cyclonedds.idl import IdlStruct
    from cyclonedds.idl.types import array, float64, int32, sequence, uint32, uint64

from lookalike.io.rosmap import TEAM_IDENTITY, dds_type


def _zeros(n: int) -> "list[float]":
    return [0.0] * n


@dataclass
@annotate.final
class Time(IdlStruct, typename=dds_type("builtin_interfaces/msg/Time")):
    """``builtin_interfaces/Time``: seconds and nanoseconds."""

    sec: int32 = 0
    nanosec: uint32 = 0


@dataclass
@annotate.final
class Header(IdlStruct, typename=dds_type("std_msgs/msg/Header")):
    """``std_msgs/Header``: a stamp and the frame the data is in."""

    stamp: Time = field(default_factory=Time)
    frame_id: str = ""


@dataclass
@annotate.final
class Point(IdlStruct, typename=dds_type("geometry_msgs/msg/Point")):
    x: float64 = 0.0
    y: float64 = 0.0
    z: float64 = 0.0


@dataclass
@annotate.final
class Vector3(IdlStruct, typename=dds_type("geometry_msgs/msg/Vector3")):
    x: float64 = 0.0
    y: float64 = 0.0
    z: float64 = 0.0


@dataclass
@annotate.final
class Quaternion(IdlStruct, typename=dds_type("geometry_msgs/msg/Quaternion")):
    x: float64 = 0.0
    y: float64 = 0.0
    z: float64 = 0.0
    w: float64 = 1.0


@dataclass
@annotate.final
class Pose(IdlStruct, typename=dds_type("geometry_msgs/msg/Pose")):
    position: Point = field(default_factory=Point)
    orientation: Quaternion = field(default_factory=Quaternion)


@dataclass
@annotate.final
class PoseArray(IdlStruct, typename=dds_type("geometry_msgs/msg/PoseArray")):
    """``geometry_msgs/PoseArray``: the identified positions (their ids: the identity message of the same stamp)."""

    header: Header = field(default_factory=Header)
    poses: sequence[Pose] = field(default_factory=list)


@dataclass
@annotate.final
class PoseWithCovariance(IdlStruct, typename=dds_type("geometry_msgs/msg/PoseWithCovariance")):
    pose: Pose = field(default_factory=Pose)
    covariance: array[float64, 36] = field(default_factory=lambda: _zeros(36))


@dataclass
@annotate.final
class Imu(IdlStruct, typename=dds_type("sensor_msgs/msg/Imu")):
    """``sensor_msgs/Imu``: a robot's heading is the yaw of ``orientation``, sent at ``header.stamp``."""

    header: Header = field(default_factory=Header)
    orientation: Quaternion = field(default_factory=Quaternion)
    orientation_covariance: array[float64, 9] = field(default_factory=lambda: _zeros(9))
    angular_velocity: Vector3 = field(default_factory=Vector3)
    angular_velocity_covariance: array[float64, 9] = field(default_factory=lambda: _zeros(9))
    linear_acceleration: Vector3 = field(default_factory=Vector3)
    linear_acceleration_covariance: array[float64, 9] = field(default_factory=lambda: _zeros(9))


@dataclass
@annotate.final
class ObjectHypothesis(IdlStruct, typename=dds_type("vision_msgs/msg/ObjectHypothesis")):
    class_id: str = ""
    score: float64 = 0.0


@dataclass
@annotate.final
class ObjectHypothesisWithPose(IdlStruct, typename=dds_type("vision_msgs/msg/ObjectHypothesisWithPose")):
    hypothesis: ObjectHypothesis = field(default_factory=ObjectHypothesis)
    pose: PoseWithCovariance = field(default_factory=PoseWithCovariance)


@dataclass
@annotate.final
class Point2D(IdlStruct, typename=dds_type("vision_msgs/msg/Point2D")):
    x: float64 = 0.0
    y: float64 = 0.0


@dataclass
@annotate.final
class Pose2D(IdlStruct, typename=dds_type("vision_msgs/msg/Pose2D")):
    position: Point2D = field(default_factory=Point2D)
    theta: float64 = 0.0


@dataclass
@annotate.final
class BoundingBox2D(IdlStruct, typename=dds_type("vision_msgs/msg/BoundingBox2D")):
    center: Pose2D = field(default_factory=Pose2D)
    size_x: float64 = 0.0
    size_y: float64 = 0.0


@dataclass
@annotate.final
class Detection2D(IdlStruct, typename=dds_type("vision_msgs/msg/Detection2D")):
    """One detection: ``results[0].pose.pose`` holds its observer-frame position and visual heading (yaw),
    ``results[0].hypothesis.score`` the detector's confidence, ``bbox`` the image box (pixels, may be zero)."""

    header: Header = field(default_factory=Header)
    results: sequence[ObjectHypothesisWithPose] = field(default_factory=list)
    bbox: BoundingBox2D = field(default_factory=BoundingBox2D)
    id: str = ""


@dataclass
@annotate.final
class Detection2DArray(IdlStruct, typename=dds_type("vision_msgs/msg/Detection2DArray")):
    """``vision_msgs/Detection2DArray``: one camera frame, stamped with its time."""

    header: Header = field(default_factory=Header)
    detections: sequence[Detection2D] = field(default_factory=list)


@dataclass
@annotate.final
class TeamIdentity(IdlStruct, typename=dds_type(TEAM_IDENTITY)):
    """``lookalike_msgs/TeamIdentity`` (:data:`lookalike.io.rosmap.TEAM_IDENTITY_MSG`)."""

    header: Header = field(default_factory=Header)
    frame: uint64 = 0
    ids: sequence[int32] = field(default_factory=list)
    poses: sequence[Pose] = field(default_factory=list)
    confidence: sequence[float64] = field(default_factory=list)
    age: sequence[float64] = field(default_factory=list)
    labels: sequence[int32] = field(default_factory=list)
