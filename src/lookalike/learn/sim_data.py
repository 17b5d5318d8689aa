"""Training arrays from the robot simulator's arrays (vectorised over time), with optional identity swaps."""

from __future__ import annotations

import dataclasses

import numpy as np

from lookalike.learn.data import IGNORE
from lookalike.sim import RobotArrays, RobotWorldConfig, simulate_arrays
from lookalike.trackers.lstm.encoding import AGENT_WIDTH, EncodingSpec, encode_agents, relative_headings


def slot_order(arrays: RobotArrays, rng: np.random.Generator | None) -> np.ndarray:
    """Per frame, the detection slots ``(T, M)`` with the occupied ones first: by score, or shuffled with ``rng``."""
    valid = arrays.det_valid
    key = -arrays.det_score if rng is None else rng.random(valid.shape)
    order: np.ndarray = np.argsort(np.where(valid, key, np.inf), axis=1, kind="stable")
    return order


def latest_reports(arrays: RobotArrays, n_agents: int) -> tuple[np.ndarray, np.ndarray]:
    """Per frame and agent, the newest report received: headings and send times ``(T, N)``, NaN before any."""
    r = arrays.reports
    T = len(arrays)
    heading = np.full((T, n_agents), np.nan)
    t_sent = np.full((T, n_agents), np.nan)
    received_by = r.frame_offsets[1:]  # rows received up to each frame
    for j in range(n_agents):
        idx = np.flatnonzero(r.agent_id == j)
        if not len(idx):
            continue
        ts = r.t_sent[idx]
        previous_max = np.concatenate([[-np.inf], np.maximum.accumulate(ts)[:-1]])
        newest = np.maximum.accumulate(np.where(ts > previous_max, np.arange(len(idx)), 0))
        count = np.searchsorted(idx, received_by)  # reports of agent j received by each frame
        have = count > 0
        pick = idx[newest[np.maximum(count - 1, 0)]]
        heading[have, j] = r.heading[pick[have]]
        t_sent[have, j] = r.t_sent[pick[have]]
    return heading, t_sent


