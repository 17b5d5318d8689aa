"""The compiled world kernels (numba, optional) give bit for bit what the numpy path gives: the beacon
identifier's window costs on awkward report histories and samples, and whole Kalman-HA runs."""

from __future__ import annotations

import copy
import dataclasses
from collections.abc import Iterator

import numpy as np
import pytest

import lookalike.trackers.kernels.world as wk
from lookalike.node.teamsim import team_sequence
from lookalike.trackers import make_tracker
from lookalike.trackers.parts.identity import BeaconIdentifier, IdentifierConfig
from lookalike.types import Beacons

numba = pytest.importorskip("numba", reason="numba (the `fast` extra) is not installed: only the numpy path runs")


@pytest.fixture(autouse=True)
def _default_switch() -> Iterator[None]:
    yield
    wk.use_compiled(None)


def _compiled_or_skip() -> None:
    wk.use_compiled(True)
    if wk.compiled() is None:
        pytest.skip("numba's cos differs from numpy's on this machine: the compiled kernels stay off")


def both_costs(ident: BeaconIdentifier, track_ids: list[int]) -> tuple[np.ndarray, np.ndarray]:
    _compiled_or_skip()
    fast = ident.costs(track_ids)
    wk.use_compiled(False)
    plain = ident.costs(track_ids)
    return fast, plain


def assert_same_bits(fast: np.ndarray, plain: np.ndarray) -> None:
    assert fast.dtype == plain.dtype and fast.shape == plain.shape
    assert np.array_equal(fast.view(np.int64), plain.view(np.int64))


def random_beacons(rng: np.random.Generator, n_agents: int, t: float) -> Beacons:
    """Reports of a random subset of agents (some never report), now and then late, repeated or out of order."""
    agents = [a for a in range(n_agents) if a % 3 != 2 and rng.random() < 0.6]
    ids, sent, heading = [], [], []
    for a in agents:
        for _ in range(1 + int(rng.random() < 0.2)):  # sometimes two reports of one agent
            ids.append(a)
            sent.append(t - rng.choice([0.0, 0.01, 0.05, 0.3, 1.5]))  # late ones, repeated times
            heading.append(float(rng.choice([rng.uniform(-np.pi, np.pi), np.pi, -np.pi, rng.uniform(-20, 20)])))
    return Beacons(agent_id=np.array(ids, dtype=int), t_sent=np.array(sent), t_received=np.full(len(ids), t),
                   heading=np.array(heading))


@pytest.mark.parametrize("n_agents", [1, 2, 3, 7, 10])
@pytest.mark.parametrize("window", [1, 5, 30])
def test_compiled_window_costs_equal_numpys(n_agents: int, window: int) -> None:
    rng = np.random.default_rng(n_agents * 100 + window)
    ident = BeaconIdentifier(IdentifierConfig(n_agents=n_agents, window_frames=window, history=4,
                                              max_turn_rate=0.5, max_extrapolation_s=0.2))
    checked = 0
    for frame in range(3 * window + 12):
        t = 0.1 * frame + rng.uniform(0, 0.02)
        empty = rng.random() < 0.2
        ident.begin_frame(t, Beacons.empty() if empty else random_beacons(rng, n_agents, t))
        seen = [i for i in range(1, 9) if rng.random() < 0.7]
        if seen:  # headings near the wrap, exactly opposite, or far outside [-pi, pi)
            ident.observe_many(seen, rng.choice([0.0, np.pi, -np.pi, 3.0, rng.uniform(-50, 50)], size=len(seen)))
        for ids in ([], [1], [99], list(range(1, 9)), [5, 99, 2, 5]):  # (99: never observed, row 0)
            fast, plain = both_costs(ident, ids)
            assert_same_bits(fast, plain)
            checked += fast.size
    assert checked > 0


