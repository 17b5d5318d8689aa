"""Non-maximum suppression of detection boxes (pixels, ``xywh``)."""

from __future__ import annotations

import numpy as np

from lookalike.geometry.boxes import iou_matrix


def nms(xywh: np.ndarray, score: np.ndarray, iou: float) -> np.ndarray:
    """Indices of boxes kept by greedy non-maximum suppression (highest score first)."""
    order = np.argsort(-score, kind="stable")
    overlap = iou_matrix(xywh[order], xywh[order])
    keep: list[int] = []
    suppressed = np.zeros(len(order), bool)
    for i in range(len(order)):
        if suppressed[i]:
            continue
        keep.append(int(order[i]))
        suppressed |= overlap[i] > iou
    return np.array(keep, dtype=int)


def merge_nms(xywh: np.ndarray, score: np.ndarray, overlap: float, merge_iou: float) -> tuple[np.ndarray, np.ndarray]:
    """Greedy suppression by intersection over the smaller box, with box averaging.

    Boxes ``(n, 4)`` px are visited best ``score`` first; each one not yet suppressed is kept and suppresses
    every box whose intersection with it exceeds ``overlap`` of the smaller area (windows on parts of
    a target, or shifted copies). Its output box is the plain mean of the not yet suppressed boxes overlapping
    it by IoU > ``merge_iou``, which localises better than the single best window of a coarse pyramid.
    Returns ``(boxes (k, 4) px, index (k,) of each kept box)``.
    """
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
