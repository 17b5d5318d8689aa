"""Non-maximum suppression of detection boxes (pixels, ``xywh``)."""

from __future__ import annotations

import numpy as np

from lookalike.geometry.boxes import iou_matrix

MATRIX_BOXES = 1024
"""Up to this many boxes :func:`nms` computes all overlaps at once, above it a row at a time (the same boxes kept)."""


def nms(xywh: np.ndarray, score: np.ndarray, iou: float) -> np.ndarray:
    """Indices of boxes kept by greedy non-maximum suppression (highest score first)."""
    order = np.argsort(-score, kind="stable")
    boxes = xywh[order]
    overlap = iou_matrix(boxes, boxes) if len(order) <= MATRIX_BOXES else None
    keep: list[int] = []
    suppressed = np.zeros(len(order), bool)
    for i in range(len(order)):
        if suppressed[i]:
            continue
        keep.append(int(order[i]))
        if overlap is not None:
            suppressed |= overlap[i] > iou
        else:  # (only the boxes after it and not yet suppressed can still be kept)
            rest = np.flatnonzero(~suppressed[i + 1:]) + i + 1
            suppressed[rest[iou_matrix(boxes[i : i + 1], boxes[rest])[0] > iou]] = True
    return np.array(keep, dtype=int)


def merge_nms(xywh: np.ndarray, score: np.ndarray, overlap: float, merge_iou: float) -> tuple[np.ndarray, np.ndarray]:
    """Greedy suppression of boxes ``(n, 4)`` px, best ``score`` first, by intersection over the smaller box >
    ``overlap``; each kept box becomes the mean of the unsuppressed boxes it overlaps by IoU > ``merge_iou``.
    Returns ``(boxes (k, 4) px, index (k,) of each kept box)``."""
    x = np.asarray(xywh, float).reshape(-1, 4)
    order = np.argsort(-np.asarray(score), kind="stable")
    xo = x[order]
    x0, y0, x1, y1 = xo[:, 0], xo[:, 1], xo[:, 0] + xo[:, 2], xo[:, 1] + xo[:, 3]
    iw = np.clip(np.minimum(x1[:, None], x1) - np.maximum(x0[:, None], x0), 0, None)
    ih = np.clip(np.minimum(y1[:, None], y1) - np.maximum(y0[:, None], y0), 0, None)
    area = xo[:, 2] * xo[:, 3]
    inter = iw * ih
    over_min = inter / np.maximum(np.minimum(area[:, None], area), 1e-12)
    iou = inter / np.maximum(area[:, None] + area - inter, 1e-12)
    boxes, keep = [], []
    suppressed = np.zeros(len(order), bool)
    for i in range(len(order)):
        if suppressed[i]:
            continue
        group = (iou[i] > merge_iou) & ~suppressed
        group[i] = True
        boxes.append(xo[group].mean(axis=0))
        keep.append(int(order[i]))
        suppressed |= over_min[i] > overlap
    return np.array(boxes).reshape(-1, 4), np.array(keep, dtype=int)
