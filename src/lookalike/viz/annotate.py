"""Drawing tracking results on frames: identity-coloured outlined boxes, labels that avoid each other, tails, a caption
and a legend. Coordinates are pixels; images ``(h, w, 3)`` uint8 BGR, modified in place."""

from __future__ import annotations

from collections import deque

import numpy as np

from lookalike._optional import needs
from lookalike.viz.colors import BGR, OUTLINE, identity_colour

Rect = tuple[int, int, int, int]  # x0, y0, x1, y1 (px)


class LabelSpace:
    """The label tags already drawn on one image, so that the next label goes where it hides none."""

    def __init__(self) -> None:
        self.taken: list[Rect] = []

    def free(self, rect: Rect) -> bool:
        """Whether ``rect`` overlaps no tag placed so far."""
        x0, y0, x1, y1 = rect
        return all(x1 <= a0 or a1 <= x0 or y1 <= b0 or b1 <= y0 for a0, b0, a1, b1 in self.taken)


def _segment(image: np.ndarray, a: tuple[int, int], b: tuple[int, int], colour: BGR, thickness: int) -> None:
    with needs("cv2"):
        import cv2

    cv2.line(image, a, b, OUTLINE, thickness + 2, cv2.LINE_AA)
    cv2.line(image, a, b, colour, thickness, cv2.LINE_AA)


def draw_box(image: np.ndarray, xywh: np.ndarray, colour: BGR, label: str | None = None,
             thickness: int = 2, dashed: bool = False, labels: LabelSpace | None = None) -> None:
    """A box ``xywh (4,)`` (px) with a dark outline and an optional label above it (hiding none of ``labels``)."""
    with needs("cv2"):
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
                _segment(image, s, e, colour, thickness)
    else:
        cv2.rectangle(image, p0, p1, OUTLINE, thickness + 2, cv2.LINE_AA)
        cv2.rectangle(image, p0, p1, colour, thickness, cv2.LINE_AA)
    if label:
        draw_box_label(image, label, xywh, colour, labels)


def draw_box_label(image: np.ndarray, text: str, xywh: np.ndarray, colour: BGR, labels: LabelSpace | None) -> Rect:
    """:func:`draw_label` above box ``xywh (4,)`` (px), or where ``labels`` leave room around it."""
    x, y, w, h = (float(v) for v in xywh)
    x0, y0 = round(x), round(y)
    return draw_label(image, text, (x0, y0 - 2), colour, labels=labels, box=(x0, y0, round(x + w), round(y + h)))


def draw_label(image: np.ndarray, text: str, anchor: tuple[int, int], colour: BGR, scale: float = 0.45,
               labels: LabelSpace | None = None, box: Rect | None = None) -> Rect:
    """``text`` on a filled tag of ``colour`` with its bottom-left at ``anchor`` (px), or with ``labels`` the first
    place above, below ``box``, further up or down that hides no earlier tag. Returns the tag's rectangle."""
    with needs("cv2"):
        import cv2

    (tw, th), base = cv2.getTextSize(text, cv2.FONT_HERSHEY_SIMPLEX, scale, 1)
    h_tag, w_tag = th + base + 3, tw + 4
    height, width = image.shape[:2]
    x = int(np.clip(anchor[0], 0, max(width - w_tag, 0)))
    below = (box[3] if box is not None else anchor[1]) + h_tag + 2
    candidates = [anchor[1], below] + [anchor[1] - k * (h_tag + 1) for k in range(1, 4)] + \
                 [below + k * (h_tag + 1) for k in range(1, 4)]
    fits = [int(np.clip(y, h_tag, height)) for y in candidates]
    y = fits[0]
    if labels is not None:
        y = next((c for c in fits if labels.free((x, c - h_tag, x + w_tag, c))), fits[0])
    rect = (x, y - h_tag, x + w_tag, y)
    cv2.rectangle(image, (rect[0] - 1, rect[1] - 1), (rect[2] + 1, rect[3] + 1), OUTLINE, -1)
    cv2.rectangle(image, (rect[0], rect[1]), (rect[2], rect[3]), colour, -1)
    ink = (0, 0, 0) if sum(colour) > 450 else (255, 255, 255)
    cv2.putText(image, text, (x + 2, y - base - 1), cv2.FONT_HERSHEY_SIMPLEX, scale, ink, 1, cv2.LINE_AA)
    if labels is not None:
        labels.taken.append(rect)
    return rect


