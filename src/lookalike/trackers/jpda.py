"""JPDA tracker (a baseline of the robot-identification paper) in world coordinates (metres): each track takes the
mixture-reduced Kalman update of all gated detections weighted by the exact JPDA marginals β; its one detection for
labels is found by the Hungarian method on ``1 - β`` (none below ``min_assignment_prob``); detections no track explains
(``Σ_i β_ij < 0.5``) may start tracks. Lifecycle, births and identification are Kalman-HA2's."""

from __future__ import annotations

from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from lookalike.association.jpda import jpda_marginals
from lookalike.association.solver import assign
from lookalike.motion import kalman
from lookalike.trackers.base import COUNT, POSITIVE, UNIT, Range, param
from lookalike.trackers.parts.world_rules import HeuristicsConfig, WorldRules, positions
from lookalike.trackers.parts.world_tracker import H, WorldTracker
from lookalike.trackers.registry import register_tracker
from lookalike.types import Detections, Frame, Tracks


@dataclass(frozen=True)
class JpdaConfig(HeuristicsConfig):
    """Kalman-HA2's parameters plus JPDA's detection and clutter model."""

    p_detection: float = param(0.85, "probability P_D that a tracked target is detected",
                               range=Range(0, 1, low_open=True))
    clutter_density: float = param(0.03, "false positives per square metre of the view, λ", range=POSITIVE)
    min_assignment_prob: float = param(0.3, "smallest β of a track's labelled detection", range=UNIT)
    max_events: int = param(5000, "joint events enumerated per cluster before the exact subset DP", range=COUNT)


class _Marginals(NamedTuple):
    """One frame's association: the tracks' projected positions ``z_hat (k, 2)`` and covariances ``S (k, 2, 2)``, the
    marginals ``beta (k, m)`` and ``beta_miss (k,)``."""

    z_hat: np.ndarray
    S: np.ndarray
    beta: np.ndarray
    beta_miss: np.ndarray


@register_tracker("jpda")
class JpdaTracker(WorldTracker):
    """JPDA track maintenance with Kalman-HA2's lifecycle and the beacon identifier."""

    Config = JpdaConfig

    def __init__(self, config: JpdaConfig | None = None) -> None:
        self.jpda = config or JpdaConfig()
        super().__init__(self.jpda, WorldRules.from_config(self.jpda))
        self._explained = np.zeros(0)
        self._pending: _Marginals | None = None  # this frame's association, found before anything changed

    def update(self, frame: Frame) -> Tracks:
        """As :meth:`WorldTracker.update`; a frame whose clusters exceed the exact methods' limits is refused
        (``ValueError``) before anything changes."""
        self._pending = self._frame_marginals(frame)
        try:
            return super().update(frame)
        finally:
            self._pending = None

    def _frame_marginals(self, frame: Frame) -> _Marginals | None:
        """The association of ``frame``'s detections with the tracks as :meth:`update` will predict them (None where
        there is nothing to associate, or :meth:`update` refuses the frame for another reason)."""
        det, t = frame.detections, self._tracks
        dt = 0.0 if self._time is None else frame.time - self._time
        if not len(t) or not len(det) or det.position is None or det.heading is None or dt < 0:
            return None
        mean, cov = self._predicted(t.mean.copy(), t.cov, dt) if dt != 0 else (t.mean, t.cov)
        return self._marginals(mean, cov, det)

    def _marginals(self, mean: np.ndarray, cov: np.ndarray, det: Detections) -> _Marginals:
        """The projected tracks ``z_hat``, ``S`` and the JPDA marginals of tracks ``mean``, ``cov`` and ``det``."""
        cfg = self.jpda
        R = self._space.R(mean[:, :2])
        z_hat, S = kalman.project(mean, cov, H, R)
        d2 = kalman.gating_distance(mean, cov, positions(det), H, R)
        d2 = np.where(d2 <= self._gate, d2, np.inf)
        norm = 1.0 / (2 * np.pi * np.sqrt(np.linalg.det(S)))  # (k,)
        likelihood = np.where(np.isfinite(d2), cfg.p_detection * norm[:, None] * np.exp(-0.5 * np.where(
            np.isfinite(d2), d2, 0.0)) / cfg.clutter_density, 0.0)
        p_gate = 1.0 - np.exp(-0.5 * self._gate)  # chi-square CDF with 2 dof
        miss = np.full(len(mean), 1.0 - cfg.p_detection * p_gate)
        return _Marginals(z_hat, S, *jpda_marginals(likelihood, miss, cfg.max_events))

    def _associate_and_update(self, det: Detections) -> np.ndarray:
        cfg, t = self.jpda, self._tracks
        k, m = len(t), len(det)
        det_of_track = np.full(k, -1, dtype=int)
        self._explained = np.zeros(m)
        if not k or not m:
            return det_of_track
        pending = self._pending if self._pending is not None else self._marginals(t.mean, t.cov, det)
        z_hat, S, beta, beta_miss = pending
        self._explained = beta.sum(axis=0)
        # Mixture-reduced update.
        nu = positions(det)[None, :, :] - z_hat[:, None, :]  # (k, m, 2)
        nu_bar = np.einsum("km,kmd->kd", beta, nu)
        PHt = t.cov @ H.T
        K = np.swapaxes(np.linalg.solve(S, np.swapaxes(PHt, -1, -2)), -1, -2)  # (k, 6, 2)
        spread = np.einsum("km,kmd,kme->kde", beta, nu, nu) - nu_bar[:, :, None] * nu_bar[:, None, :]
        KSKt = K @ S @ np.swapaxes(K, -1, -2)
        updated = 1.0 - beta_miss
        t.mean = t.mean + np.einsum("kij,kj->ki", K, nu_bar)
        cov = t.cov - updated[:, None, None] * KSKt + K @ spread @ np.swapaxes(K, -1, -2)
        t.cov = 0.5 * (cov + np.swapaxes(cov, -1, -2))  # keep it symmetric against round-off
        # One detection per track for labels and the lifecycle.
        matches, _, _ = assign(1.0 - beta, 1.0 - cfg.min_assignment_prob)
        det_of_track[matches[:, 0]] = matches[:, 1]
        return det_of_track

    def _birth_candidates(self, det: Detections, det_of_track: np.ndarray) -> np.ndarray:
        new = super()._birth_candidates(det, det_of_track)
        if len(self._explained) == len(det):
            new = new[self._explained[new] < 0.5]
        return new
