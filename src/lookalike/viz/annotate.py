"""Drawing tracking results on frames: identity-coloured boxes, labels, tails and a caption.

All coordinates are pixels of the image being drawn on; images are ``(h, w, 3)`` uint8 BGR and are
modified in place. OpenCV is imported lazily.
"""

from __future__ import annotations

from collections import deque

import numpy as np

from lookalike.viz.colors import BGR, identity_colour


def draw_box(image: np.ndarray, xywh: np.ndarray, colour: BGR, label: str | None = None,
             thickness: int = 2, dashed: bool = False) -> None:
    """A box ``xywh (4,)`` (px) with an optional filled label above it (below when at the top edge)."""
    import cv2

    x, y, w, h = (float(v) for v in xywh)
    if not np.isfinite([x, y, w, h]).all():
        return
    p0, p1 = (round(x), round(y)), (round(x + w), round(y + h))
    if dashed:
        for a, b in ((p0, (p1[0], p0[1])), ((p1[0], p0[1]), p1), (p1, (p0[0], p1[1])), ((p0[0], p1[1]), p0)):
            n = max(int(np.hypot(b[0] - a[0], b[1] - a[1]) // 6), 1)
            for k in range(0, n, 2):
                s = (round(a[0] + (b[0] - a[0]) * k / n), round(a[1] + (b[1] - a[1]) * k / n))
                e = (round(a[0] + (b[0] - a[0]) * (k + 1) / n), round(a[1] + (b[1] - a[1]) * (k + 1) / n))
                cv2.line(image, s, e, colour, thickness, cv2.LINE_AA)
    else:
        cv2.rectangle(image, p0, p1, colour, thickness, cv2.LINE_AA)
    if label:
        draw_label(image, label, (p0[0], p0[1]), colour)


def draw_label(image: np.ndarray, text: str, anchor: tuple[int, int], colour: BGR, scale: float = 0.45) -> None:
    """``text`` on a filled tag of ``colour`` whose bottom-left corner is ``anchor`` (px)."""
    import cv2

    (tw, th), base = cv2.getTextSize(text, cv2.FONT_HERSHEY_SIMPLEX, scale, 1)
    x = int(np.clip(anchor[0], 0, max(image.shape[1] - tw - 4, 0)))
    y = anchor[1] if anchor[1] - th - base - 2 >= 0 else anchor[1] + th + base + 2
    cv2.rectangle(image, (x, y - th - base - 2), (x + tw + 4, y), colour, -1)
    ink = (0, 0, 0) if sum(colour) > 450 else (255, 255, 255)
    cv2.putText(image, text, (x + 2, y - base - 1), cv2.FONT_HERSHEY_SIMPLEX, scale, ink, 1, cv2.LINE_AA)


def draw_tail(image: np.ndarray, points: np.ndarray, colour: BGR, thickness: int = 2) -> None:
    """A fading polyline through ``points (n, 2)`` (px, oldest first); NaN points break the line."""
    import cv2

    pts = np.asarray(points, dtype=float).reshape(-1, 2)
    n = len(pts)
    for k in range(1, n):
        a, b = pts[k - 1], pts[k]
        if not (np.isfinite(a).all() and np.isfinite(b).all()):
            continue
        fade = 0.35 + 0.65 * k / n
        c = tuple(int(ch * fade + 255 * (1 - fade) * 0.3) for ch in colour)
        cv2.line(image, (round(a[0]), round(a[1])), (round(b[0]), round(b[1])), c, thickness, cv2.LINE_AA)


def draw_caption(image: np.ndarray, lines: list[str]) -> None:
    """Caption ``lines`` in the top-left corner on a translucent dark band."""
    import cv2

    if not lines:
        return
    scale, step = 0.5, 18
    width = max(cv2.getTextSize(t, cv2.FONT_HERSHEY_SIMPLEX, scale, 1)[0][0] for t in lines) + 12
    band = image[: step * len(lines) + 8, : min(width, image.shape[1])]
    band[:] = (band.astype(np.uint16) * 2 // 5).astype(np.uint8)
    for i, text in enumerate(lines):
        cv2.putText(image, text, (6, 17 + step * i), cv2.FONT_HERSHEY_SIMPLEX, scale, (255, 255, 255), 1, cv2.LINE_AA)


class Tails:
    """The last ``length`` points of each id, for drawing track tails (any coordinate frame)."""

    def __init__(self, length: int = 30) -> None:
        if length < 1:
            raise ValueError(f"Tails.length: must be >= 1, got {length}")
        self.length = length
        self._points: dict[int, deque[np.ndarray]] = {}
        self._last: dict[int, int] = {}

    def add(self, frame: int, identity: int, point: np.ndarray) -> None:
        """Record ``point (2,)`` of ``identity`` at ``frame``; a gap in frames breaks the tail (NaN)."""
        q = self._points.setdefault(identity, deque(maxlen=self.length))
        if identity in self._last and frame - self._last[identity] > 1 and q:
            q.append(np.full(2, np.nan))
        q.append(np.asarray(point, dtype=float).reshape(2))
        self._last[identity] = frame

    def expire(self, frame: int, max_age: int) -> None:
        """Forget ids not seen for more than ``max_age`` frames."""
        for identity in [i for i, f in self._last.items() if frame - f > max_age]:
            del self._last[identity], self._points[identity]

    def items(self) -> list[tuple[int, np.ndarray]]:
        """``(id, points (n, 2))`` for every id, points oldest first."""
        return [(i, np.array(q)) for i, q in self._points.items()]


def draw_box_tracks(image: np.ndarray, frame: int, ids: np.ndarray, xywh: np.ndarray, tails: Tails,
                    prefix: str = "id ", max_gap: int = 5) -> None:
    """Boxes ``xywh (n, 4)`` (px) of tracks ``ids (n,)`` in their identity colours, with tails of
    their bottom-centres (``tails`` is updated with this frame's points; tails of tracks unseen for
    more than ``max_gap`` frames are dropped)."""
    boxes = np.asarray(xywh, dtype=float).reshape(-1, 4)
    ids = np.asarray(ids).reshape(-1).astype(int)
    if len(ids) != len(boxes):
        raise ValueError(f"ids: {len(ids)} ids for {len(boxes)} boxes")
    for i, b in zip(ids, boxes):
        tails.add(frame, int(i), np.array([b[0] + b[2] / 2, b[1] + b[3]]))
    tails.expire(frame, max_gap)
    for i, pts in tails.items():
        draw_tail(image, pts, identity_colour(i))
    for i, b in zip(ids, boxes):
        draw_box(image, b, identity_colour(int(i)), f"{prefix}{int(i)}")
