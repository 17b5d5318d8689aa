"""Training arrays for the set associator (any team size) from the robot simulator: agent tokens
``cos ψ, sin ψ, age / max_age, known`` and detection tokens ``x, y, cos φ, sin φ, γ`` (metres, observer frame).
A team size ``(N, M, false positives per frame)`` is drawn per batch from its seed."""

from __future__ import annotations

import dataclasses

import numpy as np

from lookalike.learn.data import IGNORE
from lookalike.learn.sim_data import latest_reports, mix_pick, silence_agent, slot_order, swap_identities
from lookalike.sim import NOISE_MODELS, RobotArrays, RobotWorldConfig, noise_sensor, simulate_arrays
from lookalike.sim.robots_config import SensorConfig
from lookalike.trackers.set.network import agent_tokens, detection_tokens


def arrays_to_tokens(arrays: RobotArrays, n_agents: int, rng: np.random.Generator | None = None
                     ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """``agents (T, N, 4)``, ``detections (T, M, 5)``, ``valid (T, M)`` and targets ``(T, M)``
    (agent id, N for a false positive, ``IGNORE`` for an empty slot). With ``rng`` the occupied
    slots are shuffled per frame (the network must not rely on their order)."""
    T, M = arrays.det_valid.shape
    heading, sent = latest_reports(arrays, n_agents)
    agents = agent_tokens(heading, arrays.time[:, None] - sent)
    order = slot_order(arrays, rng)

    def take(a: np.ndarray) -> np.ndarray:
        return np.take_along_axis(a, order, axis=1)

    v = take(arrays.det_valid)
    pos = np.stack([take(arrays.det_position[..., 0]), take(arrays.det_position[..., 1])], axis=-1)
    dets = detection_tokens(pos, take(arrays.det_heading), take(arrays.det_score)) * v[..., None]
    label = take(arrays.det_label)
    y = np.where(v, np.where(label >= 0, label, n_agents), IGNORE).astype(np.int64)
    return agents, dets, v, y


@dataclasses.dataclass(frozen=True)
class TeamSizes:
    """Team sizes drawn per batch: N in ``[n_min, n_max]``, M in ``[N, 2N + m_extra]``, fp uniform in ``fp_range``."""

    n_min: int = 1
    n_max: int = 12
    m_extra: int = 3
    fp_range: tuple[float, float] = (0.3, 2.5)
    focus: tuple[tuple[int, int, float], ...] = ()
    focus_prob: float = 0.0

    def __post_init__(self) -> None:
        if not 1 <= self.n_min <= self.n_max:
            raise ValueError(f"TeamSizes: need 1 <= n_min <= n_max, got {self.n_min}, {self.n_max}")
        if not 0.0 <= self.focus_prob <= 1.0 or (self.focus_prob > 0 and not self.focus):
            raise ValueError(f"TeamSizes: need 0 <= focus_prob <= 1 and focus teams when > 0, got {self.focus_prob}")

    def draw(self, rng: np.random.Generator) -> tuple[int, int, float]:
        """``(N, M, false positives per frame)``; one of the ``focus`` teams with ``focus_prob``."""
        if self.focus_prob > 0 and rng.random() < self.focus_prob:
            n, m, fp = self.focus[int(rng.integers(len(self.focus)))]
            return int(n), int(m), float(fp)
        n = int(rng.integers(self.n_min, self.n_max + 1))
        m = int(rng.integers(max(n, 1), 2 * n + self.m_extra + 1))
        return n, m, float(rng.uniform(*self.fp_range))


def world(n_agents: int, n_slots: int, fp_per_frame: float, frame_rate_hz: float = 30.0) -> RobotWorldConfig:
    """The default robot world with ``n_agents`` robots, ``n_slots`` kept detections and this clutter."""
    return RobotWorldConfig(n_agents=n_agents, max_detections=n_slots, frame_rate_hz=frame_rate_hz,
                            sensor=dataclasses.replace(SensorConfig(), fp_per_frame=fp_per_frame))


Batch = tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, float]


