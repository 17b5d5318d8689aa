"""boxtrack's self-calibration on the sequence's own tracks (issue #10): the high score threshold
follows how often each score band continues confirmed tracks (``high_match_ratio``), and a missed
track is reported at its prediction while tracks missed that long usually came back
(the constant ``COAST_REPORT_PROB``; issue 16 made it and the evidence counts constants)."""

from __future__ import annotations

from unittest.mock import patch

import numpy as np
import pytest

from lookalike.trackers import boxtrack_config, make_tracker
from lookalike.trackers.boxtrack_config import CALIB_MIN_COUNT
from lookalike.trackers.parts.self_calibration import MissReturns, ScoreBands
from lookalike.types import Detections, Frame

FPS = 10.0
ROWS = 6


def _truth(k: int) -> np.ndarray:
    """``(ROWS, 4)`` boxes in frame ``k``: 40×80 px targets moving 3 px/frame right, rows 150 px apart."""
    return np.array([[50.0 + 3.0 * k, 50.0 + 150.0 * r, 40.0, 80.0] for r in range(ROWS)])


def _frame(k: int, boxes: np.ndarray, scores: np.ndarray) -> Frame:
    return Frame(index=k, time=k / FPS, detections=Detections(xywh=boxes.reshape(-1, 4), score=scores))


def _high(tracker) -> float:
    """The high threshold the tracker's score bands support so far."""
    return tracker._calibration.bands.threshold(tracker.config.high_match_ratio, CALIB_MIN_COUNT)


def _clutter(rng: np.random.Generator, n: int) -> np.ndarray:
    """``n`` false boxes scattered far right of the targets (they never overlap one another for long)."""
    return np.column_stack([rng.uniform(1200, 3000, n), rng.uniform(0, 2000, n), np.full(n, 40.0), np.full(n, 80.0)])


def test_high_threshold_falls_when_middling_scores_are_as_reliable_as_top_ones() -> None:
    rng = np.random.default_rng(0)
    tracker = make_tracker("boxtrack")
    for k in range(80):  # every target seen, scored uniformly in [0.6, 1]
        tracker.update(_frame(k, _truth(k), rng.uniform(0.6, 1.0, ROWS)))
    assert _high(tracker) == pytest.approx(0.6)


def test_high_threshold_stays_when_middling_scores_are_clutter() -> None:
    rng = np.random.default_rng(1)
    tracker = make_tracker("boxtrack")
    for k in range(80):  # targets scored 0.9-1; new false boxes scored 0.6-0.9 in every frame
        boxes = np.vstack([_truth(k), _clutter(rng, 4)])
        scores = np.concatenate([rng.uniform(0.9, 1.0, ROWS), rng.uniform(0.6, 0.9, 4)])
        tracker.update(_frame(k, boxes, scores))
    assert _high(tracker) >= 0.9


def test_high_match_ratio_off_keeps_the_configured_threshold() -> None:
    rng = np.random.default_rng(0)
    tracker = make_tracker("boxtrack", high_match_ratio=None)
    for k in range(80):
        tracker.update(_frame(k, _truth(k), rng.uniform(0.6, 1.0, ROWS)))
    assert tracker._calibration.bands.seen.sum() == 0  # nothing counted, so nothing can lower the threshold


def _coast_run(tracker, miss: np.ndarray) -> list[list]:
    """Snapshots per frame of targets missed where ``miss[k, r]``, all scored 0.95."""
    out = []
    for k in range(len(miss)):
        seen = ~miss[k]
        out.append(tracker.update(_frame(k, _truth(k)[seen], np.full(int(seen.sum()), 0.95))))
    return out


def test_short_misses_are_reported_at_the_prediction_once_they_usually_end_in_a_return() -> None:
    rng = np.random.default_rng(2)
    miss = rng.random((200, ROWS)) < 0.15
    miss[:3] = False  # every target confirmed first
    out = _coast_run(make_tracker("boxtrack"), miss)
    late = range(150, 200)  # by then dozens of one-frame misses ended in a return
    coasted = [s for k in late for s in out[k] if s.detection_index == -1]
    missed = [(k, r) for k in late for r in range(ROWS) if miss[k, r] and not miss[k - 1, r]]
    assert len(coasted) >= 0.9 * len(missed) > 0
    for k in late:  # a coasted box keeps its track's id and sits near the missed target
        for s in out[k]:
            if s.detection_index == -1:
                r = int(np.argmin(np.abs(_truth(k)[:, 1] - s.xywh[1])))
                assert miss[k, r] and np.abs(s.xywh[0] - _truth(k)[r, 0]) < 10


