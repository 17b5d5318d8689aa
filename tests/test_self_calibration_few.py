"""ScoreCalibration counts a few scores a frame as Python numbers: the same counts and thresholds as
its array path."""

import numpy as np
import pytest

from lookalike.trackers.parts import self_calibration
from lookalike.trackers.parts.self_calibration import ScoreCalibration


def _run(frames: list[np.ndarray], few: int, monkeypatch: pytest.MonkeyPatch) -> tuple:
    monkeypatch.setattr(self_calibration, "_FEW", few)
    cal = ScoreCalibration(0.6, 0.7, high_quantile=0.3, high_match_ratio=0.8, calib_min_count=20,
                           clutter_factor=1.0)
    decided = []
    for k, score in enumerate(frames):
        cal.observe_scores(score)
        cal.observe_continued(score, np.arange(0, len(score), 1 + k % 3))
        decided.append(cal.decide(None if k < 5 else 0.1 + 0.01 * k))
    return cal.histogram.copy(), cal.bands.seen.copy(), cal.bands.kept.copy(), decided


def test_few_scores_path_counts_and_decides_as_the_array_path(monkeypatch: pytest.MonkeyPatch) -> None:
    rng = np.random.default_rng(3)
    frames = [rng.random(rng.integers(0, 14)) for _ in range(60)]
    frames += [np.array([0.0, 1.0, 0.999, 0.1, 0.5]), np.array([1.0]), np.zeros(0)]
    few = _run(frames, 10, monkeypatch)
    plain = _run(frames, -1, monkeypatch)
    for a, b in zip(few[:3], plain[:3]):
        assert np.array_equal(a, b)
    assert few[3] == plain[3]
