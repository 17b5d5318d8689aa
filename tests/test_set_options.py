"""The set identifier's mechanisms, each on frames made for it: hiding stale reports, the false-positive prior,
report jumps, the report- and visual-exchange detectors and the undo window."""

import numpy as np
import pytest

from lookalike.trackers import make_tracker
from lookalike.types import Beacons, Detections, Frame

RATE = 30.0
PLACES = np.array([[2.0, 0.5], [3.0, -1.0]])  # the two robots' ground positions, metres


def frames(n_frames: int, report_heading, visual_heading, reports_from=lambda agent, t: True) -> list[Frame]:
    """Two robots standing at PLACES; each reports ``report_heading(agent, t)`` at 10 Hz (when
    ``reports_from(agent, t)``) and is seen with ``visual_heading(robot, t)``."""
    out = []
    for k in range(n_frames):
        t = k / RATE
        ids = [a for a in (0, 1) if k % 3 == 0 and reports_from(a, t)]
        beacons = Beacons(agent_id=np.array(ids, dtype=int), t_sent=np.full(len(ids), t),
                          t_received=np.full(len(ids), t), heading=np.array([report_heading(a, t) for a in ids]))
        dets = Detections(position=PLACES.copy(), heading=np.array([visual_heading(r, t) for r in (0, 1)]),
                          score=np.full(2, 0.9))
        out.append(Frame(index=k, time=t, detections=dets, beacons=beacons))
    return out


@pytest.fixture(scope="module")
def shipped():
    from lookalike.trackers.set.network import SHIPPED_SET_WEIGHTS

    if not SHIPPED_SET_WEIGHTS.is_file():
        pytest.skip("no shipped set weights")
    return SHIPPED_SET_WEIGHTS


def tokens_seen(tracker, fs: list[Frame]) -> list[np.ndarray]:
    """The agent tokens the network was given, per frame."""
    seen = []
    step = tracker.net.step

    def spy(agents, dets, dt):
        seen.append(np.array(agents))
        return step(agents, dets, dt)

    tracker.net.step = spy
    for f in fs:
        tracker.update(f)
    return seen


def test_a_stale_report_whose_robot_turned_is_hidden_only_with_stale_s(shipped):
    from lookalike.trackers import make_tracker

    heading = {0: 0.0, 1: 2.0}
    # Robot 0 stops reporting at 0.5 s and turns by 2 rad at 1.0 s; robot 1 keeps reporting.
    fs = frames(90, lambda a, t: heading[a], lambda r, t: heading[r] + (2.0 if r == 0 and t >= 1.0 else 0.0),
                reports_from=lambda a, t: a == 1 or t < 0.5)
    known = {}
    for stale_s in (None, 1.0):
        tracker = make_tracker("set", n_agents=2, n_slots=2, stale_s=stale_s)
        known[stale_s] = np.array([a[:, 3] for a in tokens_seen(tracker, fs)])  # column 3: "heard from"
    assert (known[None][1:] == 1).all()  # without the option every heard agent stays heard
    late = int(1.6 * RATE)  # the report is older than 1 s and the robot has turned
    assert (known[1.0][late:, 0] == 0).all() and (known[1.0][:, 1][1:] == 1).all()
    assert (known[1.0][1:int(1.4 * RATE), 0] == 1).all()  # before it is 1 s old it is shown
    same_heading = frames(90, lambda a, t: heading[a], lambda r, t: heading[r],
                          reports_from=lambda a, t: a == 1 or t < 0.5)
    tracker = make_tracker("set", n_agents=2, n_slots=2, stale_s=1.0)
    assert all(a[0, 3] == 1 for a in tokens_seen(tracker, same_heading)[1:])  # stale but not turned: shown


