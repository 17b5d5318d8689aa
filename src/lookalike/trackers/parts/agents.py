"""What the learned identifiers (``set``, ``lstm``) share: the agents' latest heading reports, decoding class
probabilities into one detection per agent, and the agents as tracks (one snapshot per agent, positioned by a
localiser)."""

from __future__ import annotations

import math
from typing import ClassVar

import numpy as np

from lookalike._lsap import linear_sum_assignment
from lookalike.trackers.base import NEEDS_ROBOTS
from lookalike.trackers.kernels.world import filled
from lookalike.trackers.parts.identity.localiser import make_localiser
from lookalike.trackers.parts.timing import RESET_HINT
from lookalike.types import Frame, TrackSnapshot, TrackStatus


class BeaconMemory:
    """The latest heading report per agent, keeping the newest by send time (late duplicates ignored)."""

    def __init__(self, n_agents: int) -> None:
        self.heading = np.full(n_agents, np.nan)
        self.t_sent = np.full(n_agents, -np.inf)

    def add(self, frame: Frame) -> None:
        b = frame.beacons
        b.require_agents(len(self.heading))
        for agent, t_sent, heading in zip(b.agent_id.tolist(), b.t_sent.tolist(), b.heading.tolist()):
            if t_sent > self.t_sent[agent]:
                self.t_sent[agent] = t_sent
                self.heading[agent] = heading

    def age(self, time_s: float) -> np.ndarray:
        """Seconds since each agent's latest report was sent (NaN: never heard)."""
        age = time_s - self.t_sent
        return np.where(np.isfinite(age), age, np.nan)


class AgentIdentifier:
    """The learned identifiers' state besides their network: reports, positions, the frame time, the latest labels."""

    needs: ClassVar[str] = NEEDS_ROBOTS
    name: ClassVar[str] = "identifier"  # (the registered name of a subclass)

    def _reset_agents(self, n_agents: int, localiser: str) -> None:
        self._beacons = BeaconMemory(n_agents)
        self._localiser = make_localiser(localiser, n_agents)
        self._last_seen = np.full(n_agents, -1)
        self.last_labels = np.zeros(0, dtype=int)
        self.last_probabilities = np.zeros(0)
        self._last_time = -np.inf

    def _step_time(self, frame: Frame) -> float:
        """Seconds since the previous frame (0 at the first). ``ValueError``, changing nothing, when time goes
        backwards, for a report from an unknown agent, or for detections without position, heading and score."""
        det = frame.detections
        if len(det) and (det.position is None or det.heading is None or det.score is None):
            raise ValueError(f"{self.name}: frame.detections need position (m), heading (rad) and score columns")
        frame.beacons.require_agents(len(self._last_seen))
        if frame.time < self._last_time:
            raise ValueError(f"frame time went backwards: {self._last_time} s then {frame.time} s{RESET_HINT}")
        dt = 0.0 if not math.isfinite(self._last_time) else frame.time - self._last_time
        self._last_time = frame.time
        return dt

    def _snapshots(self, labels: np.ndarray, conf: np.ndarray, position: np.ndarray, heading: np.ndarray,
                   frame: Frame, det_of_agent: np.ndarray | None = None) -> list[TrackSnapshot]:
        """One snapshot per agent seen so far from the frame's detection labels (-1: false positive), their
        probabilities ``conf``, positions ``(n, 2)`` m and headings ``(n,)`` rad; each agent's most confident
        detection (``det_of_agent``: :func:`agent_detections`' when given) updates the localiser and the frame each
        agent last took a detection (-1: never)."""
        last_seen = self._last_seen
        n_agents = len(last_seen)
        if det_of_agent is None:
            det_of_agent = agent_detections(labels, conf, n_agents)
        assigned = det_of_agent >= 0
        measured = filled((n_agents, 2), np.nan)
        weight = np.zeros(n_agents)
        taken = det_of_agent[assigned]
        measured[assigned] = position[taken]
        weight[assigned] = conf[taken]
        located = self._localiser.update(frame.time, measured, weight)
        finite = np.logical_and.reduce(np.isfinite(located), axis=1)
        fallback = assigned & ~finite  # labels never depend on the localiser
        if fallback.any():
            located[fallback] = measured[fallback]
            finite = np.logical_and.reduce(np.isfinite(located), axis=1)
        last_seen[assigned] = frame.index
        snapshots = []
        shown = ((last_seen >= 0) & finite).nonzero()[0].tolist()  # (unseen, or lost beyond the localiser: none)
        taken_by, headings, probabilities = det_of_agent.tolist(), heading.tolist(), conf.tolist()
        for j in shown:
            k = taken_by[j]
            seen = k >= 0
            snapshot = object.__new__(TrackSnapshot)  # (every field set directly: TrackSnapshot checks nothing)
            snapshot.__dict__.update(
                track_id=j + 1, status=TrackStatus.CONFIRMED if seen else TrackStatus.LOST, xywh=None,
                position=located[j].copy(), velocity=None, heading=headings[k] if seen else None, agent_id=j,
                identity_prob=probabilities[k] if seen else None, detection_index=k)
            snapshots.append(snapshot)
        return snapshots


def decode(prob: np.ndarray, used: np.ndarray, n: int, one_to_one: bool) -> tuple[np.ndarray, np.ndarray]:
    """Labels ``(n,)`` of a frame's ``n`` detections (agent or -1) and their probabilities (0 where unused) from the
    probabilities ``(M, N+1)`` of the slots holding detections ``used``."""
    labels, conf = filled(n, -1, int), np.zeros(n)
    k = len(used)
    p = prob[:k]
    n_agents = p.shape[1] - 1
    if not one_to_one:
        label = p.argmax(axis=1)
        labels[used], conf[used] = np.where(label == n_agents, -1, label), p[np.arange(k), label]
        return labels, conf
    # Each detection may be a false positive; each agent takes at most one detection.
    cost = -np.log(np.minimum(np.maximum(np.concatenate([p[:, :n_agents], p[:, n_agents:].repeat(k, axis=1)],
                                                        axis=1), 1e-12), 1))
    rows, cols = linear_sum_assignment(cost)
    label = filled(k, -1, int)
    label[rows] = np.where(cols < n_agents, cols, -1)
    labels[used], conf[used] = label, np.where(label >= 0, p[np.arange(k), np.maximum(label, 0)], p[:, n_agents])
    return labels, conf


def agent_detections(labels: np.ndarray, conf: np.ndarray, n_agents: int) -> np.ndarray:
    """``(n_agents,)`` each agent's most confident detection (index into ``labels``), -1 for none."""
    det_of_agent = [-1] * n_agents
    label = labels.tolist()
    for k in (-conf).argsort().tolist():
        j = label[k]
        if j >= 0 and det_of_agent[j] < 0:
            det_of_agent[j] = k
    return np.array(det_of_agent)
