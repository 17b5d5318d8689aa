"""The set associator as a registered identifier (``set``): one network for every team size.

Labels every detection "agent j" or "false positive" from the detections (ground position in
metres, absolute visual heading in radians, detector score) and the agents' latest heading
reports, with :class:`~lookalike.learn.set_numpy.NumpySetAssociator`; decoded one-to-one like the
LSTM (Hungarian on ``-log p``, false positives allowed). Agent positions are low-pass filtered as
the LSTM identifier does: ``T_j ← α·L_k + (1−α)·T_j``.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from lookalike.learn.checkpoint import CheckpointError
from lookalike.learn.set_data import agent_tokens, detection_tokens
from lookalike.learn.set_numpy import NumpySetAssociator, load_set_weights
from lookalike.learn.tracker import BeaconMemory, decode
from lookalike.learn.weights import WEIGHTS_DIR
from lookalike.trackers.base import check_params, param
from lookalike.trackers.registry import register_tracker
from lookalike.types import Frame, TrackSnapshot, TrackStatus

SHIPPED_SET_WEIGHTS = WEIGHTS_DIR / "set_any.npz"


def shipped_set_weights_path() -> Path:
    """The shipped set-associator weights (one file for every N and M)."""
    if not SHIPPED_SET_WEIGHTS.is_file():
        raise CheckpointError(f"{SHIPPED_SET_WEIGHTS}: the shipped set-associator weights are missing; "
                              "train some with `lookalike train --model set` and pass weights=PATH")
    return SHIPPED_SET_WEIGHTS


@register_tracker("set")
class SetIdentifier:
    """The set associator: per-detection identities for any number of agents and detections."""

    needs = ("ground positions, headings and heading reports of robots (a `lookalike simulate` sequence, "
             "or --video V --pipeline robots --reports FILE)")

    @dataclass(frozen=True)
    class Config:
        n_agents: int = param(3, "number of reporting agents N (any; no per-size weights)",
                              range=(1, 1000))
        n_slots: int | None = param(None, "keep at most this many most probable detections per frame (None: all)",
                                     range=(1, 1000))
        weights: str | None = param(None, "path of set.npz (None: the shipped weights, any N and M)")
        one_to_one: bool = param(True, "decode with Hungarian on -log p (else per-detection argmax)")

        def __post_init__(self) -> None:
            check_params(self)

    def __init__(self, config: SetIdentifier.Config | None = None) -> None:
        self.config = config or SetIdentifier.Config()
        path = self.config.weights or shipped_set_weights_path()
        self.net = NumpySetAssociator(load_set_weights(path))
        self.reset()

    def reset(self) -> None:
        """Forget the agents' memory, the reports and the agents' positions."""
        n = self.config.n_agents
        self.net.reset(n)
        self._beacons = BeaconMemory(n)
        self._position = np.full((n, 2), np.nan)
        self._last_seen = np.full(n, -1)
        self.last_labels = np.zeros(0, dtype=int)
        self.last_probabilities = np.zeros(0)
        self._last_time = -np.inf

    def update(self, frame: Frame) -> list[TrackSnapshot]:
        """Label the frame's detections and return one snapshot per agent seen so far."""
        if frame.time < self._last_time:
            raise ValueError(f"frame time went backwards: {self._last_time} s then {frame.time} s")
        dt = 0.0 if not np.isfinite(self._last_time) else frame.time - self._last_time
        self._last_time = frame.time
        self._beacons.add(frame)
        det = frame.detections
        n = len(det)
        if n and (det.position is None or det.heading is None or det.score is None):
            raise ValueError("set: frame.detections need position (m), heading (rad) and score columns")
        position = det.position if det.position is not None and n else np.zeros((0, 2))
        heading = det.heading if det.heading is not None and n else np.zeros(0)
        score = det.score if det.score is not None and n else np.zeros(0)
        used = np.argsort(-score, kind="stable")[: self.config.n_slots]
        agents = agent_tokens(self._beacons.heading, self._beacons.age(frame.time), self.net.weights.max_age_s)
        prob = self.net.step(agents, detection_tokens(position[used], heading[used], score[used]), dt)
        slot_label, slot_conf = decode(prob, len(used), self.config.one_to_one)
        labels, conf = np.full(n, -1), np.zeros(n)
        labels[used], conf[used] = slot_label, slot_conf
        self.last_labels, self.last_probabilities = labels, conf
        return self._snapshots(labels, conf, position, heading, frame.index)

    def _snapshots(self, labels: np.ndarray, conf: np.ndarray, position: np.ndarray, heading: np.ndarray,
                   frame_index: int) -> list[TrackSnapshot]:
        n_agents = self.config.n_agents
        det_of_agent = np.full(n_agents, -1)
        for k in np.argsort(-conf):  # the most confident detection of an agent updates it
            j = labels[k]
            if j >= 0 and det_of_agent[j] < 0:
                det_of_agent[j] = k
        snapshots = []
        for j in range(n_agents):
            k = det_of_agent[j]
            if k >= 0:
                alpha = conf[k]
                prev = self._position[j]
                self._position[j] = position[k] if np.isnan(prev).any() else alpha * position[k] + (1 - alpha) * prev
                self._last_seen[j] = frame_index
            if self._last_seen[j] < 0:
                continue
            snapshots.append(TrackSnapshot(
                track_id=j + 1,
                status=TrackStatus.CONFIRMED if k >= 0 else TrackStatus.LOST,
                position=self._position[j].copy(),
                heading=float(heading[k]) if k >= 0 else None,
                agent_id=j,
                identity_prob=float(conf[k]) if k >= 0 else None,
                detection_index=int(k),
            ))
        return snapshots