def draw_tail(image: np.ndarray, points: np.ndarray, colour: BGR, thickness: int = 2) -> None:
    """A fading, outlined polyline through ``points (n, 2)`` (px, oldest first); NaN points break the line."""
    with needs("cv2"):
        import cv2

    pts = np.asarray(points, dtype=float).reshape(-1, 2)
    n = len(pts)
    lim = 4.0 * max(image.shape[:2])  # far off-image points (behind the camera) are not drawn
    for k in range(1, n):
        a, b = pts[k - 1], pts[k]
        if not (np.isfinite(a).all() and np.isfinite(b).all()) or np.abs(np.r_[a, b]).max() > lim:
            continue
        fade = 0.35 + 0.65 * k / n
        c = tuple(int(ch * fade + 255 * (1 - fade) * 0.3) for ch in colour)
        pa, pb = (round(a[0]), round(a[1])), (round(b[0]), round(b[1]))
        cv2.line(image, pa, pb, OUTLINE, thickness + 2, cv2.LINE_AA)
        cv2.line(image, pa, pb, c, thickness, cv2.LINE_AA)


def draw_caption(image: np.ndarray, lines: list[str]) -> None:
    """Caption ``lines`` in the top-left corner on a translucent dark band."""
    with needs("cv2"):
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
    """The last ``length`` points of each id, for track tails; a tail breaks (NaN) at missing frames or a jump of
    more than ``max_jump`` (same units)."""

    def __init__(self, length: int = 30, max_jump: float | None = None) -> None:
        if length < 1:
            raise ValueError(f"Tails.length: must be >= 1, got {length}")
        if max_jump is not None and not max_jump > 0:
            raise ValueError(f"Tails.max_jump: must be positive, got {max_jump}")
        self.length, self.max_jump = length, max_jump
        self._points: dict[int, deque[np.ndarray]] = {}
        self._last: dict[int, int] = {}

    def add(self, frame: int, identity: int, point: np.ndarray, max_jump: float | None = None) -> None:
        """Record ``point (2,)`` of ``identity`` at ``frame`` (``max_jump`` default: the tails' own)."""
        q = self._points.setdefault(identity, deque(maxlen=self.length))
        p = np.asarray(point, dtype=float).reshape(2)
        limit = max_jump if max_jump is not None else self.max_jump
        if q and identity in self._last:
            gap = frame - self._last[identity] > 1
            jump = (limit is not None and np.isfinite(q[-1]).all() and float(np.hypot(*(p - q[-1]))) > limit)
            if gap or jump:
                q.append(np.full(2, np.nan))
        q.append(p)
        self._last[identity] = frame

    def expire(self, frame: int, max_age: int) -> None:
        """Forget ids not seen for more than ``max_age`` frames."""
        for identity in [i for i, f in self._last.items() if frame - f > max_age]:
            del self._last[identity], self._points[identity]

    def items(self) -> list[tuple[int, np.ndarray]]:
        """``(id, points (n, 2))`` for every id, points oldest first."""
        return [(i, np.array(q)) for i, q in self._points.items()]


