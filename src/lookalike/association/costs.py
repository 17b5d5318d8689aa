"""Association costs between tracks (rows) and detections (columns)."""

from __future__ import annotations

import numpy as np

from lookalike.geometry.boxes import iou_matrix


def iou_cost(track_xywh: np.ndarray, det_xywh: np.ndarray, min_iou: float = 0.0,
             det_weight: np.ndarray | None = None) -> np.ndarray:
    """``(k, d)`` costs ``1 - IoU`` (times ``det_weight`` per detection, if given), ``inf`` below ``min_iou``."""
    return cost_from_iou(iou_matrix(track_xywh, det_xywh), min_iou, det_weight)


def iou_columns(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """:func:`~lookalike.geometry.boxes.iou_matrix` bit for bit, of column boxes ``a (4, m)``, ``b (4, n)``."""
    lo_a, lo_b = a[0:2, :, None], b[0:2, None, :]
    side = np.minimum(lo_a + a[2:4, :, None], lo_b + b[2:4, None, :])
    side -= np.maximum(lo_a, lo_b)
    np.maximum(side, 0.0, out=side)
    inter = side[0] * side[1]
    union = (a[2] * a[3])[:, None] + b[2] * b[3]
    union -= inter
    if not union.size or np.minimum.reduce(union, axis=None) > 0:  # as iou_matrix: NaN takes the guarded division
        out: np.ndarray = inter / union
        return out
    out = np.divide(inter, union, out=np.zeros_like(inter), where=union > 0)
    return out


def cost_from_iou(iou: np.ndarray, min_iou: float = 0.0, det_weight: np.ndarray | None = None) -> np.ndarray:
    """:func:`iou_cost` from an IoU matrix ``(k, d)`` already computed."""
    cost = 1.0 - (iou if det_weight is None else iou * det_weight[None, :])
    if min_iou > 0:
        cost[iou < min_iou] = np.inf
    return cost


def centre_distance_cost(track_cxcywh: np.ndarray, det_cxcywh: np.ndarray, gate: np.ndarray | float,
                         max_scale: float) -> np.ndarray:
    """Distance between box centres in track heights (heights floored at 1 pixel): ``(k, d)``; ``inf`` beyond ``gate``
    (``(k, 1)`` or scalar, in heights) or where width or height differ by more than a factor ``max_scale``."""
    height = np.maximum(track_cxcywh[:, 3:4], 1.0)
    square = track_cxcywh[:, None, :2] - det_cxcywh[None, :, :2]
    square *= square
    dist: np.ndarray = np.sqrt(square[:, :, 0] + square[:, :, 1])  # np.linalg.norm's numbers
    dist /= height
    allowed = dist <= gate
    if not np.count_nonzero(allowed):  # every pair beyond the gate: the size ratios cannot matter
        dist.fill(np.inf)
        return dist
    size_t = np.maximum(track_cxcywh[:, None, 2:4], 1.0)
    ratio = np.abs(np.log(size_t / np.maximum(det_cxcywh[None, :, 2:4], 1.0)))
    allowed &= np.maximum(ratio[:, :, 0], ratio[:, :, 1]) <= np.log(max_scale)
    out: np.ndarray = np.where(allowed, dist, np.inf)
    return out
