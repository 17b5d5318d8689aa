"""SORT (Bewley et al., 2016) as its reference implementation: Kalman filter on ``[u, v, s, r]``, maximum-IoU matching,
reported after ``min_hits`` hits or in the first ``min_hits`` frames (:mod:`lookalike.trackers.parts.sort_tracks`)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from lookalike.trackers.base import COUNT0, POSITIVE, UNIT, check_params, param
from lookalike.trackers.parts.sort_tracks import SortTracks
from lookalike.trackers.parts.timing import FrameClock
from lookalike.trackers.registry import register_tracker
from lookalike.types import Frame, Tracks


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
        self.config = cfg = config or Sort.Config()
        self._tracks = SortTracks(cfg.max_age, cfg.min_hits, cfg.iou_threshold)
        self.reset()

    def reset(self) -> None:
        """Forget every track; ids restart at 1."""
        self._tracks.clear()
        self._clock = FrameClock(self.config.frame_interval_s)

    def update(self, frame: Frame) -> Tracks:
        """Advance all tracks to ``frame`` and match its detections."""
        frame.detections.require_sizes("sort")
        steps = self._clock.steps(frame.time)
        ids, confirmed, xywh, velocity, det_index = self._tracks.step(frame.detections.xywh, steps)
        return Tracks.trusted(ids, confirmed.astype(np.int8), xywh, velocity / self._clock.interval, det_index)
