"""boxtrack's score thresholds relative to the sequence's own scores (issue #10): the high threshold
follows the 0.35-quantile of the scores seen (the constant ``HIGH_QUANTILE``), so a detector that
scores lower gets a lower one; checked against the absolute thresholds alone."""

from __future__ import annotations

from unittest.mock import patch

import numpy as np
import pytest

from lookalike.trackers import boxtrack_config, make_tracker
from lookalike.types import Detections, Frame

FPS = 10.0


def _box(k: int, row: int) -> list[float]:
    """Target ``row``'s box in frame ``k``: 40×80 px, moving 3 px/frame to the right, rows 200 px apart."""
    return [50.0 + 3.0 * k, 50.0 + 200.0 * row, 40.0, 80.0]


def _run(tracker, frames: list[tuple[list[list[float]], list[float]]]) -> list[dict[int, int]]:
    """Per frame ``{detection index: track id}`` of the reported tracks."""
    out = []
    for k, (boxes, scores) in enumerate(frames):
        dets = Detections(xywh=np.array(boxes, dtype=float).reshape(-1, 4), score=np.array(scores, dtype=float))
        snaps = tracker.update(Frame(index=k, time=k / FPS, detections=dets))
        out.append({s.detection_index: s.track_id for s in snaps})
    return out


def _lower_scored_returns(n_frames: int = 30, gap: range = range(10, 13)) -> list:
    """Four targets always scored 0.95 (detections 0-3) and two (detections 4, 5 when present) that
    score 0.97 in the first frame (born and confirmed there), then 0.7, and are missed during ``gap``;
    plus a still false box far away scored 0.7 in every frame (the last detection)."""
    frames = []
    for k in range(n_frames):
        boxes = [_box(k, r) for r in range(4)]
        scores = [0.95] * 4
        if k not in gap:
            boxes += [_box(k, 4), _box(k, 5)]
            scores += [0.97 if k == 0 else 0.7] * 2
        frames.append((boxes + [[1500.0, 1500.0, 40.0, 80.0]], scores + [0.7]))
    return frames


def test_high_quantile_recovers_targets_of_a_lower_scoring_detector() -> None:
    frames = _lower_scored_returns()
    # running scores: ~37-43% at 0.7, the rest 0.95 -> median 0.95 (birth 0.95, high 0.9),
    # 0.35-quantile 0.7
    # (births by the absolute birth_score: a false box standing still is no flicker, so the clutter
    # share would let it start a track; tests/test_boxtrack_clutter.py covers births)
    adaptive = _run(make_tracker("boxtrack", clutter_factor=None), frames)
    with patch.object(boxtrack_config, "HIGH_QUANTILE", 1.0):  # the absolute thresholds only
        absolute = _run(make_tracker("boxtrack", clutter_factor=None), frames)
    first_ids = adaptive[0][4], adaptive[0][5]
    for k in range(13, 30):
        # a 0.7 detection is "high" for this detector: the lost tracks are re-identified by motion
        assert (adaptive[k].get(4), adaptive[k].get(5)) == first_ids
        # with absolute thresholds it is only a low-score detection: it continues no lost track and
        # starts none (birth 0.95), so those targets are never reported again
        assert 4 not in absolute[k] and 5 not in absolute[k]
    for k in range(30):  # the always-confident targets are tracked alike; the false box never
        assert [adaptive[k][i] for i in range(4)] == [absolute[k][i] for i in range(4)] == [1, 2, 3, 4]
        assert len(frames[k][1]) - 1 not in adaptive[k]


def test_quantile_thresholds_never_exceed_the_absolute_ones() -> None:
    # every score 0.99: quantiles lie above the absolute thresholds, which then apply unchanged
    frames = [([_box(k, r) for r in range(2)], [0.99, 0.99]) for k in range(15)]
    out = _run(make_tracker("boxtrack", clutter_factor=0.2), frames)
    with patch.object(boxtrack_config, "HIGH_QUANTILE", 1.0):
        assert out == _run(make_tracker("boxtrack", clutter_factor=None), frames)
    assert all(out[k] == {0: 1, 1: 2} for k in range(15))


@pytest.mark.parametrize("name", ["high_match_ratio"])
def test_quantiles_outside_unit_interval_are_rejected(name: str) -> None:
    with pytest.raises(ValueError, match=name):
        make_tracker("boxtrack", **{name: 1.5})
    with pytest.raises(ValueError, match=name):
        make_tracker("boxtrack", **{name: -0.1})
