"""The set identifier's shortcuts give exactly what the general paths give: the Kalman update from a projection made
once with numpy's kernels, the localiser with every agent seen (no row copies), agents' detections, the
report-exchange wrap on floats."""

import math

import numpy as np

from lookalike.motion import kalman
from lookalike.trackers.parts.agents import agent_detections
from lookalike.trackers.parts.identity.localiser import _H, KalmanLocaliser, _corrected
from lookalike.trackers.set.report_exchange import _wrap, _wrap_float


def test_localisers_update_equals_the_kalman_update():
    rng = np.random.default_rng(0)
    k = 6
    a = rng.normal(size=(k, 4, 4))
    mean, cov, z = rng.normal(size=(k, 4)), a @ a.transpose(0, 2, 1) + np.eye(4), rng.normal(size=(k, 2))
    R = 0.1 * np.tile(np.eye(2), (k, 1, 1))
    fast = _corrected(mean, cov, z, *kalman.project(mean, cov, _H, R))
    for got, want in zip(fast, kalman.update(mean, cov, z, _H, R)):
        assert np.array_equal(got, want)


def test_localiser_with_every_agent_seen_equals_the_rows_of_a_larger_team():
    """Three agents always seen (the path without copies) against the same three in a team of four whose fourth is
    never seen (rows copied out and back): the same positions, bit for bit, frame by frame."""
    rng = np.random.default_rng(1)
    whole, part = KalmanLocaliser(3), KalmanLocaliser(4)
    position = rng.uniform(-3, 3, size=(3, 2))
    for frame in range(60):
        position += rng.normal(scale=0.05, size=(3, 2))
        measured = position + rng.normal(scale=0.02, size=(3, 2))
        weight = rng.uniform(0.6, 1.0, size=3)
        if frame == 30:
            measured[1] += 40.0  # (gated out: the path with some assignments rejected)
        time = frame / 30
        got = whole.update(time, measured, weight)
        want = part.update(time, np.vstack([measured, [np.nan, np.nan]]), np.append(weight, 0.0))
        assert np.array_equal(got, want[:3], equal_nan=True)
        assert np.isnan(want[3]).all()


def test_agent_detections_takes_each_agents_most_confident_detection():
    rng = np.random.default_rng(2)
    for _ in range(200):
        n, n_agents = int(rng.integers(0, 9)), int(rng.integers(1, 5))
        labels, conf = rng.integers(-1, n_agents, size=n), rng.choice([0.2, 0.5, 0.9], size=n)
        want = np.full(n_agents, -1)
        for k in np.argsort(-conf):
            if labels[k] >= 0 and want[labels[k]] < 0:
                want[labels[k]] = k
        got = agent_detections(labels, conf, n_agents)
        assert got.dtype == want.dtype and np.array_equal(got, want)


def test_wrap_of_one_float_equals_the_array_wrap():
    rng = np.random.default_rng(3)
    angles = [0.0, -0.0, math.pi, -math.pi, 2 * math.pi, -3 * math.pi, 1e-17, -1e-17,
              *rng.uniform(-50, 50, 2000).tolist()]
    for angle in angles:
        want = float(_wrap(np.asarray(angle)))
        got = _wrap_float(angle)
        assert got == want and math.copysign(1.0, got) == math.copysign(1.0, want)
