"""Training arrays in the robot-identification paper's layout ``N + 4·M``, and a noise-mix sampler."""

from __future__ import annotations

import dataclasses

import numpy as np

from lookalike.learn.data import IGNORE
from lookalike.learn.sim_data import arrays_to_training, latest_reports, mix_pick, slot_order
from lookalike.sim import RobotArrays, RobotWorldConfig, simulate_arrays
from lookalike.trackers.lstm.encoding import EncodingSpec, encode_agents_paper

NOISE_CHOICES = ("ours", "paper", "mix")


def arrays_to_training_paper(
    spec: EncodingSpec, arrays: RobotArrays, rng: np.random.Generator | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """Inputs ``(T, N + 4·M)`` and targets ``(T, M)`` in the paper's layout; slots ordered by ``slot_order``."""
    if spec.protocol != "paper":
        raise ValueError(f"arrays_to_training_paper needs an encoding of protocol 'paper', got {spec.protocol!r}")
    T, M = arrays.det_valid.shape
    if M != spec.n_slots:
        raise ValueError(f"the sequence has {M} detection slots, the encoding {spec.n_slots}")
    heading, _ = latest_reports(arrays, spec.n_agents)
    order = slot_order(arrays, rng)

    def take(a: np.ndarray) -> np.ndarray:
        return np.take_along_axis(a, order, axis=1)

    v = take(arrays.det_valid)
    columns = [take(arrays.det_position[..., 0]), take(arrays.det_position[..., 1]),
               encode_agents_paper(take(arrays.det_heading)), take(arrays.det_score)]
    slots = np.stack(columns, axis=-1) * v[..., None]
    x = np.concatenate([encode_agents_paper(heading), slots.reshape(T, -1)], axis=1)
    label = take(arrays.det_label)
    y = np.where(v, np.where(label >= 0, label, spec.n_agents), IGNORE).astype(np.int64)
    return x, y


@dataclasses.dataclass(frozen=True)
class NoiseMixSampler:
    """A picklable ``(seed, n_frames, rng) -> (x, y)`` sampler over ``worlds`` (:func:`mix_pick`)."""

    worlds: tuple[RobotWorldConfig, ...]
    spec: EncodingSpec

    def __post_init__(self) -> None:
        if not self.worlds:
            raise ValueError("NoiseMixSampler needs at least one world")
        for w in self.worlds:
            if (w.n_agents, w.max_detections) != (self.spec.n_agents, self.spec.n_slots):
                raise ValueError(f"world of N={w.n_agents}, M={w.max_detections} does not fit the encoding "
                                 f"N={self.spec.n_agents}, M={self.spec.n_slots}")

    def __call__(self, seed: int, n_frames: int, rng: np.random.Generator | None) -> tuple[np.ndarray, np.ndarray]:
        arrays = simulate_arrays(self.worlds[mix_pick(seed, len(self.worlds))], n_frames, seed)
        if self.spec.protocol == "paper":
            return arrays_to_training_paper(self.spec, arrays, rng)
        return arrays_to_training(self.spec, arrays, rng)


def noise_worlds(setup: str, noise: str) -> tuple[RobotWorldConfig, ...]:
    """The worlds of preset ``setup`` for ``noise``: ``"ours"``, ``"paper"`` or ``"mix"`` (both)."""
    from lookalike.sim import preset

    if noise not in NOISE_CHOICES:
        raise ValueError(f"noise: unknown choice {noise!r}; known: {', '.join(NOISE_CHOICES)}")
    names = ("ours", "paper") if noise == "mix" else (noise,)
    return tuple(preset(setup, n) for n in names)
