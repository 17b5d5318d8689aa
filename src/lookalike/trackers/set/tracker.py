"""``set``: one network that labels detections with agent identities for any number of agents and detections.

Each public parameter switches one mechanism on or sets its strength (None: off):

- **Network** (``weights``, ``n_slots``): a set associator (:mod:`~lookalike.trackers.set.network`) gives each detection
  (position m, visual heading rad, score) a probability of being agent ``j`` or a false positive from the agents'
  latest reports and its memory per agent; decoded one-to-one (Hungarian on ``-log p``).
- **Positions** (``localiser``): Kalman or low-pass filters (:mod:`lookalike.trackers.parts.identity.localiser`).
- **Stale reports** (``stale_s``): an older report is hidden from the network when a detection within
  :data:`STALE_RADIUS_M` of the agent's remembered position has turned more than :data:`STALE_TURN_RAD` from it.
- **False-positive prior** (``fp_prior_ref``): the false-positive probability is scaled by the running rate of
  false positives per frame (time constant :data:`FP_PRIOR_S`) over ``fp_prior_ref``, clipped to :data:`FP_PRIOR_CLIP`.
- **Report jumps** (``report_jump``), **report exchange** (``exchange_llr``, teams of up to seven) and **visual
  exchange** (``visual_exchange``): detectors of swapped ids (:mod:`~lookalike.trackers.set.report_jumps`,
  :mod:`~lookalike.trackers.set.report_exchange`, :mod:`~lookalike.trackers.set.visual_exchange`) that exchange or
  forget the agents' memories.
- **Undo** (``undo_factor``): a pair exchanged within :data:`UNDO_S` seconds is exchanged back on that fraction of the
  evidence; an agent undoes only its latest exchange.

Values chosen on tuning sequences and checked on fresh ones (docs/experiments/any-team-size.md)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from lookalike.trackers.base import Range, check_params, param
from lookalike.trackers.parts.agents import AgentIdentifier, agent_detections, decode
from lookalike.trackers.parts.identity.localiser import LOCALISERS
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
class SetIdentifier(AgentIdentifier):
    """The set associator: per-detection identities for any number of agents and detections (see the module)."""

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
                                              "headings count as exchanged (None: never)",
                                              range=Range(0.0, 1e4, low_open=True))
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
        self._reset_agents(n, cfg.localiser)
        self._jumps = None if cfg.report_jump is None else ReportJumps(cfg.report_jump, TURN_RATE_RAD_S)
        self.fp_rate = cfg.fp_prior_ref  # running mean of false positives per frame
        self._exchange = None if cfg.exchange_llr is None else report_exchange.for_team(n, cfg.exchange_llr)
        self._visual = None if cfg.visual_exchange is None else VisualExchange(n, cfg.visual_exchange)
        self.exchanges = 0  # memories exchanged by the report-exchange detector so far (for tests and analysis)
        self.visual_exchanges = 0  # the same, by the visual-exchange detector
        self._exchanged_at = np.full((n, n), -np.inf)  # frame time (s) of each pair's latest exchange (undo)
        self._latest_exchange = -np.inf  # the latest time set in _exchanged_at

    def update(self, frame: Frame) -> list[TrackSnapshot]:
        """Label the frame's detections and return one snapshot per agent seen so far."""
        dt = self._step_time(frame)
        before = (self._beacons.heading.copy(), self._beacons.t_sent.copy())
        self._beacons.add(frame)
        if self._jumps is not None:
            self._report_jumps(*before)
        if self._exchange is not None:
            self._report_exchanges(frame)
        det = frame.detections
        n = len(det)  # (_step_time checked the columns)
        position = det.position if det.position is not None and n else np.zeros((0, 2))
        heading = det.heading if det.heading is not None and n else np.zeros(0)
        score = det.score if det.score is not None and n else np.zeros(0)
        used = (-score).argsort(kind="stable")[: self.config.n_slots]
        age = self._beacons.age(frame.time)
        reported = self._beacons.heading
        if self.config.stale_s is not None:
            reported = self._hide_stale(reported, age, position, heading)
        agents = agent_tokens(reported, age, self.net.weights.max_age_s)
        prob = self.net.step(agents, detection_tokens(position[used], heading[used], score[used]), dt)
        if self.fp_rate is not None:
            prob = self._fp_prior(prob)
        labels, conf = decode(prob, used, n, True)
        if self.fp_rate is not None:
            weight = 1.0 - math.exp(-dt / FP_PRIOR_S)
            self.fp_rate += weight * (np.count_nonzero(labels[used] < 0) - self.fp_rate)
        held = agent_detections(labels, conf, self.config.n_agents)
        if self._visual is not None:
            swapped = self._visual_exchanges(labels, held, heading, age, dt)
            if swapped is not labels:
                labels, held = swapped, agent_detections(swapped, conf, self.config.n_agents)
        self.last_labels, self.last_probabilities = labels, conf
        return self._snapshots(labels, conf, position, heading, frame, held)

    def _fp_prior(self, prob: np.ndarray) -> np.ndarray:
        """``prob (slots, N+1)`` with the false-positive column scaled by the running rate over ``fp_prior_ref`` (a
        prior-shift correction), rows normalised again."""
        assert self.fp_rate is not None and self.config.fp_prior_ref is not None
        out: np.ndarray = prob.copy()
        out[:, -1] *= min(max(self.fp_rate / self.config.fp_prior_ref, FP_PRIOR_CLIP[0]), FP_PRIOR_CLIP[1])
        out /= np.maximum(np.add.reduce(out, axis=1, keepdims=True), 1e-12)
        return out

    def _hide_stale(self, reported: np.ndarray, age: np.ndarray, position: np.ndarray,
                    heading: np.ndarray) -> np.ndarray:
        """The reported headings (radians) with NaN (never heard) for the stale reports to hide (see the module)."""
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
        """Exchange or forget the memories of agents whose reports jumped since the previous newest ``heading``
        (radians, sent at ``t_sent`` s)."""
        assert self._jumps is not None
        for action in self._jumps.find(heading, t_sent, self._beacons.heading, self._beacons.t_sent, self._last_time):
            if isinstance(action, tuple):  # (the network's and the report-exchange detector's memories)
                self._swap_network(*action)
                if self._exchange is not None:
                    self._exchange.swap(*action)
            else:  # (forgotten, their report tracks restarted)
                self.net.forget(np.isin(np.arange(self.config.n_agents), action))
                if self._exchange is not None:
                    for agent in action.tolist():
                        self._exchange.forget(agent)

    def _swap_network(self, a: int, b: int) -> None:
        """Exchange agents ``a`` and ``b``'s memories in the network and note when (undo: only an agent's latest)."""
        self.net.swap(a, b)
        undone = self._last_time - self._exchanged_at[a, b] <= UNDO_S
        self._exchanged_at[[a, b], :] = -np.inf
        self._exchanged_at[:, [a, b]] = -np.inf
        if not undone:
            self._exchanged_at[a, b] = self._exchanged_at[b, a] = self._last_time
            self._latest_exchange = self._last_time

    def _threshold_scale(self, agent: int | None = None) -> np.ndarray | None:
        """The factor on the exchange thresholds per pair, or of ``agent`` with each other agent (None: no undo)."""
        factor = self.config.undo_factor
        if factor is None:
            return None
        since = self._last_time - (self._exchanged_at if agent is None else self._exchanged_at[agent])
        return np.where(since <= UNDO_S, factor, 1.0)

    def _recent_scale(self, agent: int | None = None) -> np.ndarray | None:
        """:meth:`_threshold_scale`, or None (the same thresholds) when no pair was exchanged within ``UNDO_S``."""
        if self._last_time - self._latest_exchange > UNDO_S:
            return None
        return self._threshold_scale(agent)

    def _report_exchanges(self, frame: Frame) -> None:
        """Feed the frame's reports to the report-exchange detector and exchange the memories of each pair it finds."""
        assert self._exchange is not None
        b = frame.beacons
        for agent, t_sent, heading in zip(b.agent_id.tolist(), b.t_sent.tolist(), b.heading.tolist()):
            if not 0 <= agent < self.config.n_agents:
                continue
            pair = self._exchange.add(agent, t_sent, heading, self._recent_scale(agent))
            if pair is not None:
                self._swap_network(*pair)
                self.exchanges += 1
                if self._jumps is not None:
                    self._jumps.exchanged(pair, t_sent)

    def _visual_exchanges(self, labels: np.ndarray, held: np.ndarray, heading: np.ndarray, age: np.ndarray,
                          dt: float) -> np.ndarray:
        """Exchange the memories and this frame's labels of the pairs the visual-exchange detector finds (``held``:
        :func:`agent_detections` of ``labels``); the labels (``labels`` itself when no pair)."""
        assert self._visual is not None
        pairs = self._visual.update(held, heading, self._beacons.heading, age, dt, self._recent_scale())
        self.visual_exchanges += len(pairs)
        out = labels
        for j, k in pairs:
            self._swap_network(j, k)
            out = np.where(labels == j, k, np.where(labels == k, j, out))
        return out
