"""Training arrays straight from the robot simulator's arrays (vectorised over time)."""

from __future__ import annotations

import numpy as np

from lookalike.learn.data import IGNORE
from lookalike.learn.encoding import AGENT_WIDTH, EncodingSpec, encode_agents, relative_headings
from lookalike.sim import RobotArrays, RobotWorldConfig, simulate_arrays


def latest_reports(arrays: RobotArrays, n_agents: int) -> tuple[np.ndarray, np.ndarray]:
    """Per frame and agent, the newest report received so far (by send time): headings and send
    times ``(T, N)``, NaN where nothing was received yet. Late reports older than the kept one are
    ignored, as :class:`~lookalike.learn.tracker.BeaconMemory` does at inference."""
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
    """Inputs ``(T, n_inputs)`` and targets ``(T, M)`` from a simulated sequence.

    Equal to :func:`lookalike.learn.data.frames_to_arrays` on the same sequence's frames; with
    ``rng`` the occupied slots are shuffled per frame, else ordered most probable first.
    """
    T, M = arrays.det_valid.shape
    if M != spec.n_slots:
        raise ValueError(f"the sequence has {M} detection slots, the encoding {spec.n_slots}")
    heading, sent = latest_reports(arrays, spec.n_agents)
    x = np.zeros((T, spec.n_inputs))
    n_agent_inputs = AGENT_WIDTH * spec.n_agents
    x[:, :n_agent_inputs] = encode_agents(spec, heading, arrays.time[:, None] - sent)
    valid = arrays.det_valid
    key = -arrays.det_score if rng is None else rng.random((T, M))
    order = np.argsort(np.where(valid, key, np.inf), axis=1, kind="stable")
    take = lambda a: np.take_along_axis(a, order, axis=1)  # noqa: E731
    v = take(valid)
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


def make_sim_sampler(config: RobotWorldConfig, relative: bool = True):
    """A ``(seed, n_frames, rng) -> (x, y)`` sampler over the robot world ``config``."""
    spec = EncodingSpec(config.n_agents, config.max_detections, relative_headings=relative)

    def sample(seed: int, n_frames: int, rng: np.random.Generator | None) -> tuple[np.ndarray, np.ndarray]:
        return arrays_to_training(spec, simulate_arrays(config, n_frames, seed), rng)

    return sample
