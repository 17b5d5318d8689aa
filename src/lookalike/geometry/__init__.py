"""Box conversions, IoU matrices, angle arithmetic, the camera model and observer odometry."""

from lookalike.geometry.angles import angle_diff, circular_mean, wrap_angle
from lookalike.geometry.boxes import (
    iou_matrix,
    xysr_to_xywh,
    xywh_to_cxcywh,
    xywh_to_xysr,
    xywh_to_xyxy,
    xyxy_to_xywh,
)
from lookalike.geometry.camera import Camera, Extrinsics, Intrinsics, Pose2D, integrate_odometry

__all__ = [
    "Camera",
    "Extrinsics",
    "Intrinsics",
    "Pose2D",
    "integrate_odometry",
    "angle_diff",
    "circular_mean",
    "iou_matrix",
    "wrap_angle",
    "xywh_to_cxcywh",
    "xywh_to_xysr",
    "xywh_to_xyxy",
    "xysr_to_xywh",
    "xyxy_to_xywh",
]
