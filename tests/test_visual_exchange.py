"""The visual exchange detector: which two agents hold each other's robots, from visual headings over frames."""

import numpy as np
import pytest

from lookalike.trackers.set.visual_exchange import VisualExchange, take_pairs

DT = 1 / 30


def feed(detector: VisualExchange, frames: int, visual, reported, age=(0.0, 0.0), seed: int = 0) -> list:
    """``frames`` frames of two agents each holding one detection (agent i holds detection i) whose visual headings
    are ``visual`` plus the classifier's noise; the pairs found, per frame."""
    rng = np.random.default_rng(seed)
    found = []
    for _ in range(frames):
        seen = np.asarray(visual, dtype=float) + rng.normal(0.0, 0.28, 2)
        found.append(detector.update(np.array([0, 1]), seen, np.asarray(reported, dtype=float),
                                     np.asarray(age, dtype=float), DT))
    return found


def test_detections_that_fit_each_others_reports_make_an_exchange_after_enough_frames():
    detector = VisualExchange(2, threshold=6.0)
    found = feed(detector, 90, visual=[0.2, 0.0], reported=[0.0, 0.2])  # robots 0.2 rad apart, ids exchanged
    first = next(k for k, pairs in enumerate(found) if pairs)
    assert found[first] == [(0, 1)]
    assert first > 2  # one frame is not enough: the evidence is gathered
    assert detector.evidence[0, 1] < 6.0  # and starts again after the exchange


def test_detections_that_fit_their_own_reports_keep_the_evidence_at_zero():
    detector = VisualExchange(2, threshold=6.0)
    assert not any(feed(detector, 300, visual=[0.0, 0.5], reported=[0.0, 0.5]))
    assert detector.evidence.max() < 6.0


def test_robots_heading_alike_give_no_exchange_either_way():
    """Two robots 0.02 rad apart: a frame says almost nothing, and the decay keeps chance from adding up."""
    for visual in ([0.0, 0.02], [0.02, 0.0]):
        detector = VisualExchange(2, threshold=6.0, memory_s=1.0)
        assert not any(feed(detector, 600, visual=visual, reported=[0.0, 0.02], seed=3))


def test_a_flipped_heading_counts_little():
    detector = VisualExchange(2, threshold=4.0)
    pairs = detector.update(np.array([0, 1]), np.array([np.pi, np.pi + 3.0]), np.array([0.0, 3.0]),
                            np.zeros(2), DT)  # both detections turned front to back at once
    assert pairs == [] and detector.evidence[0, 1] == pytest.approx(1.5)  # at most max_step in one frame


def test_missing_reports_and_agents_without_a_detection_take_no_part():
    detector = VisualExchange(3, threshold=1.0, fresh_s=0.5)
    reported = np.array([0.0, 0.5, np.nan])
    for held, age in ((np.array([0, -1, 1]), np.zeros(3)),  # agent 1 holds nothing, agent 2 never reported
                      (np.array([0, 1, 2]), np.array([0.0, np.nan, 0.0]))):
        assert detector.update(held, np.array([0.5, 0.0, 0.0]), reported, age, DT) == []
    assert detector.evidence.max() == 0.0


def test_a_silent_agent_takes_part_and_the_reporting_one_carries_the_evidence():
    """Agent 1 went silent 2 s ago while still reporting robot 0's heading (ids exchanged, then restored while it
    was silent); agent 0 reports its robot again. Agent 0's fresh report fits agent 1's detection, not its own."""
    detector = VisualExchange(2, threshold=6.0)
    assert [(0, 1)] in feed(detector, 90, visual=[1.0, 0.0], reported=[0.0, 0.0], age=(0.05, 2.0))


def test_a_silent_agent_whose_robot_may_have_turned_gives_no_exchange_alone():
    """Agent 1's old report no longer fits its detection (its robot turned while silent) while agent 0's fresh report
    fits its own: the widened noise keeps that from looking like an exchange."""
    detector = VisualExchange(2, threshold=6.0)
    assert not any(feed(detector, 300, visual=[0.0, 1.5], reported=[0.0, 0.5], age=(0.05, 3.0)))


def test_a_pairs_scale_lowers_its_threshold_only():
    """Three agents; 0 and 1 hold each other's robots. With the pair's threshold scaled by 0.25 the exchange comes
    sooner; a scale on another pair changes nothing."""
    def first_exchange(scale) -> int:
        detector, rng = VisualExchange(3, threshold=8.0), np.random.default_rng(4)
        for k in range(300):
            seen = np.array([0.3, 0.0, 2.0]) + rng.normal(0.0, 0.28, 3)
            if detector.update(np.arange(3), seen, np.array([0.0, 0.3, 2.0]), np.zeros(3), DT, scale):
                return k
        return 300

    other = np.ones((3, 3))
    other[0, 2] = other[2, 0] = 0.25
    mine = np.ones((3, 3))
    mine[0, 1] = mine[1, 0] = 0.25
    plain = first_exchange(None)
    assert first_exchange(other) == plain < 300
    assert first_exchange(mine) < plain


def test_take_pairs_with_one_threshold_per_pair():
    evidence = np.array([[0.0, 5.0, 3.0], [5.0, 0.0, 0.0], [3.0, 0.0, 0.0]])
    threshold = np.full((3, 3), 6.0)
    threshold[0, 2] = threshold[2, 0] = 2.0
    assert take_pairs(evidence.copy(), threshold) == [(0, 2)]  # only (0, 2) passes its own threshold
    assert take_pairs(evidence.copy(), 4.0) == [(0, 1)]


@pytest.mark.parametrize("kwargs", [dict(threshold=0.0), dict(threshold=1.0, memory_s=0.0),
                                    dict(threshold=1.0, stale_rad_s=0.0),
                                    dict(threshold=1.0, noise_rad=-0.1), dict(threshold=1.0, max_step=0.0),
                                    dict(threshold=1.0, flip_prob=0.6,
                                                                              outlier_prob=0.5)])
def test_bad_settings_are_refused(kwargs):
    with pytest.raises(ValueError, match="VisualExchange"):
        VisualExchange(2, **kwargs)
