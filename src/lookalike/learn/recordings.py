"""Training arrays from labelled recordings for fine-tuning; validation splits by recording."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from lookalike.learn.data import IGNORE
from lookalike.learn.paper_protocol import NoiseMixSampler, arrays_to_training_paper
from lookalike.learn.sim_data import arrays_to_training
from lookalike.sim import RobotArrays, RobotSequence, RobotWorldConfig
from lookalike.trackers.lstm.encoding import EncodingSpec


def recording_arrays(spec: EncodingSpec, arrays: RobotArrays, rng: np.random.Generator | None = None
                     ) -> tuple[np.ndarray, np.ndarray]:
    """Inputs ``(T, n_inputs)`` and targets ``(T, M)`` of a whole recording in ``spec``'s layout."""
    if spec.protocol == "paper":
        return arrays_to_training_paper(spec, arrays, rng)
    return arrays_to_training(spec, arrays, rng)


def check_recordings(spec: EncodingSpec, recordings: Sequence[RobotSequence], names: Sequence[str]) -> None:
    """``ValueError`` naming the first recording whose N or M differs from the network's, or without detections."""
    for rec, name in zip(recordings, names):
        n, m = rec.config.n_agents, rec.config.max_detections
        if (n, m) != (spec.n_agents, spec.n_slots):
            raise ValueError(f"{name}: recorded with N={n}, M={m}, but the network has N={spec.n_agents}, "
                             f"M={spec.n_slots}")
        if not rec.arrays.det_valid.any():
            raise ValueError(f"{name}: holds no detection to learn from")


def without_robots(recordings: Sequence[RobotSequence], names: Sequence[str]) -> list[str]:
    """The names of the recordings none of whose detections is labelled as a robot: they teach only false positives
    (the robots out of view throughout, or an export of a sequence nobody labelled)."""
    return [name for rec, name in zip(recordings, names)
            if not (rec.arrays.det_label[rec.arrays.det_valid] >= 0).any()]


def split_recordings(n: int, validation_fraction: float, seed: int = 0) -> tuple[list[int], list[int]]:
    """Indices ``(training, validation)`` of ``n`` >= 2 recordings, ``round(fraction·n)`` >= 1 for validation."""
    if n < 2:
        raise ValueError(f"need at least 2 recordings for a validation split by recording, got {n}")
    if not 0.0 < validation_fraction < 1.0:
        raise ValueError(f"validation fraction must lie in (0, 1), got {validation_fraction}")
    k = min(max(1, round(validation_fraction * n)), n - 1)
    order = np.random.default_rng([seed, 0x5B1]).permutation(n)
    return sorted(int(i) for i in order[k:]), sorted(int(i) for i in order[:k])


def _pad(x: np.ndarray, y: np.ndarray, length: int) -> tuple[np.ndarray, np.ndarray]:
    if len(x) >= length:
        return x[:length], y[:length]
    xp = np.zeros((length, x.shape[1]))
    yp = np.full((length, y.shape[1]), IGNORE, dtype=np.int64)
    xp[: len(x)], yp[: len(y)] = x, y
    return xp, yp


@dataclass(frozen=True)
class RecordingSampler:
    """A picklable ``(seed, n_frames, rng) -> (x, y)`` sampler of windows of ``recordings`` (the seed picks one by
    length and a start; short ones padded); ``sim_fraction``: share simulated in ``world`` instead."""

    spec: EncodingSpec
    recordings: tuple[RobotArrays, ...]
    world: RobotWorldConfig | None = None
    sim_fraction: float = 0.0

    def __post_init__(self) -> None:
        if not self.recordings:
            raise ValueError("RecordingSampler: needs at least one recording")
        if not 0.0 <= self.sim_fraction <= 1.0:
            raise ValueError(f"simulated fraction must lie in [0, 1], got {self.sim_fraction}")
        if self.sim_fraction > 0 and self.world is None:
            raise ValueError("RecordingSampler: a simulated fraction needs the world to simulate")

    def __call__(self, seed: int, n_frames: int, rng: np.random.Generator | None) -> tuple[np.ndarray, np.ndarray]:
        draw = np.random.default_rng([seed, 0x2EC])
        if draw.random() < self.sim_fraction and self.world is not None:
            return NoiseMixSampler((self.world,), self.spec)(seed, n_frames, rng)
        lengths = np.array([len(a) for a in self.recordings], dtype=float)
        k = int(draw.choice(len(lengths), p=lengths / lengths.sum()))
        x, y = recording_arrays(self.spec, self.recordings[k], rng)
        start = int(draw.integers(0, max(len(x) - n_frames, 0) + 1))
        return _pad(x[start:], y[start:], n_frames)


def validation_arrays(spec: EncodingSpec, recordings: Sequence[RobotArrays], bptt: int
                      ) -> tuple[np.ndarray, np.ndarray]:
    """Whole recordings as one batch ``(B, T, n_inputs)``, ``(B, T, M)``, padded to a multiple of ``bptt``."""
    pairs = [recording_arrays(spec, a) for a in recordings]
    longest = max(len(x) for x, _ in pairs)
    length = -(-longest // bptt) * bptt
    xs, ys = zip(*(_pad(x, y, length) for x, y in pairs))
    return np.stack(xs), np.stack(ys)


__all__ = ["RecordingSampler", "check_recordings", "recording_arrays", "split_recordings", "validation_arrays",
           "without_robots"]
