"""Identities by the look while tracking: an online closed set's slots re-assigned after a crossing.

A motion-only closed set (``boxtrack`` with ``max_targets``) keeps N slots but cannot tell which animal leaves a
contact on which slot. :class:`LookIdentities` wraps it and learns, as the video plays, what each identity looks like
(the identity map of :func:`~lookalike.trackers.offline.appearance.fit_identity_space`, refitted every second), from
*pieces*: runs of one slot's rows on one animal's blob (:data:`~lookalike.trackers.offline.appearance.SINGLE_AREA` of
the slot's median area so far). When a new piece reaches
:data:`~lookalike.trackers.offline.appearance.MIN_ROWS` rows, the slots whose pieces began near it (a crossing's)
are given the identities their looks fit best, if that fits better by more than :data:`LOOK_THRESHOLD`. Rows already
reported keep their identity; nothing looks ahead. Chosen and measured in ``research/online_look/``."""

from __future__ import annotations

import bisect
import copy
from collections import deque
from collections.abc import Callable
from typing import Any

import numpy as np

from lookalike.association.solver import linear_sum_assignment
from lookalike.trackers.offline.appearance import (
    MIN_ROWS,
    SINGLE_AREA,
    IdentitySpace,
    fit_identity_space,
    log_distance,
    look_margin,
)
from lookalike.trackers.offline.tracklets import Tracklet
from lookalike.types import Frame, Tracks

__all__ = ["LOOK_THRESHOLD", "LookIdentities", "ShapeLookup", "SlotLooks", "shape_lookup", "shapes_by_box"]

LOOK_THRESHOLD = 0.5  # a crossing's slots change identities when that lowers their summed log distance this much
GROUP_FRAMES = 8  # pieces that began within this many frames of each other may come from one crossing ...
GROUP_SIZES = 3.0  # ... and within this many sizes (sqrt(w h) of the new piece's first box) of each other
MIN_JUDGE_ROWS = 3  # rows a piece needs to be weighed
AREA_HISTORY = 500  # latest blob areas of a slot whose median is its one-animal area
MAX_PIECES = 400  # finished pieces kept (the latest), which bounds memory and the refit on long or live videos
MAX_PIECE_ROWS = 1000  # shape vectors kept per piece

ShapeLookup = Callable[[int, np.ndarray], np.ndarray]
"""``(frame index, boxes (k, 4) px) -> (k, SHAPE_SIZE)`` shape vectors of the frame's blobs with those boxes (NaN
rows where none)."""


def shapes_by_box(xywh: np.ndarray, shapes: np.ndarray, boxes: np.ndarray) -> np.ndarray:
    """The rows of ``shapes`` (one per box of ``xywh``, ``(n, 4)``) whose boxes equal ``boxes`` ``(k, 4)``, NaN rows
    where none does."""
    same = (np.asarray(boxes, dtype=float).reshape(-1, 1, 4) == np.asarray(xywh).reshape(1, -1, 4)).all(axis=2)
    out = np.full((len(same), shapes.shape[1]), np.nan)
    found = same.any(axis=1)
    if found.any():
        out[found] = shapes[same[found].argmax(axis=1)]
    return out


def shape_lookup(rows: np.ndarray, shapes: np.ndarray, n_frames: int) -> ShapeLookup:
    """A :data:`ShapeLookup` over detection ``rows`` ``(k, >=6)`` (1-based frames, boxes in px) of ``n_frames``
    frames and their ``shapes`` ``(k, SHAPE_SIZE)``."""
    order = np.argsort(rows[:, 0], kind="stable")
    boxes, looks = rows[order, 2:6], np.asarray(shapes)[order]
    bounds = np.searchsorted(rows[order, 0], np.arange(1, n_frames + 2))

    def lookup(index: int, wanted: np.ndarray) -> np.ndarray:
        if not 0 <= index < n_frames:
            return np.full((len(wanted), looks.shape[1]), np.nan)
        a, b = bounds[index], bounds[index + 1]
        return shapes_by_box(boxes[a:b], looks[a:b], wanted)
    return lookup


class _Piece:
    def __init__(self, frame: int, centre: np.ndarray, size: float) -> None:
        self.first, self.centre, self.size = frame, centre, size
        self.shapes: list[np.ndarray] = []
        self.total: np.ndarray | float = 0.0  # the sum of its shape vectors


