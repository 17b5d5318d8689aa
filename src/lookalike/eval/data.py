"""One sequence prepared for scoring: per-frame ids and similarity matrices after preprocessing.

Ground-truth and tracker ids are relabelled ``0 .. n-1`` (in increasing order of the original ids)
so that metrics can index dense arrays with them.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np


@dataclass(frozen=True, eq=False)
class SequenceData:
    """Per-frame ids and similarities of one sequence.

    Attributes:
        gt_ids: per frame, ``(n_t,)`` relabelled ground-truth ids.
        tracker_ids: per frame, ``(m_t,)`` relabelled tracker ids.
        similarity: per frame, ``(n_t, m_t)`` similarity in ``[0, 1]`` (IoU or distance score).
        num_gt_ids: number of distinct ground-truth ids.
        num_tracker_ids: number of distinct tracker ids.
    """

    gt_ids: list[np.ndarray]
    tracker_ids: list[np.ndarray]
    similarity: list[np.ndarray]
    num_gt_ids: int
    num_tracker_ids: int

    @property
    def num_frames(self) -> int:
        return len(self.gt_ids)

    @property
    def num_gt_dets(self) -> int:
        return int(sum(len(g) for g in self.gt_ids))

    @property
    def num_tracker_dets(self) -> int:
        return int(sum(len(t) for t in self.tracker_ids))

    def pairs(self) -> Pairs:
        """Every ``(gt, tracker)`` pair of every frame with a positive similarity, flattened."""
        frames, rows, cols, gts, trs, sims = [], [], [], [], [], []
        g_off = t_off = 0
        for t, sim in enumerate(self.similarity):
            r, c = np.nonzero(sim > 0)
            frames.append(np.full(len(r), t))
            rows.append(r + g_off)
            cols.append(c + t_off)
            gts.append(self.gt_ids[t][r])
            trs.append(self.tracker_ids[t][c])
            sims.append(sim[r, c])
            g_off += sim.shape[0]
            t_off += sim.shape[1]

        def cat(parts: list[Any], dt: type) -> np.ndarray:
            return np.concatenate(parts).astype(dt) if parts else np.zeros(0, dt)

        return Pairs(
            frame=cat(frames, int),
            gt_det=cat(rows, int),
            tracker_det=cat(cols, int),
            gt_id=cat(gts, int),
            tracker_id=cat(trs, int),
            similarity=cat(sims, float),
            num_gt_dets=g_off,
            num_tracker_dets=t_off,
        )


@dataclass(frozen=True, eq=False)
class Pairs:
    """Flattened positive-similarity pairs: ``gt_det``/``tracker_det`` index all detections of
    the sequence in frame order; ``gt_id``/``tracker_id`` are the relabelled ids."""

    frame: np.ndarray
    gt_det: np.ndarray
    tracker_det: np.ndarray
    gt_id: np.ndarray
    tracker_id: np.ndarray
    similarity: np.ndarray
    num_gt_dets: int
    num_tracker_dets: int
