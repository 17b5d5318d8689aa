"""Closed-set slots: N identities (``max_targets``) that are never lost for good.

A tracker with a known number of targets keeps at most N confirmed tracks (slots), which never die. A coasting slot's
box shape is frozen (:meth:`ClosedSlots.freeze_shape`); its recovery gate grows with the time lost
(:meth:`ClosedSlots.gate`, sizes ``sqrt(w·h)``: :meth:`ClosedSlots.squared`); a slot lost ``refill_s`` seconds or more
is re-assigned to a persistent tentative track, keeping its id (:meth:`ClosedSlots.refill`)."""

from __future__ import annotations

import numpy as np

from lookalike.trackers.parts.table import TrackTable


class ClosedSlots:
    """The closed-set rules of a box tracker with ``size`` (N) slots; states ``[cx, cy, w, h, vx, vy, vw, vh]``."""

    def __init__(self, size: int, distance: float, growth: float, refill_s: float) -> None:
        self.size, self.distance, self.growth, self.refill_s = size, distance, growth, refill_s
        self.speed = 0.0  # typical speed of tracked slots, sizes per second (running mean of frame medians)

    def freeze_shape(self, table: TrackTable) -> None:
        """Drop the size velocity of every slot that missed its last detection (pixels/frame)."""
        lost = table.confirmed & (table.unseen_s > 0)
        table.mean[lost, 6:8] = 0.0

    def gate(self, unseen_s: np.ndarray) -> np.ndarray:
        """``(k, 1)`` recovery gate in track sizes: ``distance`` plus, per second lost, ``growth`` or
        twice the typical speed (sizes per second), whichever is more."""
        rate = max(self.growth, 2.0 * self.speed)
        return (self.distance + rate * np.asarray(unseen_s, dtype=float))[:, None]

    def observe_speed(self, table: TrackTable, tracked: np.ndarray, dt: float) -> None:
        """Update the typical speed from the slots ``tracked`` (mask) this frame (``dt`` seconds a frame)."""
        rows = np.flatnonzero(tracked & table.confirmed)
        if len(rows) and dt > 0:
            size = np.sqrt(np.maximum(table.mean[rows, 2] * table.mean[rows, 3], 1e-9))
            v = float(np.median(np.hypot(table.mean[rows, 4], table.mean[rows, 5]) / size)) / dt
            self.speed = v if self.speed == 0.0 else 0.9 * self.speed + 0.1 * v

    @staticmethod
    def squared(box: np.ndarray) -> np.ndarray:
        """``[cx, cy, w, h]`` boxes as squares of the same area (``[cx, cy, s, s]``, ``s = sqrt(w·h)``)."""
        out = np.array(box[:, :4], dtype=float, copy=True)
        out[:, 2] = out[:, 3] = np.sqrt(np.maximum(out[:, 2] * out[:, 3], 0.0))
        return out

    def _refillable(self, table: TrackTable) -> np.ndarray:
        return np.flatnonzero(table.confirmed & (table.unseen_s >= self.refill_s))

    def room(self, table: TrackTable) -> int:
        """How many new tentative tracks may start now: free slots plus slots lost ``refill_s`` or
        longer, less the tentative tracks already waiting."""
        free = self.size - int(table.confirmed.sum()) + len(self._refillable(table))
        return max(free - int((~table.confirmed).sum()), 0)

    def refill(self, table: TrackTable, ready: np.ndarray, det_of_track: np.ndarray) -> np.ndarray:
        """Confirm the tentative tracks ``ready`` (mask: reached ``n_init`` hits): into a free slot
        while fewer than N are confirmed, else into the slot lost longest (at least ``refill_s``),
        which keeps its id and takes the candidate's state and detection; candidates with no slot
        stay tentative. Returns ``det_of_track`` for the rows left (candidates moved are removed)."""
        ready = np.flatnonzero(ready & ~table.confirmed)
        free = max(self.size - int(table.confirmed.sum()), 0)
        table.confirmed[ready[:free]] = True
        ready = ready[free:]
        lost = self._refillable(table)
        lost = lost[np.argsort(-table.unseen_s[lost], kind="stable")][: len(ready)]
        if not len(lost):
            return det_of_track
        src = ready[: len(lost)]
        for s, d in zip(src, lost):
            table.copy_row(int(s), int(d), ("mean", "cov", "hits", "misses", "unseen_s"))
            det_of_track[d] = det_of_track[s]
        kept = np.ones(len(table), dtype=bool)
        kept[src] = False
        table.keep(kept)
        return det_of_track[kept]
