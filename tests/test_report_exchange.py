"""The report-exchange detector and the set identifier's exchange_llr option."""

import numpy as np
import pytest

from lookalike.bench.experiments import most_seen_pair, swap_reports
from lookalike.learn.report_exchange import ReportExchange
from lookalike.sim import preset, simulate_robots
from lookalike.trackers import make_tracker


def _streams(gap: float, exchange_at: float | None, seconds: float = 10.0, seed: int = 0):
    """Reports of two robots turning slowly, ``gap`` rad apart, 10 Hz, 2° noise; their ids exchanged from
    ``exchange_at`` on (None: never). Yields (agent, t_sent, heading) in send order."""
    rng = np.random.default_rng(seed)
    for k in range(int(seconds * 10)):
        for robot in (0, 1):
            t = 0.1 * k + 0.03 * robot
            heading = 0.3 * np.sin(0.4 * t) + robot * gap + rng.normal(0.0, np.radians(2.0))
            agent = 1 - robot if exchange_at is not None and t >= exchange_at else robot
            yield agent, t, heading


def _firings(det: ReportExchange, reports) -> list[tuple[float, tuple[int, int]]]:
    return [(t, pair) for a, t, h in reports if (pair := det.add(a, t, h)) is not None]


@pytest.mark.parametrize("gap", [0.25, 0.4])
def test_an_exchange_too_small_for_a_report_jump_is_found_soon(gap):
    fired = _firings(ReportExchange(2, threshold=8.0), _streams(gap, exchange_at=5.0))
    assert len(fired) == 1
    t, pair = fired[0]
    assert 5.0 <= t < 6.0 and set(pair) == {0, 1}


def _crossing(seconds: float = 10.0, seed: int = 0, rate: float = 0.5, gap: float = 0.25):
    """Reports of two robots (10 Hz, 2° noise) that from 5 s turn smoothly at ``rate`` rad/s onto each other's
    heading, ``gap`` rad apart: no exchange of ids. Yields (agent, t_sent, heading) in send order."""
    rng = np.random.default_rng(seed)
    for k in range(int(seconds * 10)):
        for robot in (0, 1):
            t = 0.1 * k + 0.03 * robot
            turned = rate * np.clip(t - 5.0, 0.0, gap / rate)
            yield robot, t, (turned if robot == 0 else gap - turned) + rng.normal(0.0, np.radians(2.0))


def test_a_step_gate_tells_an_exchange_from_a_smooth_crossing():
    def detector(step_rad):
        return ReportExchange(2, threshold=8.0, accel_psd=0.03, lag_s=0.3, step_rad=step_rad)

    for seed in (1, 2, 3):  # a model tight enough to take these smooth crossings for exchanges
        assert len(_firings(detector(None), _crossing(seed=seed))) == 1
        assert _firings(detector(0.12), _crossing(seed=seed)) == []
    fired = _firings(detector(0.12), _streams(0.25, exchange_at=5.0))
    assert len(fired) == 1 and 5.0 <= fired[0][0] < 6.0


def test_no_exchange_no_firing_and_a_lone_jump_is_not_an_exchange():
    assert _firings(ReportExchange(2, threshold=8.0), _streams(0.25, exchange_at=None)) == []
    det = ReportExchange(2, threshold=8.0)
    jumped = [(a, t, h - (0.3 if a == 0 and t > 5 else 0.0)) for a, t, h in _streams(0.25, None)]
    assert _firings(det, jumped) == []


def test_a_scale_on_a_pairs_threshold_finds_a_smaller_exchange():
    """Reports 0.12 rad apart exchanged at 5 s: too small for the threshold, found with the pair's threshold halved."""
    def firings(scale):
        det = ReportExchange(2, threshold=8.0, accel_psd=0.03, lag_s=0.3)
        return [(t, pair) for a, t, h in _streams(0.12, exchange_at=5.0, seed=3)
                if (pair := det.add(a, t, h, scale)) is not None]

    assert firings(None) == []
    fired = firings(np.array([0.5, 0.5]))
    assert len(fired) == 1 and 5.0 <= fired[0][0] < 6.0


