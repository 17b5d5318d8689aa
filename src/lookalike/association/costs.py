"""Association costs between tracks (rows) and detections (columns)."""

from __future__ import annotations

import numpy as np

from lookalike.geometry.boxes import iou_matrix


def iou_cost(track_xywh: np.ndarray, det_xywh: np.ndarray, min_iou: float = 0.0,
             det_weight: np.ndarray | None = None) -> np.ndarray:
    """``1 - IoU`` (``1 - IoU·weight`` with a per-detection ``det_weight``, e.g. its score) for every
    track/detection pair, ``inf`` where IoU < ``min_iou``: ``(k, d)``."""
    return cost_from_iou(iou_matrix(track_xywh, det_xywh), min_iou, det_weight)


def cost_from_iou(iou: np.ndarray, min_iou: float = 0.0, det_weight: np.ndarray | None = None) -> np.ndarray:
    """:func:`iou_cost` from an IoU matrix ``(k, d)`` already computed (e.g. a block of a frame's
    whole track × detection matrix)."""
    cost = 1.0 - (iou if det_weight is None else iou * det_weight[None, :])
    if min_iou > 0:
        cost[iou < min_iou] = np.inf
    return cost


def centre_distance_cost(track_cxcywh: np.ndarray, det_cxcywh: np.ndarray, gate: np.ndarray,
                         max_scale: float) -> np.ndarray:
    """Distance between box centres in track heights (heights floored at 1 pixel): ``(k, d)``;
    ``inf`` beyond ``gate`` (``(k, 1)`` or scalar, in heights) or where width or height differ by
    more than a factor ``max_scale``."""
    height = np.maximum(track_cxcywh[:, 3:4], 1.0)
    dist = np.linalg.norm(track_cxcywh[:, None, :2] - det_cxcywh[None, :, :2], axis=2) / height
    size_t = np.maximum(track_cxcywh[:, None, 2:4], 1.0)
    ratio = np.abs(np.log(size_t / np.maximum(det_cxcywh[None, :, 2:4], 1.0))).max(axis=2)
    return np.where((dist <= gate) & (ratio <= np.log(max_scale)), dist, np.inf)
