"""What the learned identifiers share: the agents' latest heading reports, decoding class probabilities into
one detection per agent, and the agents as tracks (one snapshot per agent, positioned by a localiser).

Used by ``set`` (:mod:`lookalike.trackers.set.tracker`) and the LSTM identifier (``lookalike.trackers.lstm.tracker``).
"""

from __future__ import annotations

import numpy as np

from lookalike.trackers.parts.identity.localiser import KalmanLocaliser, LowPassLocaliser
from lookalike.types import Frame, TrackSnapshot, TrackStatus


class BeaconMemory:
    """The latest heading report per agent, keeping the newest by send time (late duplicates ignored)."""

    def __init__(self, n_agents: int) -> None:
        self.heading = np.full(n_agents, np.nan)
        self.t_sent = np.full(n_agents, -np.inf)

    def add(self, frame: Frame) -> None:
        b = frame.beacons
        for agent, t_sent, heading in zip(b.agent_id, b.t_sent, b.heading):
            if agent < len(self.heading) and t_sent > self.t_sent[agent]:
                self.t_sent[agent] = t_sent
                self.heading[agent] = heading

    def age(self, time_s: float) -> np.ndarray:
        """Seconds since each agent's latest report was sent (NaN: never heard)."""
        age = time_s - self.t_sent
        return np.where(np.isfinite(age), age, np.nan)


def decode(prob: np.ndarray, n_used: int, one_to_one: bool) -> tuple[np.ndarray, np.ndarray]:
    """Labels ``(n_used,)`` (agent or -1) and their probabilities from slot probabilities ``(M, N+1)``."""
    p = prob[:n_used]
    n_agents = p.shape[1] - 1
    if not one_to_one:
        label = p.argmax(axis=1)
        conf = p[np.arange(n_used), label]
        return np.where(label == n_agents, -1, label), conf
    # Each detection may be a false positive; each agent takes at most one detection.
    cost = -np.log(np.clip(np.hstack([p[:, :n_agents], np.repeat(p[:, n_agents:], n_used, axis=1)]), 1e-12, 1))
    from scipy.optimize import linear_sum_assignment  # imported on first use (slow to import)

    rows, cols = linear_sum_assignment(cost)
    label = np.full(n_used, -1)
    label[rows] = np.where(cols < n_agents, cols, -1)
    conf = np.where(label >= 0, p[np.arange(n_used), np.maximum(label, 0)], p[:, n_agents])
    return label, conf


def agent_detections(labels: np.ndarray, conf: np.ndarray, n_agents: int) -> np.ndarray:
    """``(n_agents,)`` each agent's most confident detection (index into ``labels``), -1 for none."""
    det_of_agent = np.full(n_agents, -1)
    for k in np.argsort(-conf):
        j = labels[k]
        if j >= 0 and det_of_agent[j] < 0:
            det_of_agent[j] = k
    return det_of_agent


def agent_snapshots(labels: np.ndarray, conf: np.ndarray, position: np.ndarray, heading: np.ndarray,
                    localiser: LowPassLocaliser | KalmanLocaliser, last_seen: np.ndarray,
                    frame: Frame) -> list[TrackSnapshot]:
    """One snapshot per agent seen so far, from the frame's detection labels (-1: false positive) and
    their probabilities ``conf``; ``position`` ``(n, 2)`` m and ``heading`` ``(n,)`` rad of the detections.
    Each agent's most confident detection updates ``localiser``; ``last_seen`` (the frame index each
    agent last took a detection, -1 never) is updated in place."""
    n_agents = len(last_seen)
    det_of_agent = agent_detections(labels, conf, n_agents)
    assigned = det_of_agent >= 0
    measured = np.full((n_agents, 2), np.nan)
    weight = np.zeros(n_agents)
    measured[assigned] = position[det_of_agent[assigned]]
    weight[assigned] = conf[det_of_agent[assigned]]
    located = localiser.update(frame.time, measured, weight)
    fallback = assigned & ~np.isfinite(located).all(axis=1)  # labels never depend on the localiser
    located[fallback] = measured[fallback]
    snapshots = []
    for j in range(n_agents):
        k = det_of_agent[j]
        if k >= 0:
            last_seen[j] = frame.index
        if last_seen[j] < 0 or not np.isfinite(located[j]).all():
            continue  # never seen, or lost for longer than the localiser keeps a position
        snapshots.append(TrackSnapshot(
            track_id=j + 1,
            status=TrackStatus.CONFIRMED if k >= 0 else TrackStatus.LOST,
            position=located[j].copy(),
            heading=float(heading[k]) if k >= 0 else None,
            agent_id=j,
            identity_prob=float(conf[k]) if k >= 0 else None,
            detection_index=int(k),
        ))
    return snapshots