def closest_headings(arrays: RobotArrays, at_s: float) -> tuple[int, int]:
    """The two robots (lower id first) whose true headings are closest at ``at_s`` seconds."""
    t = min(int(np.searchsorted(arrays.time, at_s)), len(arrays) - 1)
    h = arrays.true_heading[t]
    gap = np.abs(np.angle(np.exp(1j * (h[:, None] - h[None, :]))))
    gap[np.diag_indices_from(gap)] = np.inf
    i, j = np.unravel_index(int(np.argmin(gap)), gap.shape)
    return int(min(i, j)), int(max(i, j))


@dataclasses.dataclass(frozen=True)
class SetBatchMaker:
    """A picklable ``(seed, batch_size, n_frames) -> batch``: ``agents (B, T, N, 4)``, ``detections (B, T, M, 5)``,
    ``valid (B, T, M)``, targets ``(B, T, M)`` and the frame interval (s).

    ``swap_prob``: fraction of sequences where two robots exchange identities for ``swap_s`` seconds (ending
    ``swap_ends`` s before the sequence's end when given). ``fixed``: one ``(N, M, fp)`` instead of ``sizes``.
    ``noises``: position-noise models, one drawn per sequence. ``close_swap_prob``: fraction of swaps between the
    two robots with the closest true headings. ``silent_swap_prob``: fraction of swaps ending inside a 1–3 s
    silence of one of the two agents."""

    sizes: TeamSizes = TeamSizes()
    swap_prob: float = 0.0
    fixed: tuple[int, int, float] | None = None
    swap_s: tuple[float, float] = (1.0, 10.0)
    swap_ends: float | None = None
    noises: tuple[str, ...] = ()
    close_swap_prob: float = 0.0
    silent_swap_prob: float = 0.0

    def __post_init__(self) -> None:
        unknown = [x for x in self.noises if x not in NOISE_MODELS]
        if unknown:
            raise ValueError(f"SetBatchMaker: unknown noise models {unknown}; known: {', '.join(NOISE_MODELS)}")
        for name in ("close_swap_prob", "silent_swap_prob"):
            if not 0.0 <= getattr(self, name) <= 1.0:
                raise ValueError(f"SetBatchMaker: {name} must lie in [0, 1], got {getattr(self, name)}")

    def world_of(self, cfg: RobotWorldConfig, seed: int) -> RobotWorldConfig:
        """The world of the sequence of ``seed``: ``cfg`` with the noise model :attr:`noises` draws for it."""
        if not self.noises:
            return cfg
        noise = self.noises[mix_pick(seed, len(self.noises))]
        return dataclasses.replace(cfg, sensor=noise_sensor(noise, cfg.sensor))

    def __call__(self, seed: int, batch_size: int, n_frames: int) -> Batch:
        n, m, fp = self.fixed or self.sizes.draw(np.random.default_rng([seed, 0x5E7]))
        cfg = world(n, m, fp)
        out = []
        for b in range(batch_size):
            s = seed * 1000 + b
            arrays = simulate_arrays(self.world_of(cfg, s), n_frames, s)
            aug = np.random.default_rng([s, 0x5A5])
            if n >= 2 and aug.random() < self.swap_prob:
                i, j = aug.choice(n, 2, replace=False)
                length_s = n_frames * cfg.dt_s
                if self.swap_ends is None:
                    start = aug.uniform(0.0, 0.8 * length_s)
                    stop = start + aug.uniform(*self.swap_s)
                else:
                    duration = min(aug.uniform(*self.swap_s), max(length_s - self.swap_ends - 1.0, 0.5))
                    start = aug.uniform(0.5, max(length_s - self.swap_ends - duration, 0.5))
                    stop = start + duration
                if self.close_swap_prob > 0 and aug.random() < self.close_swap_prob:
                    i, j = closest_headings(arrays, start)
                arrays = swap_identities(arrays, int(i), int(j), start, stop)
                if self.silent_swap_prob > 0 and aug.random() < self.silent_swap_prob:
                    quiet = int(i if aug.random() < 0.5 else j)
                    begin = stop - aug.uniform(0.2, 1.5)
                    arrays = silence_agent(arrays, quiet, begin, begin + aug.uniform(1.0, 3.0))
            out.append(arrays_to_tokens(arrays, n, np.random.default_rng([s, 1])))
        a, d, v, y = (np.stack(parts) for parts in zip(*out))
        k = max(int(v.sum(-1).max()), 1)  # occupied slots come first: drop the columns empty everywhere
        return a, d[:, :, :k], v[:, :, :k], y[:, :, :k], cfg.dt_s
