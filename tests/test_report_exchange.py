"""The report-exchange detector and the set identifier's exchange_llr."""

import numpy as np
import pytest

from lookalike.bench.experiments import most_seen_pair, swap_reports
from lookalike.sim import preset, simulate_robots
from lookalike.trackers import make_tracker
from lookalike.trackers.set.report_exchange import ReportExchange


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
    """Seed 63181 (M=3, N=2; the first from 63005 on with this world, chosen from the truth alone): the reports swapped
    back while the two headings are under 0.1 rad apart, which then part by more than 0.5 rad before 18 s."""
    seq = simulate_robots(preset("m3n2"), 600, 63181)
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
    for memory_s in (1.0, 1e9):  # 1e9 s: no decay to speak of
        det = ReportExchange(2, threshold=8.0, memory_s=memory_s)
        for a, t, h in reports[:40]:
            det.add(a, t, h)
        det.evidence[0, 1] = 30.0  # one stream's evidence, seconds before the other's
        for a, t, h in reports[40:140]:
            det.add(a, t, h)
        left[memory_s] = det.evidence[0, 1]
    assert left[1.0] < 30.0 * np.exp(-4.0) + 2.0 < left[1e9]


def test_options_override_an_identifiers_parameters():
    from lookalike.bench.ident import build_identifier

    seq = simulate_robots(preset("m5n3"), 30, 1)
    tracker = build_identifier("set", seq, options={"exchange_llr": 6.0})
    assert tracker.config.exchange_llr == 6.0 and build_identifier("set", seq).config.exchange_llr == 8.0