def test_old_and_nan_reports_are_ignored_and_swap_exchanges_the_tracks():
    det = ReportExchange(2, threshold=8.0)
    for a, t, h in _streams(1.0, None, seconds=2.0):
        det.add(a, t, h)
    before = det.x.copy()
    assert det.add(0, 0.5, 3.0) is None and det.add(0, 5.0, float("nan")) is None
    assert np.array_equal(det.x, before)
    det.swap(0, 1)
    assert np.array_equal(det.x, before[::-1]) and not det.evidence.any()


def test_set_exchanges_memories_at_a_swap_the_report_jump_misses():
    """Analysis seed 63005 (M=3, N=2): the reports swapped back while the two headings are 0.07 rad apart."""
    seq = simulate_robots(preset("m3n2"), 600, 63005)
    truth = seq.true_labels()
    pair = most_seen_pair(truth[150:540], 2)
    frames = swap_reports(list(seq.frames()), 5.0, 15.0, pair)
    runs = {}
    for llr in (None, 8.0):
        tracker = make_tracker("set", n_agents=2, n_slots=3, exchange_llr=llr)  # 8.0: the default
        for f in frames:
            tracker.update(f)
        runs[llr] = tracker.exchanges
    clean = make_tracker("set", n_agents=2, n_slots=3, exchange_llr=8.0)
    for f in seq.frames():
        clean.update(f)
    assert runs[None] == 0 and runs[8.0] >= 1 and clean.exchanges == 0


def test_evidence_decays_with_its_time_constant():
    reports = list(_streams(0.0, None, seconds=8.0))  # two robots heading alike: little evidence either way
    left = {}
    for memory_s in (1.0, None):
        det = ReportExchange(2, threshold=8.0, memory_s=memory_s)
        for a, t, h in reports[:40]:
            det.add(a, t, h)
        det.evidence[0, 1] = 30.0  # one stream's evidence, seconds before the other's
        for a, t, h in reports[40:140]:
            det.add(a, t, h)
        left[memory_s] = det.evidence[0, 1]
    assert left[1.0] < 30.0 * np.exp(-4.0) + 2.0 < left[None]


def test_a_track_silent_for_a_lost_burst_takes_no_part():
    reports = [(a, t, h) for a, t, h in _streams(0.0, None, seconds=6.0) if not (a == 1 and t > 2.0)]
    fired = {}
    for fresh_s in (0.6, None):
        det = ReportExchange(2, threshold=8.0, fresh_s=fresh_s)
        for a, t, h in reports:
            if a == 0 and t > 4.0:  # agent 1 silent for 2 s: its track predicts little
                det.evidence[:] = [[0.0, 20.0], [20.0, 0.0]]
                fired[fresh_s] = det.add(a, t, h)
                break
            det.add(a, t, h)
    assert fired[0.6] is None and fired[None] == (0, 1)


def test_set_exchange_variant_is_set_with_the_detector_on_for_any_team():
    from lookalike.bench.ident import build_identifier

    seq = simulate_robots(preset("m5n3"), 30, 1)
    tracker = build_identifier("set-exchange", seq)
    assert tracker.config.exchange_llr == 8.0 and tracker.config.exchange_max_agents is None
    assert build_identifier("set", seq).config.exchange_max_agents == 7


def test_options_override_an_identifiers_parameters():
    from lookalike.bench.ident import build_identifier

    seq = simulate_robots(preset("m5n3"), 30, 1)
    tracker = build_identifier("set-exchange", seq, options={"exchange_llr": 6.0, "exchange_lag_s": 0.3})
    assert tracker.config.exchange_llr == 6.0 and tracker.config.exchange_lag_s == 0.3
    assert tracker.config.exchange_max_agents is None  # the variant's own, kept
    assert build_identifier("set-exchange", seq).config.exchange_llr == 8.0  # the variant is unchanged


def test_exchange_max_agents_leaves_larger_teams_without_the_detector():
    small = make_tracker("set", n_agents=7, exchange_llr=8.0, exchange_max_agents=7)
    large = make_tracker("set", n_agents=8, exchange_llr=8.0, exchange_max_agents=7)
    assert small._exchange is not None and large._exchange is None