@pytest.mark.parametrize("exchange_llr", [None, 8.0])  # the exchange detector adds nothing to a report jump
def test_a_report_swap_exchanges_the_memories(shipped, exchange_llr):
    from lookalike.trackers import make_tracker

    heading = {0: 0.0, 1: 2.0}
    swapped = lambda a, t: heading[1 - a] if t >= 1.5 else heading[a]  # noqa: E731  ids exchanged from 1.5 s
    fs = frames(60, swapped, lambda r, t: heading[r])
    tracker = make_tracker("set", n_agents=2, n_slots=2, exchange_llr=exchange_llr)
    calls = []
    for name in ("swap", "forget"):
        method = getattr(tracker.net, name)
        setattr(tracker.net, name, lambda *a, m=method, n=name: (calls.append(n), m(*a)))
    before = None
    for f in fs:
        if f.time >= 1.5 and before is None:
            before = tracker.net.p.copy()
            tracker.update(f)
            after_jump = tracker.net.p.copy()
        else:
            tracker.update(f)
    assert calls == ["swap"]  # one exchange; the partner's own jump changes nothing more
    assert np.linalg.norm(after_jump[0] - before[1]) < np.linalg.norm(after_jump[0] - before[0])
    quiet = make_tracker("set", n_agents=2, n_slots=2)
    quiet.net.swap = quiet.net.forget = lambda *a: pytest.fail("no jump, no change")
    for f in frames(60, lambda a, t: heading[a], lambda r, t: heading[r]):
        quiet.update(f)


def three_robot_frames(report_heading, n_frames: int = 120) -> list[Frame]:
    """Three robots standing apart, seen with headings 0, 2.0 and 2.3 rad; agent ``a`` reports
    ``report_heading(a, t)`` at 10 Hz in frames ``k % 3 == a`` (so no two agents report in one frame; a NaN
    heading: no report)."""
    places, seen = np.array([[2.0, 0.5], [3.0, -1.0], [4.0, 1.0]]), np.array([0.0, 2.0, 2.3])
    out = []
    for k in range(n_frames):
        t, a = k / RATE, k % 3
        heading = np.array([report_heading(a, t)])
        sent = np.isfinite(heading)
        beacons = Beacons(agent_id=np.array([a])[sent], t_sent=np.array([t])[sent], t_received=np.array([t])[sent],
                          heading=heading[sent])
        out.append(Frame(index=k, time=t, detections=Detections(position=places.copy(), heading=seen.copy(),
                                                                score=np.full(3, 0.9)), beacons=beacons))
    return out


def test_two_ambiguous_jumps_that_mirror_each_other_are_paired(shipped):
    """Agents 0 and 1 swap ids at 1.5 s; agent 0's jump to 2.0 rad could be for robot 1 or 2 (2.3 rad): it waits
    for agent 1's mirroring jump and the two swap memories. A lone jump with no mirror is forgotten once
    PAIR_WAIT_S has passed."""
    from lookalike.trackers import make_tracker
    from lookalike.trackers.set.report_jumps import PAIR_WAIT_S

    own = np.array([0.0, 2.0, 2.3])
    swapped = lambda a, t: own[{0: 1, 1: 0}.get(a, a)] if t >= 1.5 else own[a]  # noqa: E731
    lone = lambda a, t: 2.15 if a == 0 and t >= 1.5 else own[a]  # noqa: E731
    for report, expected in ((swapped, ["swap"]), (lone, ["forget"])):
        tracker = make_tracker("set", n_agents=3, n_slots=3, exchange_llr=None)
        calls = []
        for name in ("swap", "forget"):
            method = getattr(tracker.net, name)
            setattr(tracker.net, name,
                    lambda *a, m=method, n=name, c=calls, t=tracker: (c.append((n, t._last_time)), m(*a)))
        before = None
        for f in three_robot_frames(report):
            if before is None and f.time >= 1.5:
                before = tracker.net.p.copy()
            tracker.update(f)
        assert [n for n, _ in calls] == expected
        if expected == ["swap"]:  # agent 0 now remembers where robot 1 stands, and agent 1 robot 0
            assert np.allclose(tracker.net.p[[0, 1]], before[[1, 0]], atol=0.3)
        if report is lone:
            assert calls[0][1] > 1.5 + PAIR_WAIT_S  # forgotten only when no mirroring jump came in time


def test_a_jump_is_paired_with_the_first_report_after_a_silence(shipped):
    """Agent 1 is silent from 0.6 s until the ids of agents 0 and 1 swap: its first report, 2 rad off its
    last one but a second later, is no jump, and agent 0's jump could be for robot 1 or 2. Agents 0 and 1
    exchange memories, whichever of the two reports comes first. A silence with no swap changes nothing."""
    own = np.array([0.0, 2.0, 2.3])
    for swap_at, quiet_to in ((1.5, 1.6), (1.51, 1.5)):  # agent 0's jump first (1.6 s); agent 1's report (1.53 s)
        def report(a: int, t: float, at: float = swap_at, to: float = quiet_to) -> float:
            if a == 1 and 0.6 <= t < to:
                return float("nan")  # silent: no report
            return float(own[{0: 1, 1: 0}.get(a, a)] if t >= at else own[a])

        assert silent_calls(report) == [("swap", {0, 1})]
    assert silent_calls(lambda a, t: float("nan") if a == 1 and 0.6 <= t < 1.6 else float(own[a])) == []


