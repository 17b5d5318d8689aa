"""boxtrack's birth threshold follows the detector's clutter (issue 16): the share of detections that
overlap none of the previous frame's sets the quantile of the scores seen below which nothing starts
a track, so a detector whose every box is a target (the pigs) starts tracks on its ordinary scores
and one with much flickering clutter (MOT15's Faster R-CNN) keeps a high birth threshold."""

from __future__ import annotations

import numpy as np

from lookalike.trackers import make_tracker
from lookalike.trackers.parts.clutter import ClutterShare
from lookalike.types import Detections, Frame

FPS = 10.0


def _targets(k: int, n: int = 6) -> np.ndarray:
    """``(n, 4)`` boxes of ``n`` targets 40×80 px moving 3 px/frame, rows 150 px apart."""
    return np.array([[50.0 + 3.0 * k, 50.0 + 150.0 * r, 40.0, 80.0] for r in range(n)])


def _flicker(rng: np.random.Generator, n: int) -> np.ndarray:
    return np.column_stack([rng.uniform(1200, 3000, n), rng.uniform(0, 2000, n), np.full(n, 40.0), np.full(n, 80.0)])


def test_clutter_share_counts_boxes_with_no_overlap_in_the_previous_frame() -> None:
    rng = np.random.default_rng(0)
    share = ClutterShare(min_iou=0.5, min_count=50)
    for k in range(20):
        share.observe(_targets(k))
    assert share.share == 0.0
    noisy = ClutterShare(min_iou=0.5, min_count=50)
    for k in range(20):
        noisy.observe(np.vstack([_targets(k), _flicker(rng, 6)]))
    assert noisy.share is not None and 0.45 <= noisy.share <= 0.55
    assert ClutterShare(min_count=1000).share is None  # nothing judged yet


def _birth(tracker) -> float:
    return float(tracker._calibration.decide(tracker._clutter.share)[1])


def test_a_clutter_free_detector_gets_a_low_birth_threshold() -> None:
    rng = np.random.default_rng(1)
    tracker = make_tracker("boxtrack")
    for k in range(60):  # every box a target, scored uniformly in [0.6, 1]
        tracker.update(Frame(index=k, time=k / FPS, detections=Detections(
            xywh=_targets(k), score=rng.uniform(0.6, 1.0, 6))))
    assert _birth(tracker) <= 0.7  # the 10% quantile: 0.64
    # a new target scored 0.75 throughout now starts a track, and is reported once confirmed
    ids = set()
    for k in range(60, 70):
        boxes = np.vstack([_targets(k), [[700.0, 50.0, 40.0, 80.0]]])
        out = tracker.update(Frame(index=k, time=k / FPS, detections=Detections(
            xywh=boxes, score=np.append(rng.uniform(0.6, 1.0, 6), 0.75))))
        ids |= {s.track_id for s in out if s.detection_index == 6}
    assert len(ids) == 1
    off = make_tracker("boxtrack", clutter_factor=None)
    for k in range(60):
        dets = Detections(xywh=_targets(k), score=rng.uniform(0.6, 1.0, 6))
        off.update(Frame(index=k, time=k / FPS, detections=dets))
    assert _birth(off) == 0.95  # the absolute threshold alone


def test_flickering_clutter_keeps_the_birth_threshold_high() -> None:
    rng = np.random.default_rng(2)
    tracker = make_tracker("boxtrack")
    for k in range(60):  # targets scored 0.95-1, as many flickering false boxes scored 0.5-0.95
        boxes = np.vstack([_targets(k), _flicker(rng, 6)])
        scores = np.concatenate([rng.uniform(0.95, 1.0, 6), rng.uniform(0.5, 0.95, 6)])
        tracker.update(Frame(index=k, time=k / FPS, detections=Detections(xywh=boxes, score=scores)))
    assert _birth(tracker) >= 0.94  # clutter share 0.5: the birth quantile is the whole clutter band
