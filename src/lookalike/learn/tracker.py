"""The LSTM identifier (seed A) as a registered tracker: labels every detection "agent j" or
"false positive" from the detections and the agents' heading reports, with the numpy network.

Tracks are the agents themselves, positioned by a localiser fed with the detection labelled ``j``
and its class probability ``α``: seed A's Eq. 3 ``T_j ← α·L_k + (1−α)·T_j`` (``localiser="lowpass"``)
or our per-agent Kalman filter (``"kalman"``, see :mod:`lookalike.trackers.parts.identity.localiser`).

With ``protocol="paper"`` the shipped weights are those of seed A's input protocol (``N + 4·M``
inputs, ``lstm_paper_m{M}_n{N}``); decode them per slot (``one_to_one=False``) as the paper does.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from lookalike.learn.checkpoint import load_weights
from lookalike.learn.encoding import PROTOCOLS, EncodingSpec, encode_frame
from lookalike.learn.numpy_net import NumpyAssociationNet
from lookalike.learn.weights import shipped_weights_path
from lookalike.trackers.base import check_params, param
from lookalike.trackers.parts.identity.localiser import LOCALISERS, KalmanLocaliser, LowPassLocaliser, make_localiser
from lookalike.trackers.registry import register_tracker
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


@register_tracker("lstm")
class LstmIdentifier:
    """The deep LSTM associator: per-detection identities and low-pass filtered agent positions."""

    @dataclass(frozen=True)
    class Config:
        n_agents: int = param(3, "number of reporting agents N", range=(1, 1000))
        n_slots: int = param(5, "detection slots M of the network", range=(1, 1000))
        weights: str | None = param(None, "path of model.npz (None: the shipped weights for N, M)")
        one_to_one: bool = param(True, "decode with Hungarian on -log p (else per-slot argmax, as the paper)")
        localiser: str = param("kalman", "agent positions: kalman (ours) or lowpass (seed A's Eq. 3)",
                               choices=LOCALISERS)
        protocol: str = param("ours", "shipped weights when weights is None: ours, or paper (seed A's N + 4M "
                              "inputs)", choices=PROTOCOLS)

        def __post_init__(self) -> None:
            check_params(self)

    def __init__(self, config: LstmIdentifier.Config | None = None) -> None:
        self.config = config or LstmIdentifier.Config()
        cfg = self.config
        stem = "lstm_paper" if cfg.protocol == "paper" else "lstm"
        path = cfg.weights or shipped_weights_path(cfg.n_agents, cfg.n_slots, stem)
        self.net = NumpyAssociationNet(load_weights(path, cfg.n_agents, cfg.n_slots))
        self.spec: EncodingSpec = self.net.spec
        self.reset()

    def reset(self) -> None:
        """Forget the recurrent state, the reports and the agents' positions."""
        self.net.reset()
        self._beacons = BeaconMemory(self.config.n_agents)
        self._localiser = make_localiser(self.config.localiser, self.config.n_agents)
        self._last_seen = np.full(self.config.n_agents, -1)
        self.last_labels = np.zeros(0, dtype=int)
        self.last_probabilities = np.zeros(0)
        self._last_time = -np.inf

    def update(self, frame: Frame) -> list[TrackSnapshot]:
        """Label the frame's detections and return one snapshot per agent seen so far."""
        if frame.time < self._last_time:
            raise ValueError(f"frame time went backwards: {self._last_time} s then {frame.time} s")
        self._last_time = frame.time
        self._beacons.add(frame)
        det = frame.detections
        n = len(det)
        x, used = encode_frame(self.spec, det, self._beacons.heading, self._beacons.age(frame.time))
        prob = self.net.step(x)
        slot_label, slot_conf = decode(prob, len(used), self.config.one_to_one)
        labels, conf = np.full(n, -1), np.zeros(n)
        labels[used], conf[used] = slot_label, slot_conf
        self.last_labels, self.last_probabilities = labels, conf
        if n and (det.position is None or det.heading is None):
            raise ValueError("lstm: frame.detections need position (m) and heading (rad) columns")
        position = det.position if det.position is not None else np.zeros((0, 2))
        heading = det.heading if det.heading is not None else np.zeros(0)
        return agent_snapshots(labels, conf, position, heading, self._localiser, self._last_seen, frame)


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