class SlotLooks:
    """Slot ids in, identities out, frame by frame; the identities are a permutation of the slot ids ``1..n_slots``
    (other ids pass unchanged). ``frame_rate``: frames per second (the map is refitted once a second)."""

    def __init__(self, n_slots: int, frame_rate: float, threshold: float = LOOK_THRESHOLD) -> None:
        self.n_slots, self.threshold = int(n_slots), float(threshold)
        self.refit_every = max(int(round(frame_rate)), 1)
        self.identity: dict[int, int] = {}
        self.areas: dict[int, tuple[deque[float], list[float]]] = {}
        self.pieces: dict[int, _Piece] = {}
        self.done: deque[tuple[int, np.ndarray, int]] = deque(maxlen=MAX_PIECES)  # identity, shapes, first frame
        self.space: IdentitySpace | None = None
        self._looks: dict[int, np.ndarray] | None = None  # each identity's look in ``space`` (None: to compute)
        self.frame = 0
        self.changes = 0  # re-assignments made

    def update(self, slots: np.ndarray, boxes: np.ndarray, shapes: np.ndarray) -> np.ndarray:
        """The identities of this frame's ``slots`` ``(k,)``; ``boxes`` ``(k, 4)`` xywh px; ``shapes``
        ``(k, SHAPE_SIZE)`` of the blob that updated each slot (NaN rows where none did)."""
        self.frame += 1
        fresh, seen = [], set()
        for slot, box, shape in zip(np.asarray(slots, dtype=int).tolist(), boxes, shapes):
            if not 1 <= slot <= self.n_slots:
                continue
            self.identity.setdefault(slot, slot)
            seen.add(slot)
            if not self._alone(slot, shape):
                self._close(slot)
                continue
            if slot not in self.pieces:
                size = float(np.sqrt(max(box[2] * box[3], 1.0)))
                self.pieces[slot] = _Piece(self.frame, box[:2] + box[2:4] / 2, size)
            if len(self.pieces[slot].shapes) < MAX_PIECE_ROWS:
                self.pieces[slot].shapes.append(shape)
                self.pieces[slot].total = self.pieces[slot].total + shape
            if len(self.pieces[slot].shapes) == MIN_ROWS:
                fresh.append(slot)
        for slot in [s for s in self.pieces if s not in seen]:
            self._close(slot)
        if self.frame % self.refit_every == 0:
            self._refit()
        if self.space is not None:
            for slot in fresh:
                self._judge(slot, self.space)
        return np.array([self.identity.get(s, s) for s in np.asarray(slots, dtype=int).tolist()], dtype=int)

    def margins(self, slots: np.ndarray) -> np.ndarray:
        """Per slot of ``slots`` ``(k,)``, after :meth:`update`: how much better its identity's look fits its current
        piece than the nearest other identity's (the log mean squared distance to that one minus to its own, within
        ±:data:`~lookalike.trackers.offline.appearance.MARGIN_CLIP`); NaN where the piece is under
        :data:`~lookalike.trackers.offline.appearance.MIN_ROWS` rows or a look is missing."""
        out = np.full(len(slots), np.nan)
        looks = self.identity_looks(self.space) if self.space is not None else {}
        if self.space is None or len(looks) < 2:
            return out
        for r, slot in enumerate(np.asarray(slots, dtype=int).tolist()):
            piece, identity = self.pieces.get(slot), self.identity.get(slot, slot)
            if piece is not None and len(piece.shapes) >= MIN_ROWS and identity in looks:
                mine = self.space.embed(np.asarray(piece.total)[None, :] / len(piece.shapes))[0]
                out[r] = look_margin(mine, looks[identity], np.array([v for k, v in looks.items() if k != identity]))
        return out

    def _alone(self, slot: int, shape: np.ndarray) -> bool:
        """Whether ``shape``'s blob is one animal's size: its area within :data:`SINGLE_AREA` of the median of the
        slot's latest :data:`AREA_HISTORY` areas (kept in arrival order and sorted)."""
        if np.isnan(shape[0]):
            return False
        order, ranked = self.areas.setdefault(slot, (deque(), []))
        area = float(np.exp(shape[0]))
        order.append(area)
        bisect.insort(ranked, area)
        if len(order) > AREA_HISTORY:
            del ranked[bisect.bisect_left(ranked, order.popleft())]
        n = len(ranked)
        typical = ranked[n // 2] if n % 2 else (ranked[n // 2 - 1] + ranked[n // 2]) / 2
        return SINGLE_AREA[0] * typical <= area <= SINGLE_AREA[1] * typical

    def _close(self, slot: int) -> None:
        piece = self.pieces.pop(slot, None)
        if piece is not None and len(piece.shapes) >= MIN_ROWS:
            self.done.append((self.identity[slot], np.array(piece.shapes), piece.first))
            self._looks = None

    def _refit(self) -> None:
        blocks = [(s, first) for _, s, first in self.done]
        blocks += [(np.array(p.shapes), p.first) for p in self.pieces.values() if len(p.shapes) >= MIN_ROWS]
        if len(blocks) < 2:
            return
        tracklets, start = [], 0
        for s, first in blocks:
            rows = np.zeros((len(s), 10))
            rows[:, 0] = first + np.arange(len(s))
            rows[:, 9] = start + np.arange(len(s))
            tracklets.append(Tracklet(rows))
            start += len(s)
        space = fit_identity_space(tracklets, np.vstack([s for s, _ in blocks]))
        if space is not None:
            self.space, self._looks = space, None

    def identity_looks(self, space: IdentitySpace) -> dict[int, np.ndarray]:
        """Each identity's look: the mean embedded shape of its finished pieces."""
        if self._looks is not None:
            return self._looks
        total: dict[int, np.ndarray] = {}
        count: dict[int, int] = {}
        for identity, s, _ in self.done:
            e = space.embed(s)
            total[identity] = total.get(identity, 0) + e.sum(axis=0)
            count[identity] = count.get(identity, 0) + len(e)
        self._looks = {k: total[k] / count[k] for k in total}
        return self._looks

    def _judge(self, slot: int, space: IdentitySpace) -> None:
        """Re-assign the identities of ``slot``'s crossing (its new piece's group) by their looks."""
        piece, looks = self.pieces[slot], self.identity_looks(space)
        group = [s for s, p in self.pieces.items()
                 if abs(p.first - piece.first) <= GROUP_FRAMES and len(p.shapes) >= MIN_JUDGE_ROWS
                 and self.identity[s] in looks
                 and (s == slot or np.hypot(*(p.centre - piece.centre)) <= GROUP_SIZES * piece.size)]
        if slot not in group or len(group) < 2:
            return
        ids = [self.identity[s] for s in group]
        mine = np.array([space.embed(np.array(self.pieces[s].shapes)).mean(axis=0) for s in group])
        theirs = np.array([looks[k] for k in ids])
        cost = log_distance(mine[:, None, :], theirs[None, :, :])
        rows, cols = linear_sum_assignment(cost)
        if np.trace(cost) - cost[rows, cols].sum() > self.threshold and (cols != rows).any():
            for a, b in zip(rows, cols):
                self.identity[group[a]] = ids[b]
            self.changes += 1


class LookIdentities:
    """``tracker`` (an online closed set of ``n_targets`` slots) with its reported ids re-assigned by
    :class:`SlotLooks`; ``shapes`` finds the shape vector of the blob behind each detection (None: the detections'
    ``feature``, as a describing blob detector gives them). Every other attribute is the tracker's."""

    def __init__(self, tracker: Any, n_targets: int, frame_rate: float, shapes: ShapeLookup | None = None,
                 keep_margins: bool = False) -> None:
        self.tracker, self.n_targets, self.frame_rate, self.shapes = tracker, int(n_targets), frame_rate, shapes
        self.keep_margins = keep_margins
        self.looks = SlotLooks(self.n_targets, frame_rate)
        self._margins: list[np.ndarray] = []

    def __getattr__(self, name: str) -> Any:
        if name == "tracker":  # not set yet (a copy being made)
            raise AttributeError(name)
        return getattr(self.tracker, name)

    def reset(self) -> None:
        self.tracker.reset()
        self.looks = SlotLooks(self.n_targets, self.frame_rate)
        self._margins = []

    def margin_rows(self) -> np.ndarray:
        """With ``keep_margins``, every reported row's look margin so far (:meth:`SlotLooks.margins`) as
        ``(frame, id, margin)`` rows (1-based frames), for the row confidence."""
        return np.vstack(self._margins) if self._margins else np.zeros((0, 3))

    def update(self, frame: Frame) -> Tracks:
        tracks: Tracks = self.tracker.update(frame)
        boxes = np.zeros((len(tracks), 4)) if tracks.xywh is None else np.asarray(tracks.xywh, dtype=float)
        used = tracks.detection_index >= 0
        index, feature = tracks.detection_index[used], frame.detections.feature
        if self.shapes is not None:
            found = self.shapes(frame.index, np.asarray(frame.detections.xywh)[index])
        elif feature is not None:
            found = np.asarray(feature, dtype=float)[index]
        else:
            found = np.full((len(index), 1), np.nan)
        shapes = np.full((len(tracks), found.shape[1]), np.nan)
        shapes[used] = found
        out = copy.copy(tracks)
        out.id = self.looks.update(tracks.id, boxes, shapes)
        if self.keep_margins and len(out.id) and out.xywh is not None:
            self._margins.append(np.column_stack([np.full(len(out.id), frame.index + 1.0), out.id,
                                                  self.looks.margins(tracks.id)]))
        return out
