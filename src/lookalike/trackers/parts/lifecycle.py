"""Track lifecycle policy: when a track is confirmed and when it is deleted (:class:`Lifecycle`)."""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from lookalike.trackers.parts.table import TrackTable
from lookalike.types.tracks import TrackStatus

__all__ = ["Lifecycle", "TrackStatus"]


@dataclass(frozen=True)
class Lifecycle:
    """Confirmation and deletion rules, applied to a :class:`TrackTable`'s columns.

    Attributes:
        n_init: hits that confirm a track (1: confirmed at birth).
        tentative_max_misses: consecutive missed frames that delete a tentative track, at least 1 (None: no limit).
        tentative_max_unseen_s: seconds unseen beyond which a tentative track is deleted (None: no limit).
        max_misses: frames a confirmed track survives without an update (None: no limit).
        max_unseen_s: seconds a confirmed track survives without an update (None: no limit).
        closed: confirmed tracks are never deleted (a closed set of targets)."""

    n_init: int = 1
    tentative_max_misses: int | None = 1
    tentative_max_unseen_s: float | None = None
    max_misses: int | None = None
    max_unseen_s: float | None = None
    closed: bool = False

    def __post_init__(self) -> None:
        if self.n_init < 1:
            raise ValueError(f"Lifecycle.n_init must be >= 1, got {self.n_init}")
        for name, low in (("tentative_max_misses", 1), ("tentative_max_unseen_s", 0), ("max_misses", 0),
                          ("max_unseen_s", 0)):
            value = getattr(self, name)
            if value is not None and not value >= low:  # (NaN too: no track would survive it)
                raise ValueError(f"Lifecycle.{name} must be >= {low} or None, got {value}")

    def closed_set(self) -> Lifecycle:
        """The same rules for a closed set: confirmed tracks never die."""
        return replace(self, closed=True)

    def born_confirmed(self, first_frame: bool = False) -> bool:
        """Whether a track starts confirmed (``n_init`` 1, or born in the first frame when ``first_frame``)."""
        return self.n_init <= 1 or first_frame

    def confirm(self, table: TrackTable, rows: np.ndarray | slice = slice(None)) -> None:
        """Confirm the tracks (of ``rows``) whose ``hits`` reached ``n_init``."""
        table.confirmed[rows] |= table.hits[rows] >= self.n_init

    def alive(self, table: TrackTable, max_unseen_s: float | np.ndarray | None = None) -> np.ndarray:
        """``(k,)`` True for the tracks that survive this frame; ``max_unseen_s`` (per track or
        shared) overrides the policy's own limit."""
        limit_s = self.max_unseen_s if max_unseen_s is None else max_unseen_s
        tentative: np.ndarray
        if self.tentative_max_misses is not None:
            tentative = table.misses < self.tentative_max_misses
            if self.tentative_max_unseen_s is not None:
                tentative &= table.unseen_s <= self.tentative_max_unseen_s
        elif self.tentative_max_unseen_s is not None:  # (no all-True mask to narrow)
            tentative = table.unseen_s <= self.tentative_max_unseen_s
        else:
            tentative = np.ones(len(table), dtype=bool)
        if self.closed:
            out: np.ndarray = table.confirmed | tentative
            return out
        if not np.count_nonzero(table.confirmed):
            return tentative
        confirmed = None if self.max_misses is None else table.misses <= self.max_misses
        if limit_s is not None:
            within = table.unseen_s <= limit_s
            confirmed = within if confirmed is None else confirmed & within
        if confirmed is None:  # confirmed tracks never die here
            out = table.confirmed | tentative
            return out
        return np.where(table.confirmed, confirmed, tentative)

    def status(self, table: TrackTable, rows: np.ndarray) -> np.ndarray:
        """``(len(rows),)`` :class:`TrackStatus` values: tentative, confirmed (updated this frame) or lost."""
        out = np.full(len(rows), TrackStatus.TENTATIVE, dtype=object)
        confirmed = table.confirmed[rows]
        out[confirmed] = TrackStatus.CONFIRMED
        out[confirmed & (table.misses[rows] > 0)] = TrackStatus.LOST
        return out
