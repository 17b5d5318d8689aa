"""Per-detection labels from identified tracks."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from lookalike.types import Tracks, TrackSnapshot


def labels_from_tracks(n_detections: int, tracks: Sequence[TrackSnapshot]) -> np.ndarray:
    """``(n_detections,)`` agent id of the identified track that took each detection, else -1.

    A detection claimed by several identified tracks goes to the most confident one (``identity_prob``); an agent
    claimed for several detections keeps the most confident."""
    if n_detections < 0:
        raise ValueError(f"n_detections must be >= 0, got {n_detections}")
    if isinstance(tracks, Tracks):
        return np.array(_label_list(n_detections, tracks), dtype=int)  # (columns read as lists: a frame is small)
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


def label_list(n_detections: int, tracks: Sequence[TrackSnapshot]) -> list[int]:
    """:func:`labels_from_tracks` as a list of ints."""
    if isinstance(tracks, Tracks) and n_detections >= 0:
        return _label_list(n_detections, tracks)
    out: list[int] = labels_from_tracks(n_detections, tracks).tolist()
    return out


def _label_list(n_detections: int, tracks: Tracks) -> list[int]:
    label = [-1] * n_detections
    k = len(tracks)
    if tracks.agent_id is None or not k:
        return label
    agent, det = tracks.agent_id.tolist(), tracks.detection_index.tolist()
    prob = [0.0] * k if tracks.identity_prob is None else [0.0 if p != p else p for p in tracks.identity_prob.tolist()]
    rows = [i for i in range(k) if agent[i] >= 0 and det[i] >= 0]
    rows.sort(key=prob.__getitem__, reverse=True)  # (stable: ties keep their order)
    best = [-np.inf] * n_detections
    claimed = set()
    for i in rows:
        a, d, p = agent[i], det[i], prob[i]
        if d >= n_detections:
            raise ValueError(f"track {int(tracks.id[i])}: detection_index {d} out of range for "
                             f"{n_detections} detections")
        if a in claimed or p <= best[d]:
            continue
        label[d], best[d] = a, p
        claimed.add(a)
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