@pytest.mark.parametrize("n_agents", [2, 3, 7])
@pytest.mark.parametrize(("max_cost", "hysteresis"), [(0.3, 0.08), (1.0, 0.0), (0.05, 0.5), (0.0, 0.1)])
def test_compiled_identities_equal_numpys(n_agents: int, max_cost: float, hysteresis: float) -> None:
    _compiled_or_skip()
    rng = np.random.default_rng(n_agents)
    config = IdentifierConfig(n_agents=n_agents, window_frames=6, max_cost=max_cost, hysteresis=hysteresis)
    fast, plain = BeaconIdentifier(config), BeaconIdentifier(config)  # (assigning changes the held agents)
    assigned = 0
    for frame in range(60):
        t = 0.1 * frame
        beacons = random_beacons(rng, n_agents, t)
        tracks = [i for i in range(1, 12) if rng.random() < 0.6]
        headings = rng.uniform(-np.pi, np.pi, size=len(tracks))
        if frame % 7 == 3:  # every track near one agent's heading: several allowed pairs a row
            headings[:] = beacons.heading[0] if len(beacons) else 0.0
        results = []
        for ident, compiled in ((fast, True), (plain, False)):
            wk.use_compiled(compiled)
            ident.begin_frame(t, beacons)
            if tracks:
                ident.observe_many(tracks, headings)
            if frame % 5 == 4 and tracks:
                ident.drop(tracks[:1])
            results.append(ident.assign_arrays(tracks + [99]))  # (99: never observed)
        (agent_f, prob_f), (agent_p, prob_p) = results
        assert_same_bits(fast._th, plain._th)  # (the report histories, shifted or merged)
        assert np.array_equal(agent_f, agent_p)
        assert_same_bits(prob_f, prob_p)
        assigned += int((agent_f >= 0).sum())
    assert assigned > 0 or max_cost == 0.0


def test_compiled_gate_pairs_equal_numpys() -> None:
    _compiled_or_skip()
    kernels = wk.compiled()
    rng = np.random.default_rng(5)
    solved = 0
    for case in range(400):
        k, d = int(rng.integers(1, 9)), int(rng.integers(1, 9))
        y = rng.normal(0.0, [0.5, 1.0, 3.0, 1e146][case % 4], size=(k, 2, d))
        if case % 5 == 1:
            y = np.round(y)  # equal distances: ties for the solver
        if case % 7 == 2:
            y[0, 0, 0] = np.nan  # (a non-definite innovation covariance)
        gate = [9.21, 0.5, 1e300, 0.0][case % 4]
        d2 = np.add.reduce(y * y, axis=1)
        rows, cols = wk.pairs(d2, d2 <= gate)
        decision, work, allowed = kernels.gate_work(y, gate)
        fast_rows, fast_cols = wk.decided_pairs(decision, work, allowed)
        assert np.array_equal(rows, fast_rows) and np.array_equal(cols, fast_cols), case
        assert np.array_equal(allowed, d2 <= gate)
        solved += decision == 2
    assert solved > 50


@pytest.mark.parametrize("name", ["kalman_ha", "kalman_ha2"])
def test_compiled_birth_candidates_equal_numpys(name: str) -> None:
    _compiled_or_skip()
    sequence = team_sequence("m10n7", 2, 2.0)
    tracker = make_tracker(name, n_agents=sequence.config.n_agents)
    plain_candidates = tracker._birth_candidates
    births = 0

    def both(det, det_of_track):  # type: ignore[no-untyped-def]
        nonlocal births
        wk.use_compiled(False)
        plain = plain_candidates(det, det_of_track)
        wk.use_compiled(True)
        fast = plain_candidates(det, det_of_track)
        assert fast.dtype == plain.dtype and np.array_equal(fast, plain)
        births += len(fast)
        return fast

    tracker._birth_candidates = both
    for frame in sequence.frames():
        tracker.update(frame)
        tracker.update(dataclasses.replace(frame, index=frame.index, time=frame.time + 1e-3,
                                           detections=frame.detections.select([])))  # (an empty frame between)
    assert births > 0


