"""The scalar, visit-only-what-is-needed paths of the self-calibration statistics give what the whole-array
forms give (kept here as oracles), and the cached coasting table follows every new count."""

from __future__ import annotations

import numpy as np

from lookalike.trackers.parts.self_calibration import _Z, MissReturns, ScoreBands, ScoreCalibration


def plain_threshold(bands: ScoreBands, ratio: float, min_count: int) -> float:
    judged = bands.seen >= min_count
    if not judged.any():
        return 1.0
    n = np.maximum(bands.seen, 1)
    rate = np.where(judged, bands.kept / n, 0.0)
    low = (rate + _Z**2 / (2 * n) - _Z * np.sqrt(rate * (1 - rate) / n + _Z**2 / (4 * n * n))) / (1 + _Z**2 / n)
    b = int(np.flatnonzero(judged)[-1])
    while b > 0 and judged[b - 1] and low[b - 1] >= ratio * rate.max():
        b -= 1
    return b / bands.bands


def plain_likely_present(m: MissReturns, missed: np.ndarray, share: float, min_count: int) -> np.ndarray:
    resolved = m.returned + m.ended
    ok = (resolved >= min_count) & (m.returned >= share * resolved)
    ok[0] = True
    ok = np.logical_and.accumulate(ok)
    ok[0] = False
    out = np.zeros(len(missed), dtype=bool)
    inside = (missed > 0) & (missed <= m.longest)
    out[inside] = ok[missed[inside]]
    return out


def test_score_band_threshold_equals_the_whole_array_form() -> None:
    rng = np.random.default_rng(0)
    for _ in range(300):
        bands = ScoreBands(10)
        for _ in range(int(rng.integers(1, 30))):
            score = rng.beta(2, 1, int(rng.integers(0, 40)))
            bands.add(score, np.flatnonzero(rng.random(len(score)) < score))
        for ratio in (0.0, 0.3, 0.5, 0.8, 1.0):
            for min_count in (0, 1, 10, 50):
                assert bands.threshold(ratio, min_count) == plain_threshold(bands, ratio, min_count)


def test_likely_present_follows_every_new_count() -> None:
    rng = np.random.default_rng(1)
    m = MissReturns(longest=6)
    missed = np.arange(-1, 9)
    for _ in range(200):
        if rng.random() < 0.5:
            m.came_back(rng.integers(0, 9, int(rng.integers(0, 4))))
        else:
            m.died(rng.integers(0, 9, int(rng.integers(0, 4))))
        for share, min_count in ((0.5, 3), (0.8, 1)):
            assert np.array_equal(m.likely_present(missed, share, min_count),
                                  plain_likely_present(m, missed, share, min_count))


def plain_decide(cal: ScoreCalibration, clutter_share: float | None) -> tuple[float, float, float]:
    high, birth = cal.high_score, cal.birth_score
    if cal.high_match_ratio is not None:
        high = min(high, plain_threshold(cal.bands, cal.high_match_ratio, cal.calib_min_count))
    tentative = 1.0
    cum = np.cumsum(cal.histogram)
    if cum[-1]:
        def edge(q: float) -> float:
            return int(np.searchsorted(cum, q * cum[-1], side="left")) / cal.bins
        if cal.high_quantile is not None:
            high = min(high, edge(cal.high_quantile))
        if cal.birth_quantile is not None:
            birth = min(birth, edge(cal.birth_quantile))
        if cal.clutter_factor is not None:
            q = 0.5 if clutter_share is None else max(cal.clutter_factor * clutter_share, cal.clutter_floor)
            birth = min(birth, edge(min(q, 0.5)))
        if cal.tentative_quantile is not None:
            tentative = edge(cal.tentative_quantile)
    high = min(high, birth)
    return high, birth, min(high, tentative)


def test_decide_equals_one_search_per_quantile() -> None:
    rng = np.random.default_rng(2)
    cal = ScoreCalibration(0.9, 0.95, high_quantile=0.3, birth_quantile=0.6, tentative_quantile=0.1,
                           high_match_ratio=0.5, calib_min_count=20, clutter_factor=2.0)
    assert cal.decide(None) == plain_decide(cal, None)
    for _ in range(100):
        score = rng.beta(2, 1, int(rng.integers(0, 20)))
        cal.observe_scores(score)
        cal.observe_continued(score, np.flatnonzero(rng.random(len(score)) < score))
        for share in (None, 0.0, 0.2, 0.4):
            assert cal.decide(share) == plain_decide(cal, share)
