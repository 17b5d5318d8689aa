"""BoxTrack's configuration: every parameter with its default and description, and its validation.

Where the defaults come from is docs/trackers/boxtrack.md.
"""

from __future__ import annotations

from dataclasses import dataclass

from lookalike.trackers.base import check_positive, param

REPORTS = ("detection", "filtered")


@dataclass(frozen=True)
class BoxTrackConfig:
    """BoxTrack's parameters (pixels, seconds, scores in [0, 1]); validated on construction."""

    high_score: float = param(0.9, "detections scoring at least this are matched first and may start tracks")
    low_score: float = param(0.1, "detections below this are ignored")
    birth_score: float = param(0.95, "minimum score of a detection that starts a track")
    match_iou: float = param(0.3, "minimum IoU of a confident detection with a confirmed track")
    low_iou: float = param(0.5, "minimum IoU of a low-score detection with a tracked track")
    tentative_iou: float = param(0.3, "minimum IoU of a detection with a tentative track")
    n_init: int = param(3, "consecutive hits that confirm a track")
    max_age_s: float = param(1.0, "seconds a confirmed track survives without a detection")
    coast_s: float = param(0.5, "seconds a lost track keeps extrapolating its velocity")
    reid_distance: float = param(0.5, "centre distance (track heights) that re-identifies a lost track")
    reid_growth: float = param(0.0, "added to reid_distance per second lost (track heights)")
    reid_scale: float = param(1.5, "largest width/height ratio between a lost track and its detection")
    max_targets: int | None = param(None, "known number of targets (closed set), None when open")
    closed_distance: float = param(4.0, "closed set: centre distance (track heights) gating recovery")
    recent_frames: int | None = param(
        2, "confirmed tracks missed at most this many frames take confident detections before longer-lost "
           "ones (None: all at once)")
    pos_noise: float = param(1 / 20, "position noise per frame, as a fraction of the box size")
    vel_noise: float = param(1 / 160, "velocity noise per frame, as a fraction of the box size")
    high_quantile: float | None = param(
        0.35, "if set, high_score is lowered to this quantile of the scores seen so far")
    birth_quantile: float | None = param(
        0.5, "if set, birth_score is lowered to this quantile of the scores seen so far")
    tentative_quantile: float | None = param(
        None, "if set, tentative tracks also take detections scoring at least this quantile of the scores seen")
    high_match_ratio: float | None = param(
        0.6, "if set, high_score is lowered to the lowest 0.1-wide score bin from which every bin up continues "
             "confirmed tracks at least this fraction as often as the best bin")
    coast_report_prob: float | None = param(
        0.7, "if set, a confirmed track missed for j frames is reported at its predicted box while this "
             "sequence's tracks missed j frames came back at least this often")
    calib_min_count: int = param(100, "detections a score bin needs before high_match_ratio judges it")
    coast_min_count: int = param(30, "tracks missed j frames (come back or died) before coast_report_prob judges j")
    report: str = param("filtered", "reported box: 'detection' or 'filtered'")
    frame_interval_s: float | None = param(None, "seconds per frame (None: the smallest step seen)")

    def __post_init__(self) -> None:
        check_positive(self, "high_score", "low_score", "birth_score", "match_iou", "low_iou",
                       "tentative_iou", "coast_s", "reid_distance", "reid_growth", "recent_frames",
                       allow_zero=True)
        check_positive(self, "n_init", "max_age_s", "reid_scale", "max_targets", "closed_distance",
                       "pos_noise", "vel_noise", "frame_interval_s", "calib_min_count",
                       "coast_min_count")
        for name in ("high_quantile", "birth_quantile", "tentative_quantile", "high_match_ratio",
                     "coast_report_prob"):
            q = getattr(self, name)
            if q is not None and not 0 <= q <= 1:
                raise ValueError(f"BoxTrack.Config.{name} must be in [0, 1], got {q}")
        if self.low_score > self.high_score:
            raise ValueError(f"BoxTrack.Config.low_score ({self.low_score}) exceeds high_score ({self.high_score})")
        if self.reid_scale < 1:
            raise ValueError(f"BoxTrack.Config.reid_scale must be >= 1, got {self.reid_scale}")
        if self.report not in REPORTS:
            raise ValueError(f"BoxTrack.Config.report must be one of {REPORTS}, got {self.report!r}")
