"""``set``: one network that labels detections with agent identities for any number of agents and detections.

How it works, by mechanism (each public parameter switches one on or sets its strength; None: off):

- **Network** (``weights``, ``n_slots``): a set associator (:mod:`~lookalike.trackers.set.network`) reads each
  frame's detections (ground position in metres, absolute visual heading in radians, detector score) and the
  agents' latest heading reports, keeps a memory per agent and gives each detection a probability of being agent
  ``j`` or a false positive; decoded one-to-one (Hungarian on ``-log p``, false positives allowed).
- **Positions** (``localiser``): each agent's position comes from the detection labelled ``j`` and its
  probability, through a per-agent Kalman filter or a low-pass filter
  (:mod:`lookalike.trackers.parts.identity.localiser`).
- **Stale reports** (``stale_s``): an agent whose report is older than ``stale_s`` while a detection within
  :data:`STALE_RADIUS_M` of its remembered position has turned more than :data:`STALE_TURN_RAD` away from that
  report is shown to the network as not heard from (its memory still places it).
- **False-positive prior** (``fp_prior_ref``): the false-positive probability is scaled by the running mean of the
  detections labelled false positive per frame (time constant :data:`FP_PRIOR_S`) over ``fp_prior_ref``, clipped to
  :data:`FP_PRIOR_CLIP`: the network was trained over 0.3-2.5 false positives per frame and cannot tell the rate
  from one frame.
- **Report jumps** (``report_jump``): an agent whose reports jump further than a robot can turn (``report_jump`` +
  :data:`TURN_RATE_RAD_S` · the time between them) now reports for another robot; its memory is exchanged with the
  agent it swapped with, else forgotten (:mod:`~lookalike.trackers.set.report_jumps`).
- **Report exchange** (``exchange_llr``): two agents whose heading reports each continue the other's report track
  exchange memories: a swap too small for a report jump (:mod:`~lookalike.trackers.set.report_exchange`; teams of
  up to seven agents).
- **Visual exchange** (``visual_exchange``): two agents whose detections' visual headings, gathered over seconds,
  fit each other's reports better than their own exchange memories (:mod:`~lookalike.trackers.set.visual_exchange`).
- **Undo** (``undo_factor``): a pair exchanged within the last :data:`UNDO_S` seconds needs that fraction of the two
  exchange detectors' evidence to be exchanged back (a swap of ids is often undone); an agent undoes only its
  latest exchange.

Every value was chosen on tuning sequences and checked on fresh ones (docs/experiments/any-team-size.md).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from lookalike.trackers.base import check_params, param
from lookalike.trackers.parts.agents import BeaconMemory, agent_detections, agent_snapshots, decode
from lookalike.trackers.parts.identity.localiser import LOCALISERS, make_localiser
from lookalike.trackers.registry import register_tracker
from lookalike.trackers.set import report_exchange
from lookalike.trackers.set.network import (
    NumpySetAssociator,
    agent_tokens,
    detection_tokens,
    load_set_weights,
    shipped_set_weights_path,
)
from lookalike.trackers.set.report_jumps import ReportJumps
from lookalike.trackers.set.visual_exchange import VisualExchange
from lookalike.types import Frame, TrackSnapshot

TURN_RATE_RAD_S = 3.0  # fastest plausible turn of a robot (report jumps), rad/s
STALE_TURN_RAD = 0.6  # heading disagreement that makes a stale report hidden, radians
STALE_RADIUS_M = 0.5  # how near the remembered position that detection must be, metres
FP_PRIOR_S = 10.0  # time constant of the running false-positive rate, seconds
FP_PRIOR_CLIP = (0.2, 5.0)  # bounds of the false-positive probability's scale
UNDO_S = 30.0  # how long a pair's exchange can be undone on less evidence, seconds


@register_tracker("set")
class SetIdentifier:
    """The set associator: per-detection identities for any number of agents and detections (see the module)."""

    needs = ("ground positions, headings and heading reports of robots (a `lookalike simulate` sequence, "
             "or --video V --pipeline robots --reports FILE)")

    @dataclass(frozen=True)
    class Config:
        # the network
        n_agents: int = param(3, "number of reporting agents N (any; one network for every size)", range=(1, 1000))
        n_slots: int | None = param(None, "keep at most this many most probable detections per frame (None: all)",
                                     range=(1, 1000))
        weights: str | None = param(None, "path of set.npz (None: the shipped weights, any N and M)")
        localiser: str = param("kalman", "agent positions: kalman (per-agent Kalman filter) or lowpass "
                               "(T_j <- a L_k + (1 - a) T_j)", choices=LOCALISERS)
        # corrections of the network's inputs and outputs
        stale_s: float | None = param(0.5, "hide a report older than this many seconds once a detection near the "
                                      "agent has turned away from it (None: never)", range=(0.0, 100.0))
        fp_prior_ref: float | None = param(1.4, "false positives per frame the network's false-positive "
                                           "probability assumes; scaled to the world's running rate (None: never)",
                                           range=(0.01, 100.0))
        # exchanges of two agents' memories after a swap of ids
        report_jump: float | None = param(0.5, "radians a report may jump beyond a robot's turn before the agent "
                                          "counts as swapped (None: never)", range=(0.0, 10.0))
        exchange_llr: float | None = param(8.0, "log-likelihood ratio at which two agents' report streams count "
                                           "as exchanged (teams of up to 7; None: never)", range=(0.0, 1000.0))
        visual_exchange: float | None = param(8.0, "log-likelihood ratio at which two agents' detections' visual "
                                              "headings count as exchanged (None: never)", range=(0.0, 1e4))
        undo_factor: float | None = param(0.5, "fraction of that evidence that undoes a pair's exchange within "
                                          f"{UNDO_S:g} s (None: the full evidence)", range=(1e-3, 1.0))

        def __post_init__(self) -> None:
            check_params(self)

    def __init__(self, config: SetIdentifier.Config | None = None) -> None:
        self.config = config or SetIdentifier.Config()
        self.net = NumpySetAssociator(load_set_weights(self.config.weights or shipped_set_weights_path()))
        self.reset()

    def reset(self) -> None:
        """Forget the agents' memory, the reports and the agents' positions."""
        cfg = self.config
        n = cfg.n_agents
        self.net.reset(n)
        self._beacons = BeaconMemory(n)
        self._localiser = make_localiser(cfg.localiser, n)
        self._last_seen = np.full(n, -1)
        self.last_labels = np.zeros(0, dtype=int)
        self.last_probabilities = np.zeros(0)
        self._last_time = -np.inf
        self._jumps = None if cfg.report_jump is None else ReportJumps(cfg.report_jump, TURN_RATE_RAD_S)
        self.fp_rate = cfg.fp_prior_ref  # running mean of false positives per frame
        self._exchange = None if cfg.exchange_llr is None else report_exchange.for_team(n, cfg.exchange_llr)
        self._visual = None if cfg.visual_exchange is None else VisualExchange(n, cfg.visual_exchange)
        self.exchanges = 0  # memories exchanged by the report-exchange detector so far (for tests and analysis)
        self.visual_exchanges = 0  # the same, by the visual-exchange detector
        self._exchanged_at = np.full((n, n), -np.inf)  # frame time (s) of each pair's latest exchange (undo)

    def update(self, frame: Frame) -> list[TrackSnapshot]:
        """Label the frame's detections and return one snapshot per agent seen so far."""
        if frame.time < self._last_time:
            raise ValueError(f"frame time went backwards: {self._last_time} s then {frame.time} s")
        dt = 0.0 if not np.isfinite(self._last_time) else frame.time - self._last_time
        self._last_time = frame.time
        before = (self._beacons.heading.copy(), self._beacons.t_sent.copy())
        self._beacons.add(frame)
        if self._jumps is not None:
            self._report_jumps(*before)
        if self._exchange is not None:
            self._report_exchanges(frame)
        det = frame.detections
        n = len(det)
        if n and (det.position is None or det.heading is None or det.score is None):
            raise ValueError("set: frame.detections need position (m), heading (rad) and score columns")
        position = det.position if det.position is not None and n else np.zeros((0, 2))
        heading = det.heading if det.heading is not None and n else np.zeros(0)
        score = det.score if det.score is not None and n else np.zeros(0)
        used = np.argsort(-score, kind="stable")[: self.config.n_slots]
        age = self._beacons.age(frame.time)
        reported = self._beacons.heading
        if self.config.stale_s is not None:
            reported = self._hide_stale(reported, age, position, heading)
        agents = agent_tokens(reported, age, self.net.weights.max_age_s)
        prob = self.net.step(agents, detection_tokens(position[used], heading[used], score[used]), dt)
        if self.fp_rate is not None:
            prob = self._fp_prior(prob)
        slot_label, slot_conf = decode(prob, len(used), True)
        if self.fp_rate is not None:
            weight = 1.0 - math.exp(-dt / FP_PRIOR_S)
            self.fp_rate += weight * (int((slot_label < 0).sum()) - self.fp_rate)
        labels, conf = np.full(n, -1), np.zeros(n)
        labels[used], conf[used] = slot_label, slot_conf
        if self._visual is not None:
            labels = self._visual_exchanges(labels, conf, heading, age, dt)
        self.last_labels, self.last_probabilities = labels, conf
        return agent_snapshots(labels, conf, position, heading, self._localiser, self._last_seen, frame)

    def _fp_prior(self, prob: np.ndarray) -> np.ndarray:
        """``prob`` (slots x N+1, false positive last) with the false-positive column scaled by the world's
        running false-positive rate over ``fp_prior_ref`` (the prior-shift correction of a posterior trained on
        another mix of false positives) and the rows normalised again."""
        assert self.fp_rate is not None and self.config.fp_prior_ref is not None
        out = prob.copy()
        out[:, -1] *= min(max(self.fp_rate / self.config.fp_prior_ref, FP_PRIOR_CLIP[0]), FP_PRIOR_CLIP[1])
        return np.asarray(out / np.maximum(out.sum(axis=1, keepdims=True), 1e-12))

    def _hide_stale(self, reported: np.ndarray, age: np.ndarray, position: np.ndarray,
                    heading: np.ndarray) -> np.ndarray:
        """The reported headings (radians) with NaN (never heard, for the network) for every agent whose
        report is older than ``stale_s`` while a detection within :data:`STALE_RADIUS_M` of its remembered
        position is more than :data:`STALE_TURN_RAD` away from that report: the robot has turned since it last
        reported, and only its remembered position still says which detection it is."""
        assert self.config.stale_s is not None
        stale = np.isfinite(age) & (age > self.config.stale_s) & self.net.remembers()
        if not stale.any() or not len(position):
            return reported
        out = reported.copy()
        for j in np.flatnonzero(stale):
            near = np.linalg.norm(position - self.net.p[j], axis=1) < STALE_RADIUS_M
            turned = np.abs(np.angle(np.exp(1j * (heading[near] - reported[j])))) > STALE_TURN_RAD
            if turned.any():
                out[j] = np.nan
        return np.asarray(out)

    def _report_jumps(self, heading: np.ndarray, t_sent: np.ndarray) -> None:
        """Exchange or forget the memories of the agents whose reports jumped to another robot since their previous
        newest report (``heading``, radians, sent at ``t_sent`` seconds)."""
        assert self._jumps is not None
        for action in self._jumps.find(heading, t_sent, self._beacons.heading, self._beacons.t_sent, self._last_time):
            if isinstance(action, tuple):
                self._exchange_memories(*action)
            else:
                self._forget(action)

    def _forget(self, agents: np.ndarray) -> None:
        """Forget the network's memory of ``agents`` (indices) and restart their report tracks."""
        self.net.forget(np.isin(np.arange(self.config.n_agents), agents))
        if self._exchange is not None:
            for a in agents.tolist():
                self._exchange.forget(a)

    def _exchange_memories(self, a: int, b: int) -> None:
        """Exchange agents ``a`` and ``b``'s memories (the network's and the report-exchange detector's tracks)."""
        self._swap_network(a, b)
        if self._exchange is not None:
            self._exchange.swap(a, b)

    def _swap_network(self, a: int, b: int) -> None:
        """Exchange agents ``a`` and ``b``'s memories in the network and note when (undo): an agent may undo only its
        latest exchange, and an exchange that undoes one leaves the pair as any other."""
        self.net.swap(a, b)
        undone = self._last_time - self._exchanged_at[a, b] <= UNDO_S
        self._exchanged_at[[a, b], :] = -np.inf
        self._exchanged_at[:, [a, b]] = -np.inf
        if not undone:
            self._exchanged_at[a, b] = self._exchanged_at[b, a] = self._last_time

    def _threshold_scale(self, agent: int | None = None) -> np.ndarray | None:
        """The factor on the exchange detectors' thresholds per pair of agents, or of ``agent`` with each other
        agent (None: no undo)."""
        factor = self.config.undo_factor
        if factor is None:
            return None
        since = self._last_time - (self._exchanged_at if agent is None else self._exchanged_at[agent])
        return np.where(since <= UNDO_S, factor, 1.0)

    def _report_exchanges(self, frame: Frame) -> None:
        """Feed the frame's reports to the report-exchange detector and exchange the memories of each pair it
        finds; a report jump of either agent within the next second is then the same exchange."""
        assert self._exchange is not None
        b = frame.beacons
        for agent, t_sent, heading in zip(b.agent_id.tolist(), b.t_sent.tolist(), b.heading.tolist()):
            if not 0 <= agent < self.config.n_agents:
                continue
            pair = self._exchange.add(agent, t_sent, heading, self._threshold_scale(agent))
            if pair is not None:
                self._swap_network(*pair)
                self.exchanges += 1
                if self._jumps is not None:
                    self._jumps.exchanged(pair, t_sent)

    def _visual_exchanges(self, labels: np.ndarray, conf: np.ndarray, heading: np.ndarray, age: np.ndarray,
                          dt: float) -> np.ndarray:
        """Exchange the memories, and this frame's labels, of the pairs of agents whose detections' visual headings
        ``heading`` (radians) fit each other's reports better. Returns the labels."""
        assert self._visual is not None
        held = agent_detections(labels, conf, self.config.n_agents)
        pairs = self._visual.update(held, heading, self._beacons.heading, age, dt, self._threshold_scale())
        self.visual_exchanges += len(pairs)
        out = labels
        for j, k in pairs:
            self._swap_network(j, k)
            out = np.where(labels == j, k, np.where(labels == k, j, out))
        return out
