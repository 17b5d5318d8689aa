"""The set associator as a registered identifier (``set``): one network for every team size.

Labels every detection "agent j" or "false positive" from the detections (ground position in
metres, absolute visual heading in radians, detector score) and the agents' latest heading
reports, with :class:`~lookalike.learn.set_numpy.NumpySetAssociator`; decoded one-to-one like the
LSTM (Hungarian on ``-log p``, false positives allowed). Agent positions come from the same
localiser as the LSTM identifier's, fed with the detection labelled ``j`` and its class probability
``α``: the per-agent Kalman filter by default (``localiser="kalman"``), or seed A's Eq. 3
``T_j ← α·L_k + (1−α)·T_j`` (``"lowpass"``); see :mod:`lookalike.trackers.parts.identity.localiser`.

An agent whose reports jump to another robot (ids swapped or restored; ``report_jump``, ``on_jump``,
``jump_pair_s``, ``jump_silent``: :mod:`lookalike.learn.report_jumps`) has its memory exchanged with the agent it
swapped with, else forgotten (``jump_pair_s`` 1 s chosen on a development sample, docs/experiments/any-team-size.md,
"An eleventh stage").
An agent whose report is older than ``stale_s`` seconds while a detection near its remembered
position has turned away from that report is shown to the network as not heard from (its memory
still places it). Both were chosen on tuning sequences (docs/experiments/any-team-size.md).
With ``pair_swap``, two agents whose detections keep fitting each other's fresh reports better than
their own (a swap undone while their headings stay too close for a report jump) exchange memories.
The false-positive probability is corrected for the world's false-positive rate (``fp_prior_ref``: the
running mean of the detections labelled false positive per frame over 1.4, chosen on tuning sequences):
the network was trained over 0.3-2.5 false positives per frame and cannot tell the rate from one frame.
With ``exchange_llr`` (8, for teams of up to ``exchange_max_agents`` = 7; chosen on tuning sequences), two agents
whose heading reports each continue the other's report track exchange memories
(:mod:`lookalike.learn.report_exchange`): an exchange too small for a report jump. Teams of
``exchange_tight_agents`` (5) agents or more run it with a report model that expects smoother turning
(``exchange_tight_accel``, ``exchange_tight_lag_s``), which finds exchanges between robots heading alike.
With ``visual_exchange`` (8, chosen on tuning sequences), two agents whose detections' visual headings, gathered
over seconds, fit each other's reports better than their own exchange memories
(:mod:`lookalike.learn.visual_exchange`); with ``visual_stale_rad_s`` (0.5 rad/s, chosen the same way) an agent
silent for a while takes part too. With ``undo_factor`` (0.5, chosen on tuning sequences and a development sample),
a pair exchanged within the last ``undo_s`` seconds needs that fraction of the two exchange detectors' evidence to be
exchanged back (a swap of ids is often undone); an agent undoes only its latest exchange.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from lookalike.learn.checkpoint import CheckpointError
from lookalike.learn.report_exchange import ReportExchange
from lookalike.learn.report_jumps import ReportJumps
from lookalike.learn.set_data import agent_tokens, detection_tokens
from lookalike.learn.set_numpy import NumpySetAssociator, load_set_weights
from lookalike.learn.tracker import BeaconMemory, agent_detections, agent_snapshots, decode
from lookalike.learn.visual_exchange import VisualExchange, take_pairs
from lookalike.learn.weights import WEIGHTS_DIR
from lookalike.trackers.base import check_params, param
from lookalike.trackers.parts.identity.localiser import LOCALISERS, make_localiser
from lookalike.trackers.registry import register_tracker
from lookalike.types import Frame, TrackSnapshot

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
        report_jump: float | None = param(
            0.5, "forget an agent's memory when its reported heading jumps by more than report_jump + "
            "turn_rate * (seconds between its reports) radians (a report from another robot; None: never)",
            range=(0.0, 10.0))
        turn_rate: float = param(3.0, "fastest plausible turn of a robot for report_jump, rad/s", range=(0.0, 100.0))
        stale_s: float | None = param(
            0.5, "hide an agent's reported heading from the network when the report is older than stale_s "
            "seconds and a detection near the agent's remembered position (stale_radius_m) has turned away from it "
            "by more than stale_turn radians (None: never)", range=(0.0, 100.0))
        stale_turn: float = param(0.6, "heading disagreement for stale_s, radians", range=(0.0, 4.0))
        stale_radius_m: float = param(0.5, "how near the remembered position a detection must be for stale_s, metres",
                                      range=(0.0, 100.0))
        on_jump: str = param("swap", "after a report jump (report_jump): forget the agent's memory, or swap "
                             "it with the one other agent that reported the new heading just before (forget: "
                             "no such agent or several)", choices=("forget", "swap"))
        jump_pair_s: float | None = param(
            1.0, "on_jump=swap: an agent whose report jump has no single partner waits this many seconds for a "
            "jump that mirrors it (another agent now reporting the heading it reported before, and the reverse), "
            "then exchanges memories with that agent; forgotten when none comes (None: forgotten at once)",
            range=(0.0, 100.0))
        jump_silent: bool = param(
            True, "jump_pair_s also pairs a jump with an agent's first report after a silence too long to judge "
            "as a jump (more than report_jump off its previous one, within report_jump + turn_rate * the silence) "
            "when the two mirror each other; such a report alone changes nothing (chosen on tuning sequences)")
        pair_swap: float | None = param(
            None, "exchange two agents' memories (and this frame's labels) when the evidence that each one's "
            "detection fits the other's fresh report better than its own, summed over frames with decay "
            "pair_swap_s, passes this many radians (None: never)", range=(0.0, 1000.0))
        pair_swap_s: float = param(0.5, "time constant of pair_swap's evidence decay, seconds", range=(0.01, 100.0))
        pair_fresh_s: float = param(0.3, "reports younger than this count for pair_swap, seconds", range=(0.0, 100.0))
        fp_prior_ref: float | None = param(
            1.4, "adapt the false-positive probability to this world's rate: scale it by (running mean of the "
            "detections labelled false positive per frame) / fp_prior_ref before decoding, clipped to 0.2-5 "
            "(None: never)", range=(0.01, 100.0))
        exchange_llr: float | None = param(
            8.0, "exchange two agents' memories when each one's heading reports continue the other's report track "
            "(a swap of ids, or its undoing, too small for report_jump): half the log-likelihood ratio the two "
            "streams must pass together, each at least a quarter of it (None: never)", range=(0.0, 1000.0))
        exchange_max_agents: int | None = param(
            7, "run exchange_llr only for teams of at most this many agents (None: any)", range=(1, 1000))
        exchange_accel: float = param(0.1, "exchange_llr's angular-acceleration spectral density of a robot's "
                                      "heading, rad^2/s^3", range=(1e-6, 100.0))
        exchange_lag_s: float = param(0.4, "how far exchange_llr's report tracks run behind the newest report, "
                                      "seconds", range=(0.0, 10.0))
        exchange_memory_s: float | None = param(
            1.0, "time constant of the decay of exchange_llr's evidence, seconds (None: no decay, the sixth stage's "
            "detector)", range=(0.01, 1e4))
        exchange_fresh_s: float | None = param(
            None, "exchange_llr leaves out an agent whose report track has had no report for exchange_lag_s + this "
            "many seconds (a lost burst; None: never, as shipped since the fifteenth stage; the eighth to "
            "fourteenth stages' detector: 0.6)", range=(0.0, 1e4))
        exchange_tight_agents: int | None = param(
            5, "teams of at least this many agents run exchange_llr with exchange_tight_accel and "
            "exchange_tight_lag_s instead of exchange_accel and exchange_lag_s (None: never; chosen on tuning "
            "sequences)", range=(1, 1000))
        exchange_tight_accel: float = param(0.03, "exchange_accel for teams of exchange_tight_agents or more, "
                                            "rad^2/s^3", range=(1e-6, 100.0))
        exchange_tight_lag_s: float = param(0.3, "exchange_lag_s for teams of exchange_tight_agents or more, "
                                            "seconds", range=(0.0, 10.0))
        exchange_step_rad: float | None = param(
            None, "exchange_llr exchanges two agents only when both their report streams stepped by more than this "
            "within the last second (a report off the previous one carried on at the track's turn rate), radians "
            "(None: no step needed)", range=(0.0, 3.2))
        exchange_noise_rad: float = param(0.035, "a heading report's noise for exchange_llr (standard deviation), "
                                          "radians", range=(1e-4, 3.0))
        visual_exchange: float | None = param(
            8.0, "exchange two agents' memories (and this frame's labels) when their detections' visual headings, "
            "gathered over seconds, fit each other's fresh reports better than their own by this log-likelihood "
            "ratio (:mod:`lookalike.learn.visual_exchange`; None: never; chosen on tuning sequences)",
            range=(0.0, 1e4))
        visual_memory_s: float = param(10.0, "time constant of visual_exchange's evidence decay, seconds",
                                       range=(0.01, 1e4))
        visual_noise_rad: float = param(0.28, "a detection's visual heading noise around its robot's heading for "
                                        "visual_exchange (standard deviation; 10 heading classes with 12 degrees of "
                                        "noise), radians", range=(1e-3, 3.0))
        visual_stale_rad_s: float | None = param(
            0.5, "visual_exchange also counts reports older than 0.5 s, their noise widened by this many radians "
            "per second of age beyond that (a silent robot may have turned; None: fresh reports only; chosen on "
            "tuning sequences and a development sample)",
            range=(1e-3, 100.0))
        undo_factor: float | None = param(
            0.5, "a pair of agents exchanged (by any rule) within the last undo_s seconds needs this fraction of "
            "exchange_llr's and visual_exchange's evidence to be exchanged again: a swap of ids is often undone, and "
            "a false exchange is better undone soon; an agent undoes only its latest exchange (None: the same "
            "evidence as any pair; chosen on tuning sequences and a development sample)", range=(1e-3, 1.0))
        undo_s: float = param(30.0, "how long undo_factor holds after a pair's exchange, seconds", range=(0.0, 1e4))
        fp_prior_s: float = param(10.0, "time constant of fp_prior_ref's running mean, seconds", range=(0.1, 1e4))
        localiser: str = param("kalman", "agent positions: kalman (ours, as the lstm) or lowpass (seed A's Eq. 3)",
                               choices=LOCALISERS)

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
        self._localiser = make_localiser(self.config.localiser, n)
        self._last_seen = np.full(n, -1)
        self.last_labels = np.zeros(0, dtype=int)
        self.last_probabilities = np.zeros(0)
        self._last_time = -np.inf
        cfg = self.config
        self._jumps = None if cfg.report_jump is None else ReportJumps(
            cfg.report_jump, cfg.turn_rate, cfg.on_jump, cfg.jump_pair_s, cfg.jump_silent)
        self._pair_evidence = np.zeros((n, n))
        self.pair_swaps = 0  # memories exchanged by pair_swap so far (for tests and analysis)
        self.fp_rate = self.config.fp_prior_ref  # running mean of false positives per frame (fp_prior_ref)
        too_many = cfg.exchange_max_agents is not None and n > cfg.exchange_max_agents
        accel, lag = cfg.exchange_accel, cfg.exchange_lag_s
        if cfg.exchange_tight_agents is not None and n >= cfg.exchange_tight_agents:
            accel, lag = cfg.exchange_tight_accel, cfg.exchange_tight_lag_s
        self._exchange = None if cfg.exchange_llr is None or too_many else ReportExchange(
            n, cfg.exchange_llr, accel, lag, cfg.exchange_noise_rad, cfg.exchange_memory_s, cfg.exchange_fresh_s,
            cfg.exchange_step_rad)
        self.exchanges = 0  # memories exchanged by exchange_llr so far (for tests and analysis)
        self._visual = None if cfg.visual_exchange is None else VisualExchange(
            n, cfg.visual_exchange, cfg.visual_memory_s, cfg.visual_noise_rad, stale_rad_s=cfg.visual_stale_rad_s)
        self.visual_exchanges = 0  # memories exchanged by visual_exchange so far (for tests and analysis)
        self._exchanged_at = np.full((n, n), -np.inf)  # frame time (s) of each pair's latest exchange (undo_factor)

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
        slot_label, slot_conf = decode(prob, len(used), self.config.one_to_one)
        if self.fp_rate is not None:
            weight = 1.0 - math.exp(-dt / self.config.fp_prior_s)
            self.fp_rate += weight * (int((slot_label < 0).sum()) - self.fp_rate)
        labels, conf = np.full(n, -1), np.zeros(n)
        labels[used], conf[used] = slot_label, slot_conf
        if self.config.pair_swap is not None:
            labels = self._pair_swaps(labels, conf, heading, age, dt)
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
        out[:, -1] *= min(max(self.fp_rate / self.config.fp_prior_ref, 0.2), 5.0)
        return out / np.maximum(out.sum(axis=1, keepdims=True), 1e-12)

    def _hide_stale(self, reported: np.ndarray, age: np.ndarray, position: np.ndarray,
                    heading: np.ndarray) -> np.ndarray:
        """The reported headings (radians) with NaN (never heard, for the network) for every agent whose
        report is older than ``stale_s`` while a detection within ``stale_radius_m`` of its remembered
        position is more than ``stale_turn`` away from that report: the robot has turned since it last
        reported, and only its remembered position still says which detection it is."""
        cfg = self.config
        stale = np.isfinite(age) & (age > cfg.stale_s) & self.net.remembers()
        if not stale.any() or not len(position):
            return reported
        out = reported.copy()
        for j in np.flatnonzero(stale):
            near = np.linalg.norm(position - self.net.p[j], axis=1) < cfg.stale_radius_m
            turned = np.abs(np.angle(np.exp(1j * (heading[near] - reported[j])))) > cfg.stale_turn
            if turned.any():
                out[j] = np.nan
        return out

    def _report_jumps(self, heading: np.ndarray, t_sent: np.ndarray) -> None:
        """Exchange or forget the memories of the agents whose reports jumped to another robot since their previous
        newest report (``heading``, radians, sent at ``t_sent`` seconds; :mod:`lookalike.learn.report_jumps`)."""
        assert self._jumps is not None
        for action in self._jumps.find(heading, t_sent, self._beacons.heading, self._beacons.t_sent, self._last_time):
            if isinstance(action, tuple):
                self._exchange_memories(*action)
            else:
                self._forget(action)

    def _forget(self, agents: np.ndarray) -> None:
        """Forget the network's memory of ``agents`` (indices) and restart their report tracks (exchange_llr)."""
        self.net.forget(np.isin(np.arange(self.config.n_agents), agents))
        if self._exchange is not None:
            for a in agents.tolist():
                self._exchange.forget(a)

    def _exchange_memories(self, a: int, b: int) -> None:
        """Exchange agents ``a`` and ``b``'s memories (the network's and the exchange detector's tracks)."""
        self._swap_network(a, b)
        if self._exchange is not None:
            self._exchange.swap(a, b)

    def _swap_network(self, a: int, b: int) -> None:
        """Exchange agents ``a`` and ``b``'s memories in the network. For ``undo_factor``, note when: an agent may undo
        only its latest exchange, and an exchange that undoes one leaves the pair as any other (a third exchange needs
        the full evidence)."""
        self.net.swap(a, b)
        undone = self._last_time - self._exchanged_at[a, b] <= self.config.undo_s
        self._exchanged_at[[a, b], :] = -np.inf
        self._exchanged_at[:, [a, b]] = -np.inf
        if not undone:
            self._exchanged_at[a, b] = self._exchanged_at[b, a] = self._last_time

    def _threshold_scale(self, agent: int | None = None) -> np.ndarray | None:
        """``undo_factor``: the factor on the exchange detectors' thresholds per pair of agents, or of ``agent`` with
        each other agent (None: off)."""
        cfg = self.config
        if cfg.undo_factor is None:
            return None
        since = self._last_time - (self._exchanged_at if agent is None else self._exchanged_at[agent])
        return np.where(since <= cfg.undo_s, cfg.undo_factor, 1.0)

    def _report_exchanges(self, frame: Frame) -> None:
        """``exchange_llr``: feed the frame's reports to the exchange detector
        (:class:`~lookalike.learn.report_exchange.ReportExchange`) and exchange the memories of each pair it
        finds; a report jump of either agent within the next second is then the same exchange
        (``report_jump`` does nothing more)."""
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
        """``visual_exchange``: exchange the memories, and this frame's labels, of the pairs of agents whose
        detections' visual headings ``heading`` (radians) fit each other's reports better
        (:class:`~lookalike.learn.visual_exchange.VisualExchange`). Returns the labels."""
        assert self._visual is not None
        held = agent_detections(labels, conf, self.config.n_agents)
        pairs = self._visual.update(held, heading, self._beacons.heading, age, dt, self._threshold_scale())
        self.visual_exchanges += len(pairs)
        return self._exchange_pairs(labels, pairs)

    def _exchange_pairs(self, labels: np.ndarray, pairs: list[tuple[int, int]]) -> np.ndarray:
        """Exchange the network's memories and this frame's ``labels`` of each of ``pairs`` (no agent twice)."""
        out = labels
        for j, k in pairs:
            self._swap_network(j, k)
            out = np.where(labels == j, k, np.where(labels == k, j, out))
        return out

    def _pair_swaps(self, labels: np.ndarray, conf: np.ndarray, heading: np.ndarray, age: np.ndarray,
                    dt: float) -> np.ndarray:
        """``pair_swap``: for every two agents ``j, k`` holding a detection and a report younger than
        ``pair_fresh_s``, the frame's evidence that they are exchanged is how much better each detection's
        visual heading fits the other's report than its own (differences clipped at π/2, so a front/back
        flip counts little); it is summed with decay ``exp(-dt / pair_swap_s)`` and never below 0. When it
        passes ``pair_swap`` radians, the two memories and this frame's labels are exchanged (the largest
        first; an agent at most once per frame). Returns the labels."""
        cfg = self.config
        assert cfg.pair_swap is not None
        evidence = self._pair_evidence
        evidence *= np.exp(-dt / cfg.pair_swap_s)
        det = agent_detections(labels, conf, cfg.n_agents)
        fresh = (det >= 0) & (age <= cfg.pair_fresh_s)
        live = np.flatnonzero(fresh)
        if len(live) < 2:
            return labels
        psi = self._beacons.heading[live]
        phi = heading[det[live]]
        misfit = np.minimum(np.abs(np.angle(np.exp(1j * (phi[None, :] - psi[:, None])))), np.pi / 2)
        own = np.diag(misfit)
        gain = own[:, None] + own[None, :] - misfit - misfit.T
        block = evidence[np.ix_(live, live)]
        evidence[np.ix_(live, live)] = np.maximum(block + gain, 0.0)
        np.fill_diagonal(evidence, 0.0)
        pairs = take_pairs(evidence, cfg.pair_swap)
        self.pair_swaps += len(pairs)
        return self._exchange_pairs(labels, pairs)
