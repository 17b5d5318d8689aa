"""Deep SORT (Wojke et al., 2017) with any appearance feature (L2-normalised ``feature`` rows; pixels, aspect ``w/h``).

Each frame: predict; matching cascade over confirmed tracks (most recently seen first) on the minimum cosine distance
to the track's gallery, gated by ``max_cosine_distance`` and the chi-square gate; ``1 - IoU`` fallback for tentative
tracks and those missed one frame; confirm after ``n_init`` hits, delete tentative tracks at their first miss and
confirmed ones after ``max_age`` frames. Defaults: docs/trackers/deepsort.md."""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from lookalike.association.appearance import FeatureGallery, require_features
from lookalike.association.stages import Stage, cascade, run_plan
from lookalike.geometry.boxes import iou_matrix
from lookalike.motion import kalman
from lookalike.motion.gating import chi2_gate
from lookalike.motion.spaces import BoxXYAH, xyah_to_xywh, xywh_to_xyah
from lookalike.trackers.base import COUNT, NEEDS_APPEARANCE, POSITIVE, PROBABILITY, Range, check_params, param
from lookalike.trackers.parts.lifecycle import Lifecycle
from lookalike.trackers.parts.table import TrackTable
from lookalike.trackers.parts.timing import FrameClock
from lookalike.trackers.registry import register_tracker
from lookalike.types import Frame, Tracks, TrackStatus

__all__ = ["DeepSort", "require_features", "xyah_to_xywh", "xywh_to_xyah"]


@register_tracker("deepsort")
class DeepSort:
    """Deep SORT style tracking on boxes (pixels) and appearance features."""

    needs: ClassVar[str] = NEEDS_APPEARANCE

    @dataclass(frozen=True)
    class Config:
        max_cosine_distance: float = param(0.2, "largest accepted gallery cosine distance (calibrated)",
                                           range=Range(0, 2, low_open=True))
        max_iou_distance: float = param(0.7, "largest accepted 1 - IoU in the IoU fallback",
                                        range=Range(0, 1, low_open=True))
        max_age: int = param(30, "frames a confirmed track survives without a match", range=COUNT)
        n_init: int = param(3, "consecutive hits that confirm a track", range=COUNT)
        gallery_size: int = param(100, "features kept per track", range=COUNT)
        gate_probability: float = param(0.95, "chi-square probability of the Mahalanobis gate", range=PROBABILITY)
        position_std_frac: float = param(1 / 20, "position noise as a fraction of the box height", range=POSITIVE)
        velocity_std_frac: float = param(1 / 160, "velocity noise (per frame) as a fraction of the height",
                                         range=POSITIVE)
        aspect_std: float = param(1e-2, "process noise of the aspect ratio per frame", range=POSITIVE)
        frame_interval_s: float | None = param(None, "seconds per frame (None: the smallest step seen)", range=POSITIVE)

        def __post_init__(self) -> None:
            check_params(self)

    def __init__(self, config: DeepSort.Config | None = None) -> None:
        self.config = cfg = config or DeepSort.Config()
        self._gate = chi2_gate(4, cfg.gate_probability)
        self._space = BoxXYAH(cfg.position_std_frac, cfg.velocity_std_frac, cfg.aspect_std)
        self._lifecycle = Lifecycle(n_init=cfg.n_init, tentative_max_misses=1, max_misses=cfg.max_age)
        self.reset()

    def reset(self) -> None:
        """Forget every track; ids restart at 1."""
        self._tracks = TrackTable(8)  # hits: every hit so far (a miss deletes a tentative track)
        self._gallery = FeatureGallery(self.config.gallery_size)
        self._clock = FrameClock(self.config.frame_interval_s)

    def update(self, frame: Frame) -> Tracks:
        """Advance all tracks to ``frame`` and match its detections (which need ``feature``)."""
        cfg, t, space = self.config, self._tracks, self._space
        det = frame.detections
        det.require_sizes("deepsort")
        features = require_features(det, "deepsort")
        self._gallery.check(features)  # before any change: a refused frame leaves the tracks as they were
        steps = self._clock.steps(frame.time)
        if len(t):
            t.mean, t.cov = space.predict(t.mean, t.cov, steps)
            t.age()
        z = space.measure(det.xywh)
        every = np.ones(len(det), dtype=bool)

        def appearance(rows: np.ndarray, cols: np.ndarray) -> np.ndarray:
            cost = self._gallery.min_distance(t.ids[rows], features[cols])
            maha = kalman.gating_distance(t.mean[rows], t.cov[rows], z[cols], space.H, space.R(t.mean[rows, 3]))
            cost[maha > self._gate] = np.inf
            return cost

        fallback = np.concatenate([np.flatnonzero(~t.confirmed), np.flatnonzero(t.confirmed & (t.misses == 1))])
        matching = run_plan(
            cascade(t.misses, cfg.max_age, t.confirmed, every, appearance, cfg.max_cosine_distance)
            + [Stage(fallback, every, lambda r, c: 1.0 - iou_matrix(space.box(t.mean[r]), det.xywh[c]),
                     cfg.max_iou_distance, name="IoU fallback")],
            len(t), len(det))
        det_of_track = matching.det_of_track
        rows = np.flatnonzero(det_of_track >= 0)
        if len(rows):
            d = det_of_track[rows]
            t.mean[rows], t.cov[rows] = kalman.update(t.mean[rows], t.cov[rows], z[d], space.H,
                                                      space.R(t.mean[rows, 3]))
            t.hits[rows] += 1
            t.misses[rows] = 0
            self._lifecycle.confirm(t, rows)
            for row, feat in zip(rows, features[d]):
                self._gallery.add(int(t.ids[row]), feat)
        keep = self._lifecycle.alive(t)
        for tid in t.ids[~keep]:
            self._gallery.remove(int(tid))
        t.keep(keep)
        det_of_track = det_of_track[keep]
        new = np.flatnonzero(matching.free)
        if len(new):
            mean, cov = space.initial(z[new])
            born = t.add(mean, cov, hits=1, confirmed=self._lifecycle.born_confirmed())
            for tid, feat in zip(t.ids[born], features[new]):
                self._gallery.add(int(tid), feat)
            det_of_track = np.concatenate([det_of_track, new])
        return self._report(det_of_track)

    def _report(self, det_of_track: np.ndarray) -> Tracks:
        t = self._tracks
        idx = np.flatnonzero(t.confirmed & (t.misses == 0))
        return Tracks(t.ids[idx], TrackStatus.CONFIRMED, xywh=self._space.box(t.mean[idx]),
                      velocity=t.mean[idx, 4:6] / self._clock.interval, detection_index=det_of_track[idx])
