"""SORT (Bewley et al., 2016): Kalman filter on ``[u, v, s, r]``, IoU cost, Hungarian matching.

The behaviour follows the reference implementation: state ``[u, v, s, r, u', v', s']`` with
``R = diag(1, 1, 10, 10)``, ``P0 = diag(10, 10, 10, 10, 1e4, 1e4, 1e4)``,
``Q = diag(1, 1, 1, 1, 0.01, 0.01, 1e-4)`` per frame; association by maximum total IoU (a
direct match when every detection and track has at most one pair above the threshold), pairs
below ``iou_threshold`` rejected afterwards; a track is reported in a frame when it was updated
in it and has ``min_hits`` consecutive hits (or during the first ``min_hits`` frames), with its
filtered box; it is deleted after more than ``max_age`` frames without update. All tracks are
predicted and updated together as batched arrays.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from lookalike.association.solver import max_weight_complete
from lookalike.geometry.boxes import iou_matrix, xysr_to_xywh, xywh_to_xysr
from lookalike.motion import kalman
from lookalike.trackers.base import check_positive, param
from lookalike.trackers.registry import register_tracker
from lookalike.trackers.timing import FrameClock
from lookalike.types import Frame, TrackSnapshot, TrackStatus

_H = np.hstack([np.eye(4), np.zeros((4, 3))])
_R = np.diag([1.0, 1.0, 10.0, 10.0])
_P0 = np.diag([10.0, 10.0, 10.0, 10.0, 1e4, 1e4, 1e4])
_Q = np.diag([1.0, 1.0, 1.0, 1.0, 1e-2, 1e-2, 1e-4])


def _transition(steps: float) -> np.ndarray:
    F = np.eye(7)
    F[0, 4] = F[1, 5] = F[2, 6] = steps
    return F


@register_tracker("sort")
class Sort:
    """SORT with the paper's defaults; boxes in pixels (``xywh``)."""

    @dataclass(frozen=True)
    class Config:
        max_age: int = param(1, "frames a track survives without a matched detection")
        min_hits: int = param(3, "consecutive hits before a track is reported")
        iou_threshold: float = param(0.3, "minimum IoU of a detection/track match")
        frame_interval_s: float | None = param(
            None, "seconds per frame of the motion model (None: the smallest step seen)"
        )

        def __post_init__(self) -> None:
            check_positive(self, "max_age", "min_hits", "iou_threshold", allow_zero=True)
            check_positive(self, "frame_interval_s")

    def __init__(self, config: "Sort.Config | None" = None) -> None:
        self.config = config or Sort.Config()
        self.reset()

    def reset(self) -> None:
        """Forget every track; ids restart at 1."""
        self._mean = np.zeros((0, 7))
        self._cov = np.zeros((0, 7, 7))
        self._ids = np.zeros(0, dtype=int)
        self._hit_streak = np.zeros(0, dtype=int)
        self._since_update = np.zeros(0, dtype=int)
        self._next_id = 1
        self._frame_count = 0
        self._clock = FrameClock(self.config.frame_interval_s)

    def update(self, frame: Frame) -> list[TrackSnapshot]:
        """Advance all tracks to ``frame`` and match its detections."""
        cfg = self.config
        steps = self._clock.steps(frame.time)
        self._frame_count += 1
        det_xywh = frame.detections.xywh
        pred_xywh = self._predict(steps)
        matches = self._associate(det_xywh, pred_xywh)
        det_of_track = np.full(len(self._ids), -1, dtype=int)
        if len(matches):
            t, d = matches[:, 1], matches[:, 0]
            z = xywh_to_xysr(det_xywh[d])
            self._mean[t], self._cov[t] = kalman.update(self._mean[t], self._cov[t], z, _H, _R)
            self._since_update[t] = 0
            self._hit_streak[t] += 1
            det_of_track[t] = d
        unmatched = np.ones(len(det_xywh), dtype=bool)
        unmatched[matches[:, 0]] = False
        new = np.flatnonzero(unmatched)
        if len(new):
            self._birth(xywh_to_xysr(det_xywh[new]))
            det_of_track = np.concatenate([det_of_track, new])

        out = self._report(det_of_track)
        alive = self._since_update <= cfg.max_age
        if not alive.all():
            self._keep(alive)
        return out

    # -- steps -------------------------------------------------------------------------------

    def _predict(self, steps: float) -> np.ndarray:
        """Predict every track; drop those whose box became invalid; return boxes ``(k, 4)``."""
        if not len(self._ids):
            return np.zeros((0, 4))
        mean = self._mean
        # Keep the predicted area positive, as the reference does.
        mean[mean[:, 6] + mean[:, 2] <= 0, 6] = 0.0
        self._mean, self._cov = kalman.predict(mean, self._cov, _transition(steps), _Q * steps)
        self._hit_streak[self._since_update > 0] = 0
        self._since_update += 1
        boxes = xysr_to_xywh(self._mean[:, :4])
        valid = np.isfinite(boxes).all(axis=1)
        if not valid.all():
            self._keep(valid)
            boxes = boxes[valid]
        return boxes

    def _associate(self, det_xywh: np.ndarray, trk_xywh: np.ndarray) -> np.ndarray:
        """``(k, 2)`` matched ``(detection, track)`` index pairs."""
        if len(det_xywh) == 0 or len(trk_xywh) == 0:
            return np.zeros((0, 2), dtype=int)
        iou = iou_matrix(det_xywh, trk_xywh)
        above = iou > self.config.iou_threshold
        if above.sum(axis=1).max() == 1 and above.sum(axis=0).max() == 1:
            rows, cols = np.nonzero(above)
        else:
            rows, cols = max_weight_complete(iou)
        keep = iou[rows, cols] >= self.config.iou_threshold
        return np.stack([rows[keep], cols[keep]], axis=1).astype(int)

    def _birth(self, z: np.ndarray) -> None:
        n = len(z)
        mean = np.hstack([z, np.zeros((n, 3))])
        self._mean = np.vstack([self._mean, mean])
        self._cov = np.concatenate([self._cov, np.broadcast_to(_P0, (n, 7, 7))])
        self._ids = np.concatenate([self._ids, np.arange(self._next_id, self._next_id + n)])
        self._next_id += n
        self._hit_streak = np.concatenate([self._hit_streak, np.zeros(n, dtype=int)])
        self._since_update = np.concatenate([self._since_update, np.zeros(n, dtype=int)])

    def _report(self, det_of_track: np.ndarray) -> list[TrackSnapshot]:
        min_hits = self.config.min_hits
        shown = (self._since_update < 1) & (
            (self._hit_streak >= min_hits) | (self._frame_count <= min_hits)
        )
        idx = np.flatnonzero(shown)
        if not len(idx):
            return []
        boxes = xysr_to_xywh(self._mean[idx, :4])
        velocity = self._mean[idx, 4:6] / self._clock.interval
        confirmed = self._hit_streak[idx] >= min_hits
        return [
            TrackSnapshot(
                track_id=int(self._ids[i]),
                status=TrackStatus.CONFIRMED if confirmed[j] else TrackStatus.TENTATIVE,
                xywh=boxes[j],
                velocity=velocity[j],
                detection_index=int(det_of_track[i]),
            )
            for j, i in enumerate(idx)
        ]

    def _keep(self, mask: np.ndarray) -> None:
        self._mean, self._cov = self._mean[mask], self._cov[mask]
        self._ids = self._ids[mask]
        self._hit_streak = self._hit_streak[mask]
        self._since_update = self._since_update[mask]
