"""Online identities by the look (rule.md): a causal layer over an online closed set's slots."""

from __future__ import annotations

import numpy as np
from scipy.optimize import linear_sum_assignment

from lookalike.trackers.offline.appearance import MIN_ROWS, SINGLE_AREA, fit_identity_space
from lookalike.trackers.offline.tracklets import Tracklet

GROUP_FRAMES = 8  # pieces that started within this many frames of each other may be one crossing's
GROUP_SIZES = 3.0  # ... and within this many sizes of each other then
MIN_JUDGE_ROWS = 3  # rows a group member's piece needs to be weighed
AREA_HISTORY = 500  # blobs per slot whose median area is its typical one


class _Piece:
    def __init__(self, frame: int, centre: np.ndarray, size: float) -> None:
        self.first, self.centre, self.size = frame, centre, size
        self.shapes: list[np.ndarray] = []


class OnlineLook:
    """Slot ids in, identities out (a permutation of the slot ids), frame by frame."""

    def __init__(self, frame_rate: float, threshold: float) -> None:
        self.threshold = threshold
        self.refit_every = max(int(round(frame_rate)), 1)
        self.identity: dict[int, int] = {}
        self.areas: dict[int, list[float]] = {}
        self.pieces: dict[int, _Piece] = {}
        self.done: list[tuple[int, np.ndarray, int, int]] = []  # identity, shapes, first, last
        self.space = None
        self.frame = 0
        self.changes = 0

    def _close(self, slot: int) -> None:
        piece = self.pieces.pop(slot, None)
        if piece is not None and len(piece.shapes) >= MIN_ROWS:
            self.done.append((self.identity[slot], np.array(piece.shapes), piece.first,
                              piece.first + len(piece.shapes) - 1))

    def _refit(self) -> None:
        blocks = [(s, first) for _, s, first, _ in self.done]
        blocks += [(np.array(p.shapes), p.first) for p in self.pieces.values() if len(p.shapes) >= MIN_ROWS]
        if len(blocks) < 2:
            return
        shapes = np.vstack([s for s, _ in blocks])
        tracklets, start = [], 0
        for s, first in blocks:
            rows = np.zeros((len(s), 10))
            rows[:, 0] = first + np.arange(len(s))
            rows[:, 9] = start + np.arange(len(s))
            tracklets.append(Tracklet(rows))
            start += len(s)
        space = fit_identity_space(tracklets, shapes)
        if space is not None:
            self.space = space

    def _looks(self) -> dict[int, np.ndarray]:
        total: dict[int, np.ndarray] = {}
        count: dict[int, int] = {}
        for identity, s, _, _ in self.done:
            e = self.space.embed(s)
            total[identity] = total.get(identity, 0) + e.sum(axis=0)
            count[identity] = count.get(identity, 0) + len(e)
        return {k: total[k] / count[k] for k in total}

    def _judge(self, slot: int, centres: dict[int, np.ndarray]) -> None:
        piece = self.pieces[slot]
        looks = self._looks()
        group = [s for s, p in self.pieces.items()
                 if abs(p.first - piece.first) <= GROUP_FRAMES and len(p.shapes) >= MIN_JUDGE_ROWS
                 and self.identity[s] in looks]
        near = []
        for s in group:
            p = self.pieces[s]
            # where the other slot's piece began, against where this one began (both at their own first frame)
            if s == slot or np.hypot(*(p.centre - piece.centre)) <= GROUP_SIZES * piece.size:
                near.append(s)
        if slot not in near or len(near) < 2:
            return
        ids = [self.identity[s] for s in near]
        cost = np.empty((len(near), len(near)))
        for a, s in enumerate(near):
            mine = self.space.embed(np.array(self.pieces[s].shapes)).mean(axis=0)
            for b, k in enumerate(ids):
                cost[a, b] = np.log(np.mean((mine - looks[k]) ** 2) + 1e-9)
        rows, cols = linear_sum_assignment(cost)
        if np.trace(cost) - cost[rows, cols].sum() > self.threshold and (cols != np.arange(len(near))).any():
            for a, b in zip(rows, cols):
                self.identity[near[a]] = ids[b]
            self.changes += 1

    def update(self, slots: np.ndarray, boxes: np.ndarray, shapes: np.ndarray) -> np.ndarray:
        """Identities of this frame's ``slots`` (``boxes`` ``(k, 4)`` xywh px; ``shapes`` ``(k, S)``, NaN rows where
        no blob updated the slot)."""
        self.frame += 1
        seen = set()
        centres = {}
        fresh = []
        for slot, box, shape in zip(slots.tolist(), boxes, shapes):
            self.identity.setdefault(slot, slot)
            seen.add(slot)
            centres[slot] = box[:2] + box[2:4] / 2
            if np.isnan(shape[0]):
                self._close(slot)
                continue
            history = self.areas.setdefault(slot, [])
            history.append(float(np.exp(shape[0])))
            del history[:-AREA_HISTORY]
            typical = float(np.median(history))
            area = history[-1]
            if not SINGLE_AREA[0] * typical <= area <= SINGLE_AREA[1] * typical:
                self._close(slot)
                continue
            if slot not in self.pieces:
                self.pieces[slot] = _Piece(self.frame, centres[slot], float(np.sqrt(max(box[2] * box[3], 1.0))))
            self.pieces[slot].shapes.append(shape)
            if len(self.pieces[slot].shapes) == MIN_ROWS:
                fresh.append(slot)
        for slot in [s for s in self.pieces if s not in seen]:
            self._close(slot)
        if self.frame % self.refit_every == 0:
            self._refit()
        if self.space is not None:
            for slot in fresh:
                self._judge(slot, centres)
        return np.array([self.identity[s] for s in slots.tolist()], dtype=int)
