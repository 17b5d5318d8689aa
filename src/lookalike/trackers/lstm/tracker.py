"""The robot-identification paper's LSTM identifier: labels every detection "agent j" or "false positive" from the
detections and the agents' heading reports (numpy network); tracks are the agents, positioned by a localiser. With
``protocol="paper"`` the shipped weights take the paper's ``N + 4·M`` inputs (decode per slot, ``one_to_one=False``,
as the paper does)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from lookalike.trackers.base import check_params, param
from lookalike.trackers.lstm.checkpoint import load_weights
from lookalike.trackers.lstm.encoding import PROTOCOLS, EncodingSpec, encode_frame
from lookalike.trackers.lstm.network import NumpyAssociationNet
from lookalike.trackers.lstm.weights import shipped_weights_path
from lookalike.trackers.parts.agents import AgentIdentifier, decode
from lookalike.trackers.parts.identity.localiser import LOCALISERS
from lookalike.trackers.registry import register_tracker
from lookalike.types import Detections, Frame, TrackSnapshot

_NONE_SEEN = Detections(position=np.zeros((0, 2)), heading=np.zeros(0), score=np.zeros(0))
"""An empty frame's detections with the columns the encoding reads."""


@register_tracker("lstm")
class LstmIdentifier(AgentIdentifier):
    """The deep LSTM associator: per-detection identities and low-pass filtered agent positions."""

    @dataclass(frozen=True)
    class Config:
        n_agents: int = param(3, "number of reporting agents N", range=(1, 1000))
        n_slots: int = param(5, "detection slots M of the network", range=(1, 1000))
        weights: str | None = param(None, "path of model.npz (None: the shipped weights for N, M)")
        one_to_one: bool = param(True, "decode with Hungarian on -log p (else per-slot argmax, as the paper)")
        localiser: str = param("kalman", "agent positions: kalman (ours) or lowpass (the paper's Eq. 3)",
                               choices=LOCALISERS)
        protocol: str = param("ours", "shipped weights when weights is None: ours, or paper (the paper's N + 4M "
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
        self._reset_agents(self.config.n_agents, self.config.localiser)

    def update(self, frame: Frame) -> list[TrackSnapshot]:
        """Label the frame's detections and return one snapshot per agent seen so far."""
        self._step_time(frame)
        self._beacons.add(frame)
        det = frame.detections if len(frame.detections) else _NONE_SEEN  # (an empty frame may lack the columns)
        x, used = encode_frame(self.spec, det, self._beacons.heading, self._beacons.age(frame.time))
        labels, conf = decode(self.net.step(x), used, len(det), self.config.one_to_one)
        self.last_labels, self.last_probabilities = labels, conf
        assert det.position is not None and det.heading is not None  # (encode_frame checked them)
        return self._snapshots(labels, conf, det.position, det.heading, frame)