def test_misses_that_end_tracks_are_not_reported() -> None:
    tracker = make_tracker("boxtrack", max_age_s=0.2, n_init=1)  # a miss of 3 frames ends a track
    out = []
    for k in range(400):  # a target that vanishes for 5 frames out of every 10, again and again
        boxes = _truth(k)[:1] if k % 10 < 5 else np.zeros((0, 4))
        out.append(tracker.update(_frame(k, boxes, np.full(len(boxes), 0.95))))
    assert not [s for snaps in out for s in snaps if s.detection_index == -1]


def test_score_bands_descend_only_on_enough_evidence() -> None:
    bands = ScoreBands(10)
    assert bands.threshold(0.6, 10) == 1.0  # nothing seen yet
    score = np.repeat([0.95, 0.75, 0.65, 0.55], 20)  # bands 9, 7, 6, 5; band 8 empty
    bands.add(score, np.arange(60))  # every detection of bands 9, 7 and 6 continued a track, none of 5
    assert bands.threshold(0.6, 10) == pytest.approx(0.9)  # the empty band 8 stops the descent
    bands.add(np.full(20, 0.85), np.arange(20))
    assert bands.threshold(0.6, 10) == pytest.approx(0.6)  # band 5 fails the ratio
    assert bands.threshold(0.6, 30) == 1.0  # no band has 30 detections


def test_miss_returns_count_every_shorter_miss() -> None:
    misses = MissReturns(longest=4)
    misses.came_back(np.array([1, 1, 2, 9]))  # a miss of 9 frames counts in lengths 1..4
    misses.died(np.array([3, 0]))  # a track never missed does not count
    assert misses.returned.tolist() == [0, 4, 2, 1, 1] and misses.ended.tolist() == [0, 1, 1, 1, 0]
    # length 1: 4 of 5 back; 2: 2 of 3; 3: 1 of 2
    assert misses.likely_present(np.array([0, 1, 2, 3, 5]), 0.6, 1).tolist() == [False, True, True, False, False]
    assert misses.likely_present(np.array([1, 2]), 0.6, 4).tolist() == [True, False]  # length 2: 3 resolved


@pytest.mark.parametrize("bad", [{"high_match_ratio": 1.5}, {"high_match_ratio": -0.1},
                                 {"calib_min_count": 100}, {"coast_report_prob": 0.7}])
def test_calibration_settings_are_checked(bad: dict) -> None:
    with pytest.raises(ValueError):
        make_tracker("boxtrack", **bad)


def test_recently_seen_tracks_take_detections_before_long_lost_ones() -> None:
    """Target B stands still at x=150 until frame 5, then is gone (its track waits there); target A walks
    right along the same row and, at frame 12, is detected 11 px ahead of its prediction, right on B's
    stale box. Matched all at once, B's stale track takes A's detection; with priority to tracks seen in
    the last frames, A keeps it."""
    def frames():
        for k in range(14):
            boxes = [[100.0 + 3.0 * k + (11.0 if k >= 12 else 0.0), 50.0, 40.0, 80.0]]
            if k <= 5:
                boxes.append([150.0, 50.0, 40.0, 80.0])
            yield _frame(k, np.array(boxes), np.full(len(boxes), 0.95))

    for recent, keeps in ((2, True), (10**9, False)):  # the constant RECENT_FRAMES, and no priority
        with patch.object(boxtrack_config, "RECENT_FRAMES", recent):
            tracker = make_tracker("boxtrack")
            ids = [{s.detection_index: s.track_id for s in tracker.update(f)} for f in frames()]
        assert ids[0] == {0: 1, 1: 2}
        assert (ids[12][0] == 1) is keeps
