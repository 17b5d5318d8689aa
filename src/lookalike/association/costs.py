"""Association costs between tracks (rows) and detections (columns)."""

from __future__ import annotations

import numpy as np

from lookalike.geometry.boxes import iou_matrix


def iou_cost(track_xywh: np.ndarray, det_xywh: np.ndarray, min_iou: float = 0.0) -> np.ndarray:
    """``1 - IoU`` for every track/detection pair, ``inf`` where IoU < ``min_iou``: ``(k, d)``."""
    iou = iou_matrix(track_xywh, det_xywh)
    cost = 1.0 - iou
    if min_iou > 0:
        cost[iou < min_iou] = np.inf
    return cost
