"""How well a motion model fits the targets, judged on the tracker's own matches (no ground truth).

:class:`MotionFit` compares the normalised innovation squared (NIS) of confirmed tracks' centres with its chi-square (2
dof) distribution and raises the process noise until their medians agree (never lowers it)."""

from __future__ import annotations

import math

import numpy as np

CHI2_2DOF_MEDIAN = 2.0 * math.log(2.0)  # median of the chi-square distribution with 2 degrees of freedom


class MotionFit:
    """Process-noise scale (variance factor, >= 1) learnt from centre innovations, ``batch`` at a time.

    Each time ``batch`` innovations have been seen, the scale is multiplied by their median NIS over the chi-square
    median (the innovations were measured with the scale in force, so the factor converges to the one that makes the
    model's median fit), clipped to [1, ``max_scale``]."""

    def __init__(self, batch: int = 30, max_scale: float = 1e4) -> None:
        if batch < 1 or not max_scale >= 1.0:
            raise ValueError(f"MotionFit: batch={batch} must be >= 1 and max_scale={max_scale} >= 1")
        self.batch = batch
        self.max_scale = max_scale
        self.scale = 1.0
        self._pending: list[np.ndarray] = []  # this batch's NIS from observe / observe_parts
        # this batch's innovations (rows 0-1) and variances (rows 2-3) from observe_columns, their NIS
        # computed with the batch; a buffer of fixed size (grown only for a larger batch)
        self._columns = np.empty((4, 2 * batch))
        self._filled = 0
        self._count = 0

    def observe(self, innovation: np.ndarray, S: np.ndarray) -> None:
        """Centre innovations ``(k, 2)`` (pixels) of matched confirmed tracks and their covariances ``(k, 2, 2)``."""
        if len(innovation) == 0:
            return
        self.observe_parts(innovation, S[:, 0, 0], S[:, 0, 1], S[:, 1, 1])

    def observe_columns(self, innovation: np.ndarray, var: np.ndarray, rows: np.ndarray | None = None) -> None:
        """:meth:`observe` for diagonal covariances: innovations ``(2, k)`` and their variances ``(2, k)``
        as rows (x, y; pixels, pixels²), of the columns ``rows`` (mask; None: all). The same NIS as
        :meth:`observe_parts` with ``b = 0`` for finite innovations, computed when the batch is complete."""
        if rows is not None and np.count_nonzero(rows) < len(rows):
            innovation, var = innovation[:, rows], var[:, rows]
        k = innovation.shape[1]
        if not k:
            return
        n = self._filled
        if n + k > self._columns.shape[1]:
            grown = np.empty((4, 2 * (n + k)))
            grown[:, :n] = self._columns[:, :n]
            self._columns = grown
        self._columns[0:2, n:n + k] = innovation
        self._columns[2:4, n:n + k] = var
        self._filled = n + k
        self._count += k
        if self._count >= self.batch:
            self._update()

    def observe_parts(self, innovation: np.ndarray, a: np.ndarray, b: np.ndarray, d: np.ndarray) -> None:
        """:meth:`observe` with the covariances given by their entries ``a = S[:, 0, 0]``, ``b = S[:, 0, 1]``
        (= ``S[:, 1, 0]``) and ``d = S[:, 1, 1]``, each ``(k,)`` (pixels²)."""
        if len(innovation) == 0:
            return
        x, y = innovation[:, 0], innovation[:, 1]
        self._add((d * x * x - 2.0 * b * x * y + a * y * y) / (a * d - b * b))  # innovation' S^-1 innovation

    def _add(self, nis: np.ndarray) -> None:
        self._pending.append(nis)
        self._count += len(nis)
        if self._count >= self.batch:
            self._update()

    def _update(self) -> None:
        """Scale by the median NIS of the batch (the median does not depend on the order), then start a new batch."""
        parts = self._pending
        n = self._filled
        if n:
            parts = parts + [_nis_of_columns(self._columns[0:2, :n], self._columns[2:4, :n])]
        median = _median(parts[0] if len(parts) == 1 else np.concatenate(parts))
        self.scale = float(np.clip(self.scale * median / CHI2_2DOF_MEDIAN, 1.0, self.max_scale))
        self._pending, self._count, self._filled = [], 0, 0


def _median(values: np.ndarray) -> float:
    """``np.median`` of a non-empty 1-D float array: the middle of the sorted values, or the mean of the
    two middle ones, ``(a + b) / 2`` as ``np.mean`` computes it (NaN if any value is NaN)."""
    if np.count_nonzero(np.isnan(values)):
        return float("nan")
    ordered = np.sort(values)
    n = len(ordered)
    if n % 2:
        return float(ordered[n // 2])
    return float((ordered[n // 2 - 1] + ordered[n // 2]) / 2)


def _nis_of_columns(innovation: np.ndarray, var: np.ndarray) -> np.ndarray:
    """NIS of innovations ``(2, k)`` with diagonal covariances ``var (2, k)``:
    ``(d·x·x + a·y·y) / (a·d)``, :meth:`MotionFit.observe_parts`' numbers with ``b = 0``."""
    part = var[::-1] * innovation * innovation  # d·x·x, a·y·y
    out: np.ndarray = (part[0] + part[1]) / (var[0] * var[1])
    return out
