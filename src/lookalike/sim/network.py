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


def _burst_mask(t_sent: np.ndarray, cfg: NetworkConfig, horizon_s: float, rng: np.random.Generator) -> np.ndarray:
    """Whether each send time ``(n_agents, K)`` falls into a loss burst of that agent's link."""
    n_agents = t_sent.shape[0]
    if cfg.burst_rate_hz == 0 or cfg.burst_s == 0:
        return np.zeros(t_sent.shape, dtype=bool)
    mean_good = 1.0 / cfg.burst_rate_hz
    cycle = mean_good + cfg.burst_s
    n_cycles = int(np.ceil(horizon_s / cycle * 2.0 + 10.0 * np.sqrt(horizon_s / cycle + 1.0))) + 4
    good = rng.exponential(mean_good, (n_agents, n_cycles))
    bad = rng.exponential(cfg.burst_s, (n_agents, n_cycles))
    # Stationary start: inside a burst with probability burst_s / cycle (memoryless durations).
    start_bad = rng.random(n_agents) < cfg.burst_s / cycle
    first = np.where(start_bad, 0.0, good[:, 0])
    durations = np.empty((n_agents, 2 * n_cycles))
    durations[:, 0::2] = good
    durations[:, 1::2] = bad
    durations[:, 0] = first
    ends = np.cumsum(durations, axis=1)  # ends of good, bad, good, bad ... periods
    out = np.empty(t_sent.shape, dtype=bool)
    for a in range(n_agents):
        period = np.searchsorted(ends[a], t_sent[a], side="right")
        out[a] = (period % 2) == 1
    return out


def simulate_reports(heading_rad: np.ndarray, dt_s: float, cfg: NetworkConfig,
                     rng: np.random.Generator) -> ReportArrays:
    """Reports of ``heading_rad (T, N)`` (unwrapped), interpolated linearly at the send times."""
    T, n_agents = heading_rad.shape
    horizon = (T - 1) * dt_s
    period = 1.0 / cfg.rate_hz
    k_max = int(np.floor(horizon / period)) + 1
    frame_offsets_empty = np.zeros(T + 1, dtype=int)
    if T == 0 or n_agents == 0 or k_max <= 0:
        z = np.zeros(0)
        return ReportArrays(np.zeros(0, int), z, z, z, frame_offsets_empty, 0)
    phase = np.asarray(rng.uniform(0.0, period, n_agents))
    t_sent = phase[:, None] + period * np.arange(k_max)[None, :]  # (N, K)
    inside = t_sent <= horizon
    lost = (rng.random(t_sent.shape) < cfg.loss_prob) | _burst_mask(t_sent, cfg, horizon, rng)
    delay = cfg.delay_s + (rng.exponential(cfg.jitter_s, t_sent.shape) if cfg.jitter_s > 0 else 0.0)
    t_received = t_sent + delay
    # Heading at the send time: linear interpolation between frames (headings are unwrapped).
    pos = t_sent / dt_s
    i0 = np.clip(np.floor(pos).astype(int), 0, T - 1)
    i1 = np.minimum(i0 + 1, T - 1)
    w = np.clip(pos - i0, 0.0, 1.0)
    agents = np.arange(n_agents)[:, None]
    h = (1 - w) * heading_rad[i0, agents] + w * heading_rad[i1, agents]
    h = h + rng.normal(0.0, cfg.imu_noise_rad, h.shape) if cfg.imu_noise_rad > 0 else h
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