@pytest.mark.parametrize("name", ["kalman_ha", "kalman_ha2", "jpda"])
def test_compiled_lifecycle_equals_numpys(name: str) -> None:
    """The compiled lifecycle (hit history, misses, seconds unseen, confirmation, deletion) leaves the same
    columns and survivors as the numpy lines, frame by frame, on a lossy run with tracks coasting out of view."""
    _compiled_or_skip()
    sequence = team_sequence("m10n7", 4, 4.0, loss=0.3, jitter_s=0.1)
    tracker = make_tracker(name, n_agents=sequence.config.n_agents)
    lifecycle = tracker._lifecycle
    deleted = 0

    def both(det_of_track, dt, in_view=None):  # type: ignore[no-untyped-def]
        nonlocal deleted
        table = copy.deepcopy(tracker._tracks)
        wk.use_compiled(False)
        plain = lifecycle(det_of_track.copy(), dt, in_view)
        plain_table, tracker._tracks = tracker._tracks, table  # (the compiled call starts from the same table)
        deleted += len(table) - len(plain_table)
        wk.use_compiled(True)
        fast = lifecycle(det_of_track, dt, in_view)
        assert fast.dtype == plain.dtype and np.array_equal(fast, plain)
        for c in table.columns:
            assert table[c].dtype == plain_table[c].dtype and np.array_equal(table[c], plain_table[c]), c
        return fast

    tracker._lifecycle = both
    for frame in sequence.frames():
        tracker.update(frame)
    assert deleted > 0


def test_gate_with_the_replicated_solve_equals_numpys() -> None:
    """Where the kernels' 2×2 lower-triangular solve replicates numpy's (checked at load: numpy 1.26's
    OpenBLAS), the one-call gate gives gate_work's decision, matrix and pairs on numpy's whitened innovations
    (elsewhere: on the replica's); factors or innovations that are not plain numbers (NaN, a zero pivot) make it
    decline (-1)."""
    _compiled_or_skip()
    kernels = wk.compiled()
    assert kernels is not None
    exact = wk.lower_solve_exact()  # (else: the one-call gate against gate_work on the replica's whitening)
    rng = np.random.default_rng(3)
    for _ in range(300):
        k, d = int(rng.integers(1, 9)), int(rng.integers(1, 12))
        var = rng.uniform(1e-3, 2.0, (k, 2))
        corr = rng.uniform(-0.99, 0.99, k)
        S = np.empty((k, 2, 2))
        S[:, 0, 0], S[:, 1, 1] = var[:, 0], var[:, 1]
        S[:, 0, 1] = S[:, 1, 0] = corr * np.sqrt(var[:, 0] * var[:, 1])
        L = wk.cholesky(S)
        mean = rng.uniform(-3, 3, (k, 6))
        z = mean[rng.integers(0, k, d), :2] + rng.normal(0, 0.3, (d, 2))
        gate = float(rng.choice([0.5, 9.21, 1e9]))
        b = z[None] - mean[:, None, :2]  # (k, d, 2)
        y = wk.solve(L, b.swapaxes(-1, -2))
        replica = kernels.solve_lower_many(np.repeat(L, d, axis=0), b.reshape(k * d, 2), d == 1)
        if exact:
            assert_same_bits(replica, y.swapaxes(-1, -2).reshape(k * d, 2))
        else:
            y = np.ascontiguousarray(replica.reshape(k, d, 2).swapaxes(-1, -2))
        expected = kernels.gate_work(y, gate)
        got = kernels.gate_work_lower(L, z, mean, gate)
        assert got[0] == expected[0]
        assert_same_bits(got[1], expected[1])
        assert np.array_equal(got[2], expected[2])
    L[0, 1, 1] = 0.0
    assert kernels.gate_work_lower(L, z, mean, 9.21)[0] == -1
    L[0, 1, 1], z[0, 0] = 1.0, np.nan
    assert kernels.gate_work_lower(L, z, mean, 9.21)[0] == -1