def arrays_to_training(
    spec: EncodingSpec, arrays: RobotArrays, rng: np.random.Generator | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """Inputs ``(T, n_inputs)`` and targets ``(T, M)``; slots ordered by :func:`slot_order`."""
    T, M = arrays.det_valid.shape
    if M != spec.n_slots:
        raise ValueError(f"the sequence has {M} detection slots, the encoding {spec.n_slots}")
    heading, sent = latest_reports(arrays, spec.n_agents)
    x = np.zeros((T, spec.n_inputs))
    n_agent_inputs = AGENT_WIDTH * spec.n_agents
    x[:, :n_agent_inputs] = encode_agents(spec, heading, arrays.time[:, None] - sent)
    order = slot_order(arrays, rng)
    take = lambda a: np.take_along_axis(a, order, axis=1)  # noqa: E731
    v = take(arrays.det_valid)
    phi = take(arrays.det_heading)
    columns = [take(arrays.det_position[..., 0])[..., None], take(arrays.det_position[..., 1])[..., None],
               np.cos(phi)[..., None], np.sin(phi)[..., None], take(arrays.det_score)[..., None]]
    if spec.relative_headings:
        columns.append(relative_headings(phi, heading))
    slots = np.concatenate(columns, axis=-1) * v[..., None]
    x[:, n_agent_inputs:] = slots.reshape(T, -1)
    label = take(arrays.det_label)
    y = np.where(v, np.where(label >= 0, label, spec.n_agents), IGNORE).astype(np.int64)
    return x, y


def swap_identities(arrays: RobotArrays, a: int, b: int, start_s: float, stop_s: float) -> RobotArrays:
    """``arrays`` with robots ``a`` and ``b`` sending each other's reports from ``start_s`` to ``stop_s`` (send time,
    s); their detection labels swap on the frames whose newest received report of either was sent then."""
    r = arrays.reports
    sent_in = (r.t_sent >= start_s) & (r.t_sent < stop_s)
    agent = r.agent_id.copy()
    agent[sent_in & (r.agent_id == a)] = b
    agent[sent_in & (r.agent_id == b)] = a
    swapped = dataclasses.replace(arrays, reports=dataclasses.replace(r, agent_id=agent))
    _, sent = latest_reports(swapped, max(a, b) + 1)
    frames = np.asarray(((sent[:, [a, b]] >= start_s) & (sent[:, [a, b]] < stop_s)).any(axis=1))[:, None]
    label = arrays.det_label
    label = np.where(frames & (label == a), b, np.where(frames & (label == b), a, label))
    return dataclasses.replace(swapped, det_label=label)


def silence_agent(arrays: RobotArrays, agent: int, start_s: float, stop_s: float) -> RobotArrays:
    """``arrays`` without the reports ``agent`` sent from ``start_s`` to ``stop_s`` (seconds)."""
    r = arrays.reports
    keep = ~((r.agent_id == agent) & (r.t_sent >= start_s) & (r.t_sent < stop_s))
    kept_before = np.concatenate([[0], np.cumsum(keep)])  # rows kept among the first k
    reports = dataclasses.replace(r, agent_id=r.agent_id[keep], t_sent=r.t_sent[keep],
                                  t_received=r.t_received[keep], heading=r.heading[keep],
                                  frame_offsets=kept_before[r.frame_offsets])
    return dataclasses.replace(arrays, reports=reports)


@dataclasses.dataclass(frozen=True)
class SimSampler:
    """A picklable ``(seed, n_frames, rng) -> (x, y)`` sampler; ``swap_prob``: share of 1–10 s identity swaps."""

    config: RobotWorldConfig
    relative: bool = True
    swap_prob: float = 0.0

    def __post_init__(self) -> None:
        if not 0.0 <= self.swap_prob <= 1.0:
            raise ValueError(f"swap_prob must lie in [0, 1], got {self.swap_prob}")

    def __call__(self, seed: int, n_frames: int, rng: np.random.Generator | None) -> tuple[np.ndarray, np.ndarray]:
        cfg = self.config
        spec = EncodingSpec(cfg.n_agents, cfg.max_detections, relative_headings=self.relative)
        arrays = simulate_arrays(cfg, n_frames, seed)
        aug = np.random.default_rng([seed, 0x5A5])
        if cfg.n_agents >= 2 and aug.random() < self.swap_prob:
            a, b = aug.choice(cfg.n_agents, 2, replace=False)
            duration_s = n_frames / cfg.frame_rate_hz
            start = aug.uniform(0.0, 0.8 * duration_s)
            arrays = swap_identities(arrays, int(a), int(b), start, start + aug.uniform(1.0, 10.0))
        return arrays_to_training(spec, arrays, rng)


def mix_pick(seed: int, count: int) -> int:
    """Which of ``count`` worlds the sequence of ``seed`` is drawn from (uniform, fixed by the seed)."""
    return int(np.random.default_rng([seed, 0x401]).integers(count))


@dataclasses.dataclass(frozen=True)
class WorldMixSampler:
    """A picklable ``(seed, n_frames, rng) -> (x, y)`` sampler over ``samplers`` (:func:`mix_pick`)."""

    samplers: tuple[SimSampler, ...]

    def __post_init__(self) -> None:
        if not self.samplers:
            raise ValueError("WorldMixSampler needs at least one sampler")

    def __call__(self, seed: int, n_frames: int, rng: np.random.Generator | None) -> tuple[np.ndarray, np.ndarray]:
        return self.samplers[mix_pick(seed, len(self.samplers))](seed, n_frames, rng)


def make_sim_sampler(config: RobotWorldConfig, relative: bool = True, swap_prob: float = 0.0) -> SimSampler:
    """A ``(seed, n_frames, rng) -> (x, y)`` sampler over the robot world ``config``."""
    return SimSampler(config, relative, swap_prob)
