"""Similarity in ``[0, 1]`` between one frame's ground-truth and tracker objects: box IoU through corner coordinates
(bit for bit TrackEval's), or the point score ``max(0, 1 - d / (2 * radius))``."""

from __future__ import annotations

import numpy as np

_EPS = np.finfo(float).eps


def rows_of(values: np.ndarray, width: int, name: str) -> np.ndarray:
    """``values`` as float rows ``(k, width)`` (one row ``(width,)`` too); ``ValueError`` naming ``name`` for another
    shape, which a reshape would otherwise cut into rows of the wrong values."""
    a = np.asarray(values, dtype=float)
    if a.ndim > 2 or (a.size and a.shape[-1] != width):
        raise ValueError(f"{name}: expected shape (k, {width}), got {a.shape}")
    return a.reshape(-1, width)


def _finite_rows(values: np.ndarray, width: int, name: str) -> np.ndarray:
    """:func:`rows_of`, with a ``ValueError`` naming ``name`` and the first row holding NaN or infinity."""
    a = rows_of(values, width, name)
    bad = np.flatnonzero(~np.isfinite(a).all(axis=1))
    if len(bad):
        raise ValueError(f"{name}[{bad[0]}]: NaN or infinity in {a[bad[0]].tolist()}")
    return a


def box_iou(gt_xywh: np.ndarray, tr_xywh: np.ndarray) -> np.ndarray:
    """IoU ``(n, m)`` of ``(n, 4)`` and ``(m, 4)`` xywh boxes (px); 0 for zero area or no union; ``ValueError`` naming
    the argument of another shape, or the argument and row of a box with NaN or infinity."""
    return _corner_iou(_finite_rows(gt_xywh, 4, "gt_xywh"), _finite_rows(tr_xywh, 4, "tr_xywh"), outer=True)


def pair_iou(gt_xywh: np.ndarray, tr_xywh: np.ndarray) -> np.ndarray:
    """IoU ``(k,)`` of ``k`` pairs of xywh boxes (px), bit for bit :func:`box_iou`'s."""
    return _corner_iou(gt_xywh, tr_xywh, outer=False)


def _corner_iou(gt_xywh: np.ndarray, tr_xywh: np.ndarray, outer: bool) -> np.ndarray:
    """IoU through corner coordinates: of every pair ``(n, m)`` (``outer``), or of row ``i`` with row ``i``."""
    a = rows_of(gt_xywh, 4, "gt_xywh")
    b = rows_of(tr_xywh, 4, "tr_xywh")
    ax0, ay0 = a[:, 0], a[:, 1]
    ax1, ay1 = ax0 + a[:, 2], ay0 + a[:, 3]
    bx0, by0 = b[:, 0], b[:, 1]
    bx1, by1 = bx0 + b[:, 2], by0 + b[:, 3]
    area_a = (ax1 - ax0) * (ay1 - ay0)
    area_b = (bx1 - bx0) * (by1 - by0)
    if outer:
        ax0, ay0, ax1, ay1, area_a = (v[:, None] for v in (ax0, ay0, ax1, ay1, area_a))
        bx0, by0, bx1, by1, area_b = (v[None, :] for v in (bx0, by0, bx1, by1, area_b))
    iw = np.minimum(ax1, bx1) - np.maximum(ax0, bx0)
    ih = np.minimum(ay1, by1) - np.maximum(ay0, by0)
    inter = np.maximum(iw, 0.0) * np.maximum(ih, 0.0)
    union = area_a + area_b - inter
    inter[(area_a <= _EPS) | (area_b <= _EPS) | (union <= _EPS)] = 0.0
    union[union <= _EPS] = 1.0
    result: np.ndarray = inter / union
    return result


def point_similarity(gt_xy: np.ndarray, tr_xy: np.ndarray, radius: float) -> np.ndarray:
    """Distance score ``(n, m)`` of ``(n, 2)`` and ``(m, 2)`` points: ``max(0, 1 - d / (2 * radius))``; ``ValueError``
    naming the argument of another shape, or the argument and row of a point with NaN or infinity."""
    if not radius > 0:
        raise ValueError(f"radius must be positive, got {radius}")
    a = _finite_rows(gt_xy, 2, "gt_xy")
    b = _finite_rows(tr_xy, 2, "tr_xy")
    d = np.sqrt(((a[:, None, :] - b[None, :, :]) ** 2).sum(axis=-1))
    result: np.ndarray = np.maximum(0.0, 1.0 - d / (2.0 * radius))
    return result
