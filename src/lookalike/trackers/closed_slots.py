"""Closed-set slots: N identities (``max_targets``) that are never lost for good.

A tracker with a known number of targets keeps at most N confirmed tracks (slots), which never
die. Three rules keep a slot recoverable however long it is lost:

- while a slot coasts, its box shape is frozen (no size velocity), so the shape gate keeps
  accepting ordinary detections (:meth:`ClosedSlots.freeze_shape`);
- the recovery gate (centre distance in the slot's heights) grows with the time lost
  (:meth:`ClosedSlots.gate`);
- a slot lost for ``refill_s`` seconds or more is re-assigned to a candidate: a tentative track
  started on left-over confident detections that persisted for ``n_init`` frames (the evidence a
  target is there that no slot recovered). The slot keeps its id and takes the candidate's state
  (:meth:`ClosedSlots.refill`).
"""

from __future__ import annotations

import numpy as np

from lookalike.trackers.table import TrackTable


class ClosedSlots:
    """The closed-set rules of a box tracker with ``size`` (N) slots; states ``[cx, cy, w, h, vx, vy, vw, vh]``."""

    def __init__(self, size: int, distance: float, growth: float, refill_s: float) -> None:
        self.size, self.distance, self.growth, self.refill_s = size, distance, growth, refill_s

    def freeze_shape(self, table: TrackTable) -> None:
        """Drop the size velocity of every slot that missed its last detection (pixels/frame)."""
        lost = table.confirmed & (table.unseen_s > 0)
        table.mean[lost, 6:8] = 0.0

    def gate(self, unseen_s: np.ndarray) -> np.ndarray:
        """``(k, 1)`` recovery gate in track heights: ``distance`` plus ``growth`` per second lost."""
        return (self.distance + self.growth * np.asarray(unseen_s, dtype=float))[:, None]

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
