"""One sequence prepared for scoring: detections per frame (flat, in frame order) with ids relabelled ``0 .. n-1``, and
their positive-similarity pairs (every other similarity is exactly 0)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True, eq=False)
class Pairs:
    """Positive-similarity pairs sorted by ground-truth then tracker detection (``gt_det``/``tracker_det``: indices in
    frame order; ``gt_id``/``tracker_id``: relabelled ids)."""

    frame: np.ndarray
    gt_det: np.ndarray
    tracker_det: np.ndarray
    gt_id: np.ndarray
    tracker_id: np.ndarray
    similarity: np.ndarray
    num_gt_dets: int
    num_tracker_dets: int


@dataclass(frozen=True, eq=False)
class SequenceData:
    """One sequence: frame ``t``'s ground-truth detections have ids ``gt_id[gt_bounds[t]:gt_bounds[t+1]]`` (relabelled,
    ``(F + 1,)`` bounds), the same for tracker detections, and ``pair``: every same-frame pair with similarity > 0."""

    gt_bounds: np.ndarray
    gt_id: np.ndarray
    tracker_bounds: np.ndarray
    tracker_id: np.ndarray
    pair: Pairs
    num_gt_ids: int
    num_tracker_ids: int

    @property
    def num_frames(self) -> int:
        return len(self.gt_bounds) - 1

    @property
    def num_gt_dets(self) -> int:
        return len(self.gt_id)

    @property
    def num_tracker_dets(self) -> int:
        return len(self.tracker_id)

    def pairs(self) -> Pairs:
        """Every ``(gt, tracker)`` pair of every frame with a positive similarity, flattened."""
        return self.pair

    @classmethod
    def from_frames(cls, gt_ids: list[np.ndarray], tracker_ids: list[np.ndarray], similarity: list[np.ndarray],
                    num_gt_ids: int, num_tracker_ids: int) -> SequenceData:
        """From per-frame relabelled ids ``(n_t,)``, ``(m_t,)`` and similarity matrices ``(n_t, m_t)``."""
        frames, gts, trs, sims = [], [], [], []
        g_off = t_off = 0
        for t, sim in enumerate(similarity):
            r, c = np.nonzero(sim > 0)
            frames.append(np.full(len(r), t))
            gts.append(r + g_off)
            trs.append(c + t_off)
            sims.append(sim[r, c])
            g_off += sim.shape[0]
            t_off += sim.shape[1]
        gt_bounds = np.concatenate([[0], np.cumsum([len(g) for g in gt_ids])]).astype(np.int64)
        tr_bounds = np.concatenate([[0], np.cumsum([len(t) for t in tracker_ids])]).astype(np.int64)
        gt_id = _cat(gt_ids, np.int64)
        tr_id = _cat(tracker_ids, np.int64)
        gt_det, tr_det = _cat(gts, np.int64), _cat(trs, np.int64)
        pair = Pairs(_cat(frames, np.int64), gt_det, tr_det, gt_id[gt_det], tr_id[tr_det], _cat(sims, np.float64),
                     len(gt_id), len(tr_id))
        return cls(gt_bounds, gt_id, tr_bounds, tr_id, pair, num_gt_ids, num_tracker_ids)

    def frames(self) -> tuple[list[np.ndarray], list[np.ndarray], list[np.ndarray]]:
        """Per-frame ``(gt ids, tracker ids, dense similarity matrices)`` (the plain form, for checks)."""
        gts, trs, sims = [], [], []
        p = self.pair
        for t in range(self.num_frames):
            g0, g1 = self.gt_bounds[t], self.gt_bounds[t + 1]
            t0, t1 = self.tracker_bounds[t], self.tracker_bounds[t + 1]
            sim = np.zeros((g1 - g0, t1 - t0))
            k = p.frame == t
            sim[p.gt_det[k] - g0, p.tracker_det[k] - t0] = p.similarity[k]
            gts.append(self.gt_id[g0:g1])
            trs.append(self.tracker_id[t0:t1])
            sims.append(sim)
        return gts, trs, sims


def _cat(parts: list[np.ndarray], dtype: type) -> np.ndarray:
    return np.concatenate(parts).astype(dtype) if parts else np.zeros(0, dtype)
