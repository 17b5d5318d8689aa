"""BoxTrack's configuration: its public parameters with defaults and descriptions, and its fixed constants. Where the
defaults come from: docs/trackers/boxtrack.md."""

from __future__ import annotations

from dataclasses import dataclass

from lookalike.trackers.base import COUNT, POSITIVE, UNIT, check_params, param

# Fixed constants (how each was chosen: research/notes/tuning.md, "Which parameters earn their place").
LOW_IOU = 0.5  # minimum IoU of a low-score detection with a track updated in the previous frame
RECENT_FRAMES = 2  # confirmed tracks missed at most this many frames take confident detections first
COAST_S = 0.5  # seconds a lost track keeps extrapolating its velocity (then waits where it was seen)
HIGH_QUANTILE = 0.35  # the high threshold is lowered to this quantile of the scores seen so far
COAST_REPORT_PROB = 0.7  # missed tracks are reported at their prediction while this share came back
CALIB_MIN_COUNT = 100  # detections a score band needs before the self-calibration judges it
COAST_MIN_COUNT = 30  # resolved misses of a length before the coast report judges that length
POS_NOISE = 1 / 20  # position (and measurement) noise per frame, as a fraction of the box size
VEL_NOISE = 1 / 160  # velocity noise per frame, as a fraction of the box size (before MotionFit's scale)
REID_DISTANCE = 0.5  # re-identification gate: centre distance in track heights x sqrt(MotionFit's scale)
CLUTTER_FLOOR = 0.1  # the birth threshold is never below this quantile of the scores seen
FIT_BATCH = 30  # matched confirmed tracks per update of the process-noise scale (MotionFit)
CLUTTER_IOU = 0.5  # a detection overlapping a previous-frame detection this much is not clutter
CLUTTER_MIN_COUNT = 10  # detections judged before the clutter share is used
CLOSED_GATE_GROWTH = 1.0  # closed set: recovery gate grows at least this many sizes per second lost
CLOSED_SCALE = 3.0  # closed set: a recovered detection's sqrt(area) within this factor of its slot's


@dataclass(frozen=True)
class BoxTrackConfig:
    """BoxTrack's parameters (pixels, seconds, scores in [0, 1]); validated on construction."""

    high_score: float = param(0.9, "ceiling of the high threshold (detections scoring at least the threshold are "
                                   "matched first to confirmed tracks)", range=UNIT)
    low_score: float = param(0.1, "detections below this are ignored", range=UNIT)
    birth_score: float = param(0.95, "ceiling of the birth threshold (detections scoring at least the "
                                     "threshold may start tracks)", range=UNIT)
    clutter_factor: float | None = param(
        2.0, "if set, birth_score is lowered to the quantile of the scores seen so far equal to this times the "
             "share of detections overlapping none of the previous frame's (at least the 0.1-quantile)", range=POSITIVE)
    high_match_ratio: float | None = param(
        0.6, "if set, high_score is lowered to the lowest 0.1-wide score bin from which every bin up continues "
             "confirmed tracks at least this fraction as often as the best bin", range=UNIT)
    match_iou: float = param(0.3, "minimum IoU of a confident detection with a confirmed or tentative track",
                             range=UNIT)
    n_init: int = param(2, "consecutive hits that confirm a track", range=COUNT)
    max_age_s: float = param(2.0, "seconds a confirmed track survives without a detection (closed set: "
                                  "before its slot may be re-filled)", range=POSITIVE)
    reid_scale: float = param(1.5, "largest width/height ratio between a lost track and its detection", range=(1, None))
    max_targets: int | None = param(None, "known number of targets (closed set), None when open", range=COUNT)
    closed_distance: float = param(
        8.0, "closed set: centre distance (slot sizes, sqrt(w*h)) gating recovery; grows with the time lost",
        range=POSITIVE)
    frame_interval_s: float | None = param(None, "seconds per frame (None: the smallest step seen)", range=POSITIVE)

    def __post_init__(self) -> None:
        check_params(self)
        if self.low_score > self.high_score:
            raise ValueError(f"tracker 'boxtrack': low_score={self.low_score} exceeds high_score={self.high_score}")