def test_compiled_update_equals_einsums() -> None:
    """The one-call Kalman update gives the einsum lines' means where its check passed at load (zeros and
    negative zeros among the gains), and the covariances made beforehand."""
    _compiled_or_skip()
    kernels = wk.compiled()
    assert kernels is not None and wk._same_updates(kernels) == wk.update_exact()
    if not wk.update_exact():
        pytest.skip("the einsum rounds otherwise here: the numpy lines are used")
    rng = np.random.default_rng(5)
    k, d = 9, 7
    mean, gain = rng.normal(0, 2, (k, 6)), rng.normal(0, 1, (k, 2, 6)) * rng.choice([0.0, -0.0, 1.0], (k, 2, 6))
    cov, cov_hit, z = rng.normal(0, 1, (k, 6, 6)), rng.normal(0, 1, (k, 6, 6)), rng.normal(0, 2, (d, 2))
    rows, cols = np.array([4, 0, 7]), np.array([6, 2, 0])
    expected_mean, expected_cov = mean.copy(), cov.copy()
    m = mean[rows]
    expected_mean[rows] = m + wk.einsum("kij,kj->ki", gain[rows].swapaxes(-1, -2), z[cols] - m[:, :2])
    expected_cov[rows] = cov_hit[rows]
    kernels.update_hits(mean, cov, rows, cols, gain, cov_hit, z)
    assert_same_bits(mean, expected_mean)
    assert_same_bits(cov, expected_cov)


def test_replicated_solve_is_refused_when_it_rounds_otherwise() -> None:
    _compiled_or_skip()
    kernels = wk.compiled()

    class Rounding:
        @staticmethod
        def solve_lower_many(factor, b, divide):  # type: ignore[no-untyped-def]
            return np.nextafter(kernels.solve_lower_many(factor, b, divide), np.inf)  # (one unit off)

    assert not wk._same_lower_solves(Rounding)
    assert not wk.lower_solve_exact(wk.CHECKED_RHS + 1)  # (more right-hand sides than were checked)
    wk.use_compiled(False)
    assert not wk.lower_solve_exact()


def test_compiled_costs_without_reports_or_samples() -> None:
    ident = BeaconIdentifier(IdentifierConfig(n_agents=4, window_frames=3))
    ident.begin_frame(0.0, Beacons.empty())
    fast, plain = both_costs(ident, [1, 2])  # no reports, no samples: every cost infinite
    assert_same_bits(fast, plain)
    assert np.isinf(fast).all()
    ident.observe_many([1], np.array([0.5]))
    ident.begin_frame(0.1, Beacons(agent_id=np.array([3]), t_sent=np.array([0.05]), t_received=np.array([0.1]),
                                   heading=np.array([1.0])))
    fast, plain = both_costs(ident, [1, 2])  # one report of one agent, one sample of one track
    assert_same_bits(fast, plain)
    assert np.isfinite(fast[0, 3]) and np.isinf(fast[1]).all()


def _tracks_columns(name: str, preset: str, seed: int, seconds: float, **network: float) -> list[tuple]:
    sequence = team_sequence(preset, seed, seconds, **network)
    tracker = make_tracker(name, n_agents=sequence.config.n_agents)
    rows = []
    for frame in sequence.frames():
        t = tracker.update(frame)
        rows.append(tuple(np.array(getattr(t, f)) for f in ("id", "status", "position", "heading", "agent_id",
                                                              "identity_prob", "detection_index")))
    return rows


@pytest.mark.parametrize("name", ["kalman_ha", "kalman_ha2"])
@pytest.mark.parametrize(("preset", "seed", "network"), [("m10n7", 0, {}), ("m3n2", 1, {"loss": 0.5, "jitter_s": 0.2})])
def test_compiled_tracker_runs_equal_numpys(name: str, preset: str, seed: int, network: dict) -> None:
    _compiled_or_skip()
    fast = _tracks_columns(name, preset, seed, 3.0, **network)
    wk.use_compiled(False)
    plain = _tracks_columns(name, preset, seed, 3.0, **network)
    assert len(fast) == len(plain)
    for a, b in zip(fast, plain):
        for x, y in zip(a, b):
            assert x.dtype == y.dtype and np.array_equal(x, y, equal_nan=x.dtype.kind == "f")


def test_switch_and_warm(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("LOOKALIKE_WORLD_NUMBA", "0")
    wk.use_compiled(None)  # (the environment is read again)
    assert wk.compiled() is None and wk.warm() is False
    monkeypatch.delenv("LOOKALIKE_WORLD_NUMBA")
    wk.use_compiled(False)
    assert wk.compiled() is None
    wk.use_compiled(None)
    assert wk.warm() is (wk.compiled() is not None)
