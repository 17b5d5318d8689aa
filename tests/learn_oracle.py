"""Training arrays built frame by frame: the oracle :func:`lookalike.learn.sim_data.arrays_to_training` must equal."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from lookalike.learn.data import IGNORE
from lookalike.trackers.lstm.encoding import EncodingSpec, encode_agents, encode_slots
from lookalike.trackers.parts.agents import BeaconMemory
from lookalike.types import Frame


def frames_to_arrays(
    spec: EncodingSpec, frames: Sequence[Frame], rng: np.random.Generator | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """Inputs ``(T, n_inputs)`` and slot targets ``(T, M)`` from frames with ``Detections.label``.

    Targets are the agent id, N for a false positive (label -1) and ``IGNORE`` for empty slots. Detections are put into
    slots in random order when ``rng`` is given (slot shuffling, as in training), else most probable first."""
    T = len(frames)
    x = np.zeros((T, spec.n_inputs))
    y = np.full((T, spec.n_slots), IGNORE, dtype=np.int64)
    memory = BeaconMemory(spec.n_agents)
    n_agent_inputs = 3 * spec.n_agents
    for t, frame in enumerate(frames):
        memory.add(frame)
        det = frame.detections
        if det.label is None or det.position is None or det.heading is None or det.score is None:
            raise ValueError(f"frame {frame.index}: training frames need position, heading, score and label")
        keep = np.argsort(-det.score, kind="stable")[: spec.n_slots]
        if rng is not None:
            keep = rng.permutation(keep)
        x[t, :n_agent_inputs] = encode_agents(spec, memory.heading[None], memory.age(frame.time)[None])[0]
        x[t, n_agent_inputs:] = encode_slots(
            spec, det.position[keep], det.heading[keep], det.score[keep], memory.heading
        )
        labels = det.label[keep]
        y[t, : len(keep)] = np.where(labels >= 0, labels, spec.n_agents)
    return x, y