def silent_calls(report) -> list[tuple[str, set[int]]]:
    """The memory changes (``("swap", {a, b})``, ``("forget", agents)``) of a three-agent set identifier
    on :func:`three_robot_frames` with ``report``."""
    tracker = make_tracker("set", n_agents=3, n_slots=3, exchange_llr=None)
    calls: list[tuple[str, set[int]]] = []
    tracker.net.swap = lambda a, b, m=tracker.net.swap: (calls.append(("swap", {a, b})), m(a, b))[1]
    tracker.net.forget = lambda mask, m=tracker.net.forget: (calls.append(("forget", set(np.flatnonzero(mask)))),
                                                             m(mask))[1]
    for f in three_robot_frames(report):
        tracker.update(f)
    return calls


def test_visual_exchange_follows_visual_headings_that_fit_the_other_agents_reports(shipped):
    heading = {0: 0.0, 1: 0.3}  # too close for a report jump; both detectors' rules off
    swapped = lambda a, t: heading[1 - a] if t >= 1.5 else heading[a]  # noqa: E731  ids exchanged from 1.5 s
    labels = {}
    for threshold in (None, 6.0):
        tracker = make_tracker("set", n_agents=2, n_slots=2, report_jump=None, exchange_llr=None,
                               visual_exchange=threshold)
        out = []
        for f in frames(150, swapped, lambda r, t: heading[r]):
            tracker.update(f)
            out.append(tracker.last_labels.copy())
        labels[threshold] = np.array(out)
        assert tracker.visual_exchanges == (0 if threshold is None else 1)
    late = int(3.0 * RATE)
    assert (labels[6.0][late:] == [1, 0]).all()  # robot 0 now reports as agent 1, and is labelled so
    assert (labels[6.0][: int(1.4 * RATE)] == [0, 1]).all()  # before the swap nothing changed
    assert (labels[None][late:] == [0, 1]).all()  # without the rule the memory holds the old labels
    quiet = make_tracker("set", n_agents=2, n_slots=2, visual_exchange=2.0)
    quiet.net.swap = lambda *a: pytest.fail("no swap, no exchange")
    for f in frames(150, lambda a, t: heading[a], lambda r, t: heading[r]):
        quiet.update(f)


def test_the_agent_still_reporting_carries_a_visual_exchange_with_a_silent_one(shipped):
    heading = {0: 0.0, 1: 0.3}
    swapped = lambda a, t: heading[1 - a] if t >= 1.5 else heading[a]  # noqa: E731  ids exchanged from 1.5 s
    silent = lambda a, t: a == 0 or t < 1.4  # noqa: E731  and agent 1 silent from just before
    tracker = make_tracker("set", n_agents=2, n_slots=2, report_jump=None, exchange_llr=None, visual_exchange=6.0)
    for f in frames(150, swapped, lambda r, t: heading[r], reports_from=silent):
        tracker.update(f)
    assert tracker.visual_exchanges == 1
    assert tracker.last_labels.tolist() == [1, 0]


