"""Per-detection labels from identified tracks."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from lookalike.types import TrackSnapshot


def labels_from_tracks(n_detections: int, tracks: Sequence[TrackSnapshot]) -> np.ndarray:
    """``(n_detections,)`` agent id of the identified track that took each detection, else -1.

    A detection claimed by several identified tracks goes to the most confident one
    (``identity_prob``); an agent claimed for several detections keeps the most confident.
    """
    if n_detections < 0:
        raise ValueError(f"n_detections must be >= 0, got {n_detections}")
    label = np.full(n_detections, -1, dtype=int)
    best = np.full(n_detections, -np.inf)
    claimed: dict[int, float] = {}
    ranked = sorted(
        (t for t in tracks if t.agent_id is not None and t.detection_index >= 0),
        key=lambda t: -(t.identity_prob if t.identity_prob is not None else 0.0),
    )
    for t in ranked:
        agent, k = t.agent_id, t.detection_index
        if agent is None:
            continue
        if k >= n_detections:
            raise ValueError(f"track {t.track_id}: detection_index {k} out of range for {n_detections} detections")
        p = t.identity_prob if t.identity_prob is not None else 0.0
        if agent in claimed or p <= best[k]:
            continue
        label[k], best[k] = agent, p
        claimed[agent] = p
    return label


def agent_positions(tracks: Sequence[TrackSnapshot], n_agents: int) -> np.ndarray:
    """``(N, 2)`` position (m) of each agent's most confident identified track, NaN when none."""
    out = np.full((n_agents, 2), np.nan)
    best = np.full(n_agents, -np.inf)
    for t in tracks:
        if t.agent_id is not None and t.position is not None and 0 <= t.agent_id < n_agents:
            p = t.identity_prob if t.identity_prob is not None else 0.0
            if p > best[t.agent_id]:
                out[t.agent_id], best[t.agent_id] = t.position, p
    return out
