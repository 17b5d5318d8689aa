"""Heading reports over a lossy network (delay with jitter, losses, loss bursts), for a whole sequence at once."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from lookalike.geometry.angles import wrap_angle
from lookalike.sim.robots_config import NetworkConfig


@dataclass(frozen=True, eq=False)
class ReportArrays:
    """The reports received during a sequence, sorted by receive time.

    Attributes:
        agent_id: ``(B,)`` sender (0-based).
        t_sent: ``(B,)`` send time, seconds.
        t_received: ``(B,)`` receive time, seconds.
        heading: ``(B,)`` reported absolute heading, radians.
        frame_offsets: ``(T + 1,)``; frame ``k`` carries rows ``frame_offsets[k]:frame_offsets[k+1]``
            (received after frame ``k - 1`` and not after frame ``k``).
        n_sent: reports sent during the sequence, lost ones included."""

    agent_id: np.ndarray
    t_sent: np.ndarray
    t_received: np.ndarray
    heading: np.ndarray
    frame_offsets: np.ndarray
    n_sent: int


def _burst_mask(t_sent: np.ndarray, cfg: NetworkConfig, horizon_s: float,
                seeds: np.random.SeedSequence) -> np.ndarray:
    """Whether each send time ``(n_agents, K)`` falls into a loss burst of that agent's link (one stream per agent)."""
    n_agents = t_sent.shape[0]
    if cfg.burst_rate_hz == 0 or cfg.burst_s == 0:
        return np.zeros(t_sent.shape, dtype=bool)
    mean_good = 1.0 / cfg.burst_rate_hz
    scale = np.resize(np.array([mean_good, cfg.burst_s]), 64)  # good, bad, good, bad ... mean durations
    out = np.empty(t_sent.shape, dtype=bool)
    for a, seed in enumerate(seeds.spawn(n_agents)):
        rng = np.random.default_rng(seed)
        # Stationary start: inside a burst with probability burst_s / cycle (memoryless durations).
        start_bad = rng.random() < cfg.burst_s / (mean_good + cfg.burst_s)
        durations = np.zeros(0)
        ends = np.zeros(0)  # ends of good, bad, good, bad ... periods
        while not ends.size or ends[-1] <= horizon_s:
            more = rng.standard_exponential(scale.size) * scale
            more[0] = 0.0 if start_bad and not durations.size else more[0]
            durations = np.concatenate([durations, more])
            ends = np.cumsum(durations)
        out[a] = np.searchsorted(ends, t_sent[a], side="right") % 2 == 1
    return out


def simulate_reports(heading_rad: np.ndarray, dt_s: float, cfg: NetworkConfig,
                     seeds: np.random.SeedSequence) -> ReportArrays:
    """Reports of ``heading_rad (T, N)`` (unwrapped), interpolated linearly at the send times. Phases, losses, bursts,
    delays and IMU noise come from their own streams of ``seeds``, drawn report by report in time order, so the
    reports of a shorter sequence are the start of those of a longer one."""
    T, n_agents = heading_rad.shape
    horizon = (T - 1) * dt_s
    period = 1.0 / cfg.rate_hz
    k_max = int(np.floor(horizon / period)) + 1
    frame_offsets_empty = np.zeros(T + 1, dtype=int)
    if T == 0 or n_agents == 0 or k_max <= 0:
        z = np.zeros(0)
        return ReportArrays(np.zeros(0, int), z, z, z, frame_offsets_empty, 0)
    r_phase, r_loss, r_burst, r_delay, r_imu = seeds.spawn(5)
    phase = np.asarray(np.random.default_rng(r_phase).uniform(0.0, period, n_agents))
    t_sent = phase[:, None] + period * np.arange(k_max)[None, :]  # (N, K)
    shape_km = (k_max, n_agents)  # draws are made (K, N): report k of every agent, then k + 1
    inside = t_sent <= horizon
    lost = (np.random.default_rng(r_loss).random(shape_km).T < cfg.loss_prob) | _burst_mask(t_sent, cfg, horizon,
                                                                                             r_burst)
    jitter = np.random.default_rng(r_delay).exponential(cfg.jitter_s, shape_km).T if cfg.jitter_s > 0 else 0.0
    delay = cfg.delay_s + jitter
    t_received = t_sent + delay
    # Heading at the send time: linear interpolation between frames (headings are unwrapped).
    pos = t_sent / dt_s
    i0 = np.clip(np.floor(pos).astype(int), 0, T - 1)
    i1 = np.minimum(i0 + 1, T - 1)
    w = np.clip(pos - i0, 0.0, 1.0)
    agents = np.arange(n_agents)[:, None]
    h = (1 - w) * heading_rad[i0, agents] + w * heading_rad[i1, agents]
    h = h + np.random.default_rng(r_imu).normal(0.0, cfg.imu_noise_rad, shape_km).T if cfg.imu_noise_rad > 0 else h
    n_sent = int(inside.sum())
    keep = inside & ~lost & (t_received <= horizon + 1e-9)
    agent_id = np.broadcast_to(agents, t_sent.shape)[keep]
    ts, tr, hd = t_sent[keep], t_received[keep], h[keep]
    order = np.lexsort((ts, tr))
    frame_times = np.arange(T) * dt_s
    tr = tr[order]
    offsets = np.concatenate([[0], np.searchsorted(tr, frame_times + 1e-9, side="right")])
    offsets[-1] = len(tr)
    return ReportArrays(
        agent_id=agent_id[order].astype(int), t_sent=ts[order], t_received=tr,
        heading=np.asarray(wrap_angle(hd[order])).reshape(-1), frame_offsets=offsets.astype(int), n_sent=n_sent,
    )