def draw_box_tracks(image: np.ndarray, frame: int, ids: np.ndarray, xywh: np.ndarray, tails: Tails,
                    prefix: str = "id ", max_gap: int = 5, labels: LabelSpace | None = None,
                    dashed: np.ndarray | None = None) -> None:
    """Boxes ``xywh (n, 4)`` (px) of tracks ``ids (n,)`` in their identity colours with tails of their bottom-centres
    (kept ``max_gap`` frames unseen), labels avoiding each other and ``labels``; ``dashed (n,)`` boxes dashed."""
    boxes = np.asarray(xywh, dtype=float).reshape(-1, 4)
    ids = np.asarray(ids).reshape(-1).astype(int)
    if len(ids) != len(boxes):
        raise ValueError(f"ids: {len(ids)} ids for {len(boxes)} boxes")
    space = labels if labels is not None else LabelSpace()
    for i, b in zip(ids, boxes):
        jump = tails.max_jump if tails.max_jump is not None else max(float(b[3]), 1.0)
        tails.add(frame, int(i), np.array([b[0] + b[2] / 2, b[1] + b[3]]), max_jump=jump)
    tails.expire(frame, max_gap)
    for i, pts in tails.items():
        draw_tail(image, pts, identity_colour(i))
    flags = np.zeros(len(ids), bool) if dashed is None else np.asarray(dashed, bool).reshape(-1)
    for i, b, d in zip(ids, boxes, flags):  # every box first, so that no box is drawn over a label
        draw_box(image, b, identity_colour(int(i)), dashed=bool(d))
    for i, b in zip(ids, boxes):
        if np.isfinite(b).all():
            draw_box_label(image, f"{prefix}{int(i)}", b, identity_colour(int(i)), space)


def draw_legend(image: np.ndarray, entries: list[tuple[str, BGR, bool]], scale: float = 0.45) -> None:
    """A legend in the bottom-left corner: per entry a box sample (``colour``, dashed or not) and its text."""
    with needs("cv2"):
        import cv2

    if not entries:
        return
    step = 20
    width = max(cv2.getTextSize(t, cv2.FONT_HERSHEY_SIMPLEX, scale, 1)[0][0] for t, _, _ in entries) + 52
    top = image.shape[0] - step * len(entries) - 8
    band = image[max(top, 0):, : min(width, image.shape[1])]
    band[:] = (band.astype(np.uint16) * 2 // 5).astype(np.uint8)
    for k, (text, colour, dashed) in enumerate(entries):
        y = top + 6 + step * k
        draw_box(image, np.array([8, y + 2, 28, step - 8], float), colour, thickness=2, dashed=dashed)
        cv2.putText(image, text, (44, y + step - 7), cv2.FONT_HERSHEY_SIMPLEX, scale, (255, 255, 255), 1, cv2.LINE_AA)


def with_header(image: np.ndarray, lines: list[str], entries: list[tuple[str, BGR, bool]],
                scale: float = 0.45) -> np.ndarray:
    """A new image: ``image`` below a dark band with caption ``lines`` and, flowed left to right, the legend
    ``entries`` (a box sample of ``colour``, dashed or not, and its text), so that neither hides the picture nor sits
    under a video player's controls. The band's height depends only on the line count and the entries' texts."""
    with needs("cv2"):
        import cv2

    width, step = image.shape[1], 20
    rows: list[list[tuple[int, tuple[str, BGR, bool]]]] = [[]]
    x = 8
    for entry in entries:
        w = cv2.getTextSize(entry[0], cv2.FONT_HERSHEY_SIMPLEX, scale, 1)[0][0] + 48
        if rows[-1] and x + w > width:
            rows.append([])
            x = 8
        rows[-1].append((x, entry))
        x += w
    rows = [r for r in rows if r]
    band = np.full((8 + step * (len(lines) + len(rows)), width, 3), 32, np.uint8)
    for i, text in enumerate(lines):
        cv2.putText(band, text, (6, 17 + step * i), cv2.FONT_HERSHEY_SIMPLEX, 0.5, (255, 255, 255), 1, cv2.LINE_AA)
    for r, row in enumerate(rows):
        y = 4 + step * (len(lines) + r)
        for x0, (text, colour, dashed) in row:
            draw_box(band, np.array([x0, y + 4, 26, step - 9], float), colour, thickness=2, dashed=dashed)
            cv2.putText(band, text, (x0 + 34, y + step - 6), cv2.FONT_HERSHEY_SIMPLEX, scale, (235, 235, 235), 1,
                        cv2.LINE_AA)
    return np.vstack([band, image])
