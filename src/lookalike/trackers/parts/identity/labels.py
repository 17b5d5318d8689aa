"""Per-detection labels from identified tracks."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from lookalike.types import Tracks, TrackSnapshot


def labels_from_tracks(n_detections: int, tracks: Sequence[TrackSnapshot]) -> np.ndarray:
    """``(n_detections,)`` agent id of the identified track that took each detection, else -1.

    A detection claimed by several identified tracks goes to the most confident one (``identity_prob``); an agent
    claimed for several detections keeps the most confident."""
    return np.array(label_list(n_detections, tracks), dtype=int)


def label_list(n_detections: int, tracks: Sequence[TrackSnapshot]) -> list[int]:
    """:func:`labels_from_tracks` as a list of ints (the columns of :class:`Tracks` read as lists: a frame is small)."""
    if n_detections < 0:
        raise ValueError(f"n_detections must be >= 0, got {n_detections}")
    if not isinstance(tracks, Tracks):  # (agent, detection, probability, track id), the most confident first
        ranked = sorted(((t.agent_id, t.detection_index, 0.0 if t.identity_prob is None else t.identity_prob,
                          t.track_id) for t in tracks if t.agent_id is not None and t.detection_index >= 0),
                        key=lambda row: -row[2])
    elif tracks.agent_id is None or not len(tracks):
        ranked = []
    else:
        agent, det, k = tracks.agent_id.tolist(), tracks.detection_index.tolist(), len(tracks)
        given = tracks.identity_prob
        prob = [0.0] * k if given is None else [0.0 if p != p else p for p in given.tolist()]  # (NaN: 0)
        rows = [i for i in range(k) if agent[i] >= 0 and det[i] >= 0]
        rows.sort(key=prob.__getitem__, reverse=True)  # (stable: ties keep their order)
        ranked = [(agent[i], det[i], prob[i], int(tracks.id[i])) for i in rows]
    label = [-1] * n_detections
    best = [-np.inf] * n_detections
    claimed = set()
    for a, d, p, track_id in ranked:
        if d >= n_detections:
            raise ValueError(f"track {track_id}: detection_index {d} out of range for {n_detections} detections")
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
