"""Clutter share: how many of a detector's detections are one-frame flickers, without ground truth.

A target's detection usually overlaps one of the previous frame's; most clutter does not. :class:`ClutterShare` counts
the detections overlapping none of the previous frame's (IoU below ``min_iou``); their share sets the birth threshold's
quantile (docs/trackers/boxtrack.md)."""

from __future__ import annotations

import numpy as np

from lookalike.geometry.boxes import iou_matrix
from lookalike.trackers.parts.batches import overlapping_pairs, pair_iou


class ClutterShare:
    """Running share of detections with no overlap (IoU ≥ ``min_iou``) in the previous frame."""

    def __init__(self, min_iou: float = 0.5, min_count: int = 100) -> None:
        self.min_iou, self.min_count = min_iou, min_count
        self.seen = 0
        self.flicker = 0
        self._previous: np.ndarray | None = None

    @property
    def previous(self) -> np.ndarray | None:
        """The previous frame's boxes ``(p, 4)`` (pixels), None before the first frame."""
        return self._previous

    def observe(self, xywh: np.ndarray) -> None:
        """Count this frame's boxes ``(k, 4)`` (pixels) against the previous frame's."""
        xywh = np.asarray(xywh, dtype=float).reshape(-1, 4)
        previous, n = self._previous, len(xywh)
        if previous is not None and n:
            self.seen += n
            if len(previous):
                self.flicker += int(np.count_nonzero(iou_matrix(xywh, previous).max(axis=1) < self.min_iou))
            else:
                self.flicker += n
        self._previous = xywh

    def observe_overlaps(self, xywh: np.ndarray, overlap: np.ndarray | None) -> None:
        """:meth:`observe` given which pairs of :attr:`previous`'s boxes and this frame's overlap enough,
        ``overlap (p, k)`` boolean (IoU ≥ ``min_iou``), computed by the caller; None when either frame
        has no boxes. ``xywh`` must be a float ``(k, 4)`` array (kept as the next frame's previous boxes)."""
        n = len(xywh)
        if self._previous is not None and n:
            self.seen += n
            self.flicker += n if overlap is None else n - len(set(overlap.nonzero()[1].tolist()))
        self._previous = xywh

    def observe_pairs(self, xywh: np.ndarray) -> None:
        """:meth:`observe_overlaps` for a large frame, from the overlapping pairs alone (memory linear in the boxes):
        ``xywh`` a float ``(k, 4)`` array (pixels)."""
        previous = self._previous
        if previous is None or not len(previous) or not len(xywh):
            self.observe_overlaps(xywh, None)
            return
        i, j = overlapping_pairs(previous, xywh)
        near = j[pair_iou(previous[i], xywh[j]) >= self.min_iou]
        self.observe_count(xywh, len(xywh) - len(np.unique(near)))

    def observe_count(self, xywh: np.ndarray, flicker: int) -> None:
        """:meth:`observe` given the number ``flicker`` of this frame's boxes ``xywh (k, 4)`` overlapping none of
        :attr:`previous`'s (all ``k`` when there were none), counted by the caller."""
        n = len(xywh)
        if self._previous is not None and n:
            self.seen += n
            self.flicker += flicker
        self._previous = xywh

    @property
    def share(self) -> float | None:
        """The share of flickering detections, or None before ``min_count`` detections were judged."""
        return self.flicker / self.seen if self.seen >= self.min_count else None