def test_undo_factor_undoes_a_recent_exchange_on_less_evidence(shipped, monkeypatch):
    from lookalike.trackers.set import tracker as set_tracker

    heading = {0: 0.0, 1: 0.25}  # too close for a report jump: the visual detector alone finds both exchanges
    swapped = lambda a, t: heading[1 - a] if 1.5 <= t < 5.0 else heading[a]  # noqa: E731  ids exchanged 1.5-5 s
    found = {}
    for undo, undo_s in ((None, 30.0), (0.25, 30.0), (0.25, 2.0)):
        monkeypatch.setattr(set_tracker, "UNDO_S", undo_s)
        tracker = make_tracker("set", n_agents=2, n_slots=2, report_jump=None, exchange_llr=None,
                               visual_exchange=8.0, undo_factor=undo)
        times, scales = [], []
        swap = tracker.net.swap
        tracker.net.swap = lambda a, b, s=swap, t=tracker, out=times: (out.append(t._last_time), s(a, b))
        for f in frames(240, swapped, lambda r, t: heading[r]):
            tracker.update(f)
            if f.index in (int(4.5 * RATE), 239):  # between the two exchanges, and at the end
                scales.append(tracker._threshold_scale())
        found[(undo, undo_s)] = times
        assert len(times) == 2 and tracker.last_labels.tolist() == [0, 1]  # the swap, then its undoing
        if undo is None:
            assert scales == [None, None]
        else:  # the pair's thresholds scaled until the undo (or undo_s), then as any other pair's
            assert scales[0][0, 1] == scales[0][1, 0] == (undo if undo_s == 30.0 else 1.0)
            assert (scales[1] == 1.0).all() and scales[0][0, 0] == 1.0
    plain, undone, expired = found[(None, 30.0)], found[(0.25, 30.0)], found[(0.25, 2.0)]
    assert plain[0] == undone[0] == expired[0]  # the first exchange needs the full evidence either way
    assert 5.0 < undone[1] < plain[1] == expired[1]  # undone sooner, unless more than undo_s after the first


def test_undo_factor_holds_for_an_agents_latest_exchange_only(shipped):
    tracker = make_tracker("set", n_agents=3, undo_factor=0.5)
    tracker._last_time = 1.0
    tracker._swap_network(0, 1)
    assert tracker._threshold_scale()[0, 1] == 0.5
    tracker._last_time = 2.0
    tracker._swap_network(1, 2)  # agent 1 exchanges again, with a third agent: only that exchange may be undone
    scale = tracker._threshold_scale()
    assert scale[0, 1] == 1.0 and scale[1, 2] == scale[2, 1] == 0.5
    tracker._swap_network(2, 1)  # undone: the pair is as any other again
    assert (tracker._threshold_scale() == 1.0).all()


def test_fp_prior_follows_the_worlds_false_positive_rate(shipped, monkeypatch):
    """fp_prior_ref: the running false-positive rate starts at the reference, falls in a world without false
    positives (so a robot's detection is less readily called one); None turns the correction off."""
    from lookalike.trackers import make_tracker
    from lookalike.trackers.set import tracker as set_tracker

    monkeypatch.setattr(set_tracker, "FP_PRIOR_S", 1.0)
    clip = frames(90, lambda a, t: 0.3 + 2.0 * a, lambda r, t: 0.3 + 2.0 * r)
    plain = make_tracker("set", n_agents=2, weights=str(shipped), fp_prior_ref=None)
    adapted = make_tracker("set", n_agents=2, weights=str(shipped), fp_prior_ref=1.0)
    assert plain.fp_rate is None and adapted.fp_rate == 1.0
    for f in clip:
        adapted.update(f)
    assert np.array_equal(adapted.last_labels, [0, 1])
    assert 0.0 <= adapted.fp_rate < 0.1  # three seconds of frames without a false positive, time constant 1 s
    prob = np.array([[0.2, 0.2, 0.6], [0.5, 0.1, 0.4]])
    scaled = adapted._fp_prior(prob)
    assert np.allclose(scaled.sum(axis=1), 1.0) and np.all(scaled[:, -1] < prob[:, -1])
    assert np.allclose(scaled[:, 0] / scaled[:, 1], prob[:, 0] / prob[:, 1])  # agents' odds kept
    adapted.reset()
    assert adapted.fp_rate == 1.0


def test_larger_teams_run_the_smoother_report_exchange_model_and_the_largest_none():
    from lookalike.trackers.set import report_exchange as rx

    small = make_tracker("set", n_agents=rx.TIGHT_TEAM - 1)
    large = make_tracker("set", n_agents=rx.TIGHT_TEAM)
    assert (small._exchange.q, small._exchange.lag_s) == (rx.ACCEL_PSD, rx.LAG_S)
    assert (large._exchange.q, large._exchange.lag_s) == (rx.TIGHT_ACCEL_PSD, rx.TIGHT_LAG_S)
    assert make_tracker("set", n_agents=rx.MAX_AGENTS + 1)._exchange is None
    assert make_tracker("set", n_agents=3, exchange_llr=None)._exchange is None
