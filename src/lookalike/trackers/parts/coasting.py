"""Coasting: a confirmed track lost ``coast_s`` seconds stops extrapolating, and a track missed ``j`` frames is reported
while tracks missed ``j`` frames came back at least ``report_prob`` of the time (:class:`Coasting`)."""

from __future__ import annotations

import numpy as np

from lookalike.trackers.parts.self_calibration import MissReturns

MAX_COAST_FRAMES = 10  # longest miss (frames) after which a track may still be reported at its prediction


class Coasting:
    """Observes how missed tracks end (come back or die) and decides which to extrapolate and report."""

    def __init__(self, coast_s: float, report_prob: float | None = None, min_count: int = 30,
                 longest: int = MAX_COAST_FRAMES) -> None:
        self.coast_s = coast_s
        self.report_prob = report_prob
        self.min_count = min_count
        self.returns = MissReturns(longest)

    def still(self, unseen_s: np.ndarray) -> np.ndarray:
        """``(k,)`` True for tracks unseen ``coast_s`` seconds or more: their velocity is dropped."""
        return unseen_s >= self.coast_s

    def observe(self, came_back: np.ndarray | None = None, died: np.ndarray | None = None) -> None:
        """Misses (frames) of confirmed tracks that were updated again, and of those deleted."""
        if came_back is not None:
            self.returns.came_back(came_back)
        if died is not None:
            self.returns.died(died)

    def decide(self, misses: np.ndarray) -> np.ndarray:
        """``(k,)`` True for tracks missed ``misses`` frames that are likely still present (reported
        at their predicted box); all False when reporting is off."""
        if self.report_prob is None:
            return np.zeros(len(misses), dtype=bool)
        return self.returns.likely_present(misses, self.report_prob, self.min_count)
