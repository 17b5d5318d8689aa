"""Box format conversions and the vectorised IoU matrix, in pixels, ``(n, 4)``: ``xywh`` (left, top, width, height),
``xyxy`` (left, top, right, bottom), ``cxcywh`` (centre, size), ``xysr`` (centre, area, aspect w/h, as in SORT)."""

from __future__ import annotations

import numpy as np


def xywh_to_xyxy(xywh: np.ndarray) -> np.ndarray:
    """``(n, 4)`` left/top/width/height to left/top/right/bottom."""
    b = np.asarray(xywh, dtype=float)
    out: np.ndarray = b.copy()
    out[..., 2:] += b[..., :2]
    return out


def xyxy_to_xywh(xyxy: np.ndarray) -> np.ndarray:
    """``(n, 4)`` left/top/right/bottom to left/top/width/height."""
    b = np.asarray(xyxy, dtype=float)
    out: np.ndarray = b.copy()
    out[..., 2:] -= b[..., :2]
    return out


def xywh_to_cxcywh(xywh: np.ndarray) -> np.ndarray:
    """``(n, 4)`` left/top/width/height to centre x/centre y/width/height."""
    b = np.asarray(xywh, dtype=float)
    out: np.ndarray = b.copy()
    out[..., :2] += b[..., 2:] / 2.0
    return out


def xywh_to_xysr(xywh: np.ndarray) -> np.ndarray:
    """``(n, 4)`` left/top/width/height to SORT's centre/area/aspect ``[u, v, s, r]``."""
    b = np.asarray(xywh, dtype=float)
    w, h = b[..., 2], b[..., 3]
    return np.stack([b[..., 0] + w / 2.0, b[..., 1] + h / 2.0, w * h, w / h], axis=-1)


def xysr_to_xywh(xysr: np.ndarray) -> np.ndarray:
    """``(n, 4)`` SORT's ``[u, v, s, r]`` to left/top/width/height (NaN where s·r < 0)."""
    z = np.asarray(xysr, dtype=float)
    area = z[..., 2] * z[..., 3]
    w = np.sqrt(area, out=np.full_like(area, np.nan), where=area >= 0)
    h = np.divide(z[..., 2], w, out=np.full_like(area, np.nan), where=w > 0)
    return np.stack([z[..., 0] - w / 2.0, z[..., 1] - h / 2.0, w, h], axis=-1)


def iou_matrix(xywh_a: np.ndarray, xywh_b: np.ndarray) -> np.ndarray:
    """Intersection over union ``(n, m)`` of every box in ``a`` with every box in ``b`` (0 for empty unions)."""
    a = np.asarray(xywh_a, dtype=float).reshape(-1, 4)
    b = np.asarray(xywh_b, dtype=float).reshape(-1, 4)
    ax1, ay1 = a[:, 0:1], a[:, 1:2]
    ax2, ay2 = ax1 + a[:, 2:3], ay1 + a[:, 3:4]
    bx1, by1 = b[:, 0], b[:, 1]
    bx2, by2 = bx1 + b[:, 2], by1 + b[:, 3]
    iw = np.minimum(ax2, bx2) - np.maximum(ax1, bx1)
    ih = np.minimum(ay2, by2) - np.maximum(ay1, by1)
    np.maximum(iw, 0.0, out=iw)
    np.maximum(ih, 0.0, out=ih)
    inter = iw * ih
    union = a[:, 2:3] * a[:, 3:4] + b[:, 2] * b[:, 3] - inter
    if (union > 0).all():
        result: np.ndarray = inter / union
    else:
        result = np.divide(inter, union, out=np.zeros_like(inter), where=union > 0)
    return result
