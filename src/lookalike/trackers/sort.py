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

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from lookalike.association.solver import max_weight_complete
from lookalike.association.stages import Stage, run_plan
from lookalike.geometry.boxes import iou_matrix
from lookalike.motion import kalman
from lookalike.motion.spaces import BoxXYSR
from lookalike.trackers.base import COUNT0, POSITIVE, UNIT, check_params, param
from lookalike.trackers.lifecycle import Lifecycle
from lookalike.trackers.registry import register_tracker
from lookalike.trackers.table import TrackTable
from lookalike.trackers.timing import FrameClock
from lookalike.types import Frame, Tracks

_SPACE = BoxXYSR()


def solve_max_iou(threshold: float) -> Callable[[np.ndarray], np.ndarray]:
    """SORT's solver on a ``(tracks, detections)`` IoU matrix: a direct match when every detection
    and track has at most one pair above ``threshold``, else a maximum-IoU complete matching;
    pairs below ``threshold`` are dropped afterwards."""

    def solve(iou_td: np.ndarray) -> np.ndarray:
        iou = iou_td.T  # detections × tracks, as the reference solves it (ties break alike)
        above = iou > threshold
        if above.sum(axis=1).max() == 1 and above.sum(axis=0).max() == 1:
            rows, cols = np.nonzero(above)
        else:
            rows, cols = max_weight_complete(iou)
        keep = iou[rows, cols] >= threshold
        return np.stack([cols[keep], rows[keep]], axis=1).astype(int)

    return solve


@register_tracker("sort")
class Sort:
    """SORT with the paper's defaults; boxes in pixels (``xywh``)."""

    @dataclass(frozen=True)
    class Config:
        max_age: int = param(1, "frames a track survives without a matched detection", range=COUNT0)
        min_hits: int = param(3, "consecutive hits before a track is reported", range=COUNT0)
        iou_threshold: float = param(0.3, "minimum IoU of a detection/track match", range=UNIT)
        frame_interval_s: float | None = param(
            None, "seconds per frame of the motion model (None: the smallest step seen)", range=POSITIVE
        )

        def __post_init__(self) -> None:
            check_params(self)

    def __init__(self, config: Sort.Config | None = None) -> None:
        self.config = config or Sort.Config()
        # every track, tentative or not, survives max_age frames without an update
        self._lifecycle = Lifecycle(tentative_max_misses=self.config.max_age + 1, max_misses=self.config.max_age)
        self.reset()

    def reset(self) -> None:
        """Forget every track; ids restart at 1."""
        self._tracks = TrackTable(7)  # hits: the current streak of consecutive hits
        self._frame_count = 0
        self._clock = FrameClock(self.config.frame_interval_s)

    def update(self, frame: Frame) -> Tracks:
        """Advance all tracks to ``frame`` and match its detections."""
        t = self._tracks
        steps = self._clock.steps(frame.time)
        self._frame_count += 1
        det_xywh = frame.detections.xywh
        pred_xywh = self._predict(steps)
        matching = run_plan([Stage(None, None, lambda r, c: iou_matrix(det_xywh[c], pred_xywh[r]).T,
                                   solve=solve_max_iou(self.config.iou_threshold))], len(t), len(det_xywh))
        det_of_track = matching.det_of_track
        matched = np.flatnonzero(det_of_track >= 0)
        if len(matched):
            z = _SPACE.measure(det_xywh[det_of_track[matched]])
            t.mean[matched], t.cov[matched] = kalman.update(t.mean[matched], t.cov[matched], z, _SPACE.H, _SPACE.R)
            t.misses[matched] = 0
            t.hits[matched] += 1
        new = np.flatnonzero(matching.free)
        if len(new):
            t.add(*_SPACE.initial(_SPACE.measure(det_xywh[new])))
            det_of_track = np.concatenate([det_of_track, new])
        out = self._report(det_of_track)
        alive = self._lifecycle.alive(t)
        if not alive.all():
            t.keep(alive)
        return out

    def _predict(self, steps: float) -> np.ndarray:
        """Predict every track; drop those whose box became invalid; return boxes ``(k, 4)``."""
        t = self._tracks
        if not len(t):
            return np.zeros((0, 4))
        t.mean, t.cov = _SPACE.predict(t.mean, t.cov, steps)
        t.hits[t.misses > 0] = 0
        t.age()
        boxes = _SPACE.box(t.mean)
        valid = np.isfinite(boxes).all(axis=1)
        if not valid.all():
            t.keep(valid)
            boxes = boxes[valid]
        return boxes

    def _report(self, det_of_track: np.ndarray) -> Tracks:
        t, min_hits = self._tracks, self.config.min_hits
        shown = (t.misses < 1) & ((t.hits >= min_hits) | (self._frame_count <= min_hits))
        idx = np.flatnonzero(shown)
        confirmed = t.hits[idx] >= min_hits
        return Tracks(t.ids[idx], np.where(confirmed, 1, 0), xywh=_SPACE.box(t.mean[idx]),
                      velocity=t.mean[idx, 4:6] / self._clock.interval, detection_index=det_of_track[idx])
