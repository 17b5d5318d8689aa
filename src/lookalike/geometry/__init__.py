"""Box conversions, IoU matrices and angle arithmetic."""

from lookalike.geometry.angles import angle_diff, circular_mean, wrap_angle
from lookalike.geometry.boxes import (
    iou_matrix,
    xywh_to_cxcywh,
    xywh_to_xysr,
    xywh_to_xyxy,
    xysr_to_xywh,
    xyxy_to_xywh,
)

__all__ = [
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
