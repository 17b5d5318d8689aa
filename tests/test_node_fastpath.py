"""Issue 18: the node's per-frame identification path is faster but gives the same results.

The plain versions below are the code before the speed-up (one agent at a time; one snapshot at a
time); the fast paths must agree with them exactly.
"""

import hashlib

import numpy as np
import pytest

from lookalike.geometry import angle_diff
from lookalike.node import IdentifierConfig, TeamIdentifier, encode
from lookalike.node.teamsim import camera_messages, robot_reports, team_sequence
from lookalike.trackers import make_tracker
from lookalike.trackers.parts.identity import BeaconIdentifier, labels_from_tracks
from lookalike.trackers.parts.identity import IdentifierConfig as BeaconConfig
from lookalike.types import Beacons, Tracks


def plain_agent_headings(b: BeaconIdentifier, times_s: np.ndarray) -> np.ndarray:
    cfg = b.config
    out = np.full((len(times_s), cfg.n_agents), np.nan)
    for a in range(cfg.n_agents):
        known = np.isfinite(b._t[a])
        t, h = b._t[a, known], b._h[a, known]
        if not len(t):
            continue
        q = np.asarray(times_s, dtype=float)
        i = np.searchsorted(t, q, side="right")
        before = np.clip(i - 1, 0, len(t) - 1)
        after = np.clip(i, 0, len(t) - 1)
        span = t[after] - t[before]
        frac = np.divide(q - t[before], span, out=np.zeros_like(q), where=span > 0)
        inter = h[before] + np.clip(frac, 0, 1) * angle_diff(h[after], h[before])
        rate = 0.0
        if len(t) >= 2 and t[-1] > t[-2]:
            rate = float(np.clip(angle_diff(h[-1], h[-2]) / (t[-1] - t[-2]), -cfg.max_turn_rate, cfg.max_turn_rate))
        ahead = np.clip(q - t[-1], 0.0, cfg.max_extrapolation_s)
        out[:, a] = np.where(i >= len(t), h[-1] + rate * ahead, np.where(i == 0, h[0], inter))
    return out


def plain_store_reports(t_hist: np.ndarray, h_hist: np.ndarray, beacons: Beacons) -> None:
    """The report history update of ``begin_frame`` before its one-new-report fast path."""
    r = t_hist.shape[1]
    for a in np.unique(beacons.agent_id):
        if a >= len(t_hist):
            continue
        rows = beacons.agent_id == a
        t = np.concatenate([t_hist[a], beacons.t_sent[rows]])
        h = np.concatenate([h_hist[a], beacons.heading[rows]])
        known = np.isfinite(t)
        t, first = np.unique(t[known], return_index=True)
        h = h[known][first][-r:]
        t = t[-r:]
        t_hist[a], h_hist[a] = np.nan, np.nan
        t_hist[a, r - len(t):], h_hist[a, r - len(h):] = t, h


@pytest.mark.parametrize("seed", range(5))
def test_agent_headings_equal_the_plain_version(seed):
    rng = np.random.default_rng(seed)
    b = BeaconIdentifier(BeaconConfig(n_agents=6, window_frames=12, history=5))
    t_plain, h_plain = b._t.copy(), b._h.copy()
    for f in range(30):
        t = f / 30
        ids = rng.choice(6, rng.integers(0, 4), replace=False)
        if rng.random() < 0.3:
            ids = np.concatenate([ids, ids[:1]])  # two reports of one robot in a frame
        sent = t - rng.uniform(0, 0.5, len(ids))
        sent[rng.random(len(ids)) < 0.2] = t - 0.1  # repeated send times
        beacons = Beacons(agent_id=ids, t_sent=sent, t_received=np.full(len(ids), t),
                          heading=rng.uniform(-4, 4, len(ids)))
        b.begin_frame(t, beacons)
        plain_store_reports(t_plain, h_plain, beacons)
        np.testing.assert_array_equal(b._t, t_plain)
        np.testing.assert_array_equal(b._h, h_plain)
        queries = np.concatenate([b._times, rng.uniform(-1, 2, 5), [np.nan, t]])
        np.testing.assert_array_equal(b.agent_headings(queries), plain_agent_headings(b, queries))


def plain_labels(n, tracks):
    label, best, claimed = np.full(n, -1, dtype=int), np.full(n, -np.inf), {}
    ranked = sorted((t for t in tracks if t.agent_id is not None and t.detection_index >= 0),
                    key=lambda t: -(t.identity_prob if t.identity_prob is not None else 0.0))
    for t in ranked:
        p = t.identity_prob if t.identity_prob is not None else 0.0
        if t.agent_id in claimed or p <= best[t.detection_index]:
            continue
        label[t.detection_index], best[t.detection_index] = t.agent_id, p
        claimed[t.agent_id] = p
    return label


@pytest.mark.parametrize("seed", range(20))
def test_labels_from_columns_equal_snapshots(seed):
    rng = np.random.default_rng(seed)
    k, n = int(rng.integers(0, 9)), 6
    prob = rng.choice([0.2, 0.5, 0.9, np.nan], k)
    tracks = Tracks(np.arange(1, k + 1), rng.integers(0, 3, k).astype(np.int8), position=rng.normal(size=(k, 2)),
                    agent_id=rng.integers(-1, 4, k), identity_prob=prob, detection_index=rng.integers(-1, n, k))
    fast = labels_from_tracks(n, tracks)
    np.testing.assert_array_equal(fast, labels_from_tracks(n, list(tracks)))
    np.testing.assert_array_equal(fast, plain_labels(n, list(tracks)))


def _team_digest(columns: bool) -> tuple[str, int]:
    seq = team_sequence("m10n7", 3, 4.0)
    n = seq.config.n_agents
    tracker = make_tracker("kalman_ha2", n_agents=n)
    if not columns:  # the same tracker, its output handed over as a list of snapshots
        update = tracker.update
        tracker.update = lambda frame: list(update(frame))
    node = TeamIdentifier(tracker, IdentifierConfig(n_robots=n))
    reports = sorted((it for j in range(n) for it in robot_reports(seq, j)), key=lambda it: it[0])
    digest, labelled, i = hashlib.sha256(), 0, 0
    for message in camera_messages(seq):
        while i < len(reports) and reports[i][0] <= message.time:
            node.add_report(reports[i][1])
            i += 1
        _, team = node.add_frame(message)
        digest.update(encode(team))
        labelled += sum(v >= 0 for v in team.labels)
    return digest.hexdigest(), labelled


def test_team_states_from_columns_equal_snapshots_on_a_fixed_seed():
    fast, labelled = _team_digest(columns=True)
    assert labelled > 100
    assert (fast, labelled) == _team_digest(columns=False)
