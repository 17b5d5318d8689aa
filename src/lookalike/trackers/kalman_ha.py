"""Kalman-HA and Kalman-HA2 (seed A's baselines): world-frame trackers identified by beacons.

Both track ground positions (observer frame, metres) with one constant-acceleration Kalman filter
per track (state ``[x, y, vx, vy, ax, ay]``, the frames' real time steps), measurement noise
``std = meas_std0_m + meas_std_per_m · distance`` and Hungarian association on the squared
Mahalanobis distance inside a chi-square gate. Tracks are identified with the N reporting agents
by the beacon identifier (:mod:`lookalike.trackers.identity`), and every detection taken by an
identified track carries its agent id.

- **Kalman-HA** (no heuristics): a track starts at every unmatched detection and ends at its
  first miss; every track is identified.
- **Kalman-HA2** (our heuristics; seed A cites them without listing them):
  1. births only from detections scoring at least ``birth_min_score`` and farther than
     ``birth_exclusion_m`` from every existing track's prediction (clutter and duplicates);
  2. a tentative track is confirmed after ``confirm_hits`` hits in its last ``confirm_window``
     frames and deleted after ``tentative_max_misses`` consecutive misses;
  3. a confirmed track coasts on its prediction (acceleration dropped, velocity decaying with
     ``coast_velocity_decay_s``) for up to ``max_coast_s`` while predicted inside the camera's
     view and ``max_out_of_view_s`` while predicted outside it (a robot that walked out of the
     view is expected back where it left);
  4. only confirmed tracks are identified and label detections.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from lookalike.association.solver import assign
from lookalike.motion import chi2_gate, constant_acceleration, gating_distance, kalman
from lookalike.trackers.base import check_positive, param
from lookalike.trackers.identity import BeaconIdentifier, IdentifierConfig
from lookalike.trackers.registry import register_tracker
from lookalike.types import Detections, Frame, TrackSnapshot, TrackStatus

H = np.hstack([np.eye(2), np.zeros((2, 4))])


@dataclass(frozen=True)
class WorldConfig:
    """Parameters shared by the world-frame trackers (metres, seconds, radians)."""

    n_agents: int = param(3, "number of reporting agents N")
    q_jerk: float = param(4.0, "white-jerk spectral density of the constant-acceleration model (m²/s⁵)")
    meas_std0_m: float = param(0.05, "position noise at distance 0 (m)")
    meas_std_per_m: float = param(0.04, "growth of the position noise per metre of distance")
    init_velocity_std: float = param(0.5, "initial velocity standard deviation (m/s)")
    init_accel_std: float = param(1.0, "initial acceleration standard deviation (m/s²)")
    gate_probability: float = param(0.99, "chi-square gate probability (2 dof)")
    window_frames: int = param(30, "identifier: frames of heading samples compared with the reports")
    max_identity_cost: float = param(0.3, "identifier: largest mean (1 - cos)/2 heading cost assigned")
    hysteresis: float = param(0.08, "identifier: cost bonus of a track's current agent")

    def __post_init__(self) -> None:
        check_positive(self, "n_agents", "meas_std0_m", "meas_std_per_m", "init_velocity_std", "init_accel_std",
                       "max_identity_cost", "hysteresis", "q_jerk", allow_zero=True)
        check_positive(self, "window_frames")
        if not 0 < self.gate_probability < 1:
            raise ValueError(f"{type(self).__name__}.gate_probability must be in (0, 1), got {self.gate_probability}")


@dataclass(frozen=True)
class HeuristicsConfig(WorldConfig):
    """Kalman-HA2's lifecycle heuristics on top of :class:`WorldConfig`."""

    birth_min_score: float = param(0.45, "lowest detector score that starts a track")
    birth_exclusion_m: float = param(0.35, "no birth this close to an existing track's prediction (m)")
    confirm_hits: int = param(3, "hits needed to confirm a tentative track ...")
    confirm_window: int = param(5, "... within this many latest frames")
    tentative_max_misses: int = param(2, "consecutive misses that delete a tentative track")
    max_coast_s: float = param(0.7, "longest coasting of a confirmed track predicted in view (s)")
    max_out_of_view_s: float = param(3.0, "longest coasting of a confirmed track predicted out of view (s)")
    coast_velocity_decay_s: float = param(1.0, "time constant of the velocity decay while coasting (s)")
    fov_deg: float = param(80.0, "camera field of view (degrees) for out-of-view handling")
    min_range_m: float = param(0.3, "nearest visible distance (m)")
    max_range_m: float = param(7.0, "farthest visible distance (m)")

    def __post_init__(self) -> None:
        super().__post_init__()
        check_positive(self, "confirm_hits", "confirm_window", "tentative_max_misses", "coast_velocity_decay_s",
                       "fov_deg", "max_range_m")
        check_positive(self, "birth_min_score", "birth_exclusion_m", "max_coast_s", "max_out_of_view_s",
                       "min_range_m", allow_zero=True)
        if self.confirm_hits > self.confirm_window:
            raise ValueError(f"{type(self).__name__}.confirm_hits ({self.confirm_hits}) exceeds confirm_window "
                             f"({self.confirm_window})")


class WorldTracker:
    """Track store, prediction, births, identification and output shared by the world trackers.

    Subclasses implement :meth:`_associate_and_update` (returns the detection index per track,
    -1 for a miss) and set ``heuristics`` (False: Kalman-HA's lifecycle).
    """

    heuristics = True

    def __init__(self, config: WorldConfig) -> None:
        self.config = config
        self._gate = chi2_gate(2, config.gate_probability)
        self.reset()

    def reset(self) -> None:
        """Forget every track; ids restart at 1."""
        cfg = self.config
        self._mean = np.zeros((0, 6))
        self._cov = np.zeros((0, 6, 6))
        self._ids = np.zeros(0, dtype=int)
        self._confirmed = np.zeros(0, dtype=bool)
        self._hits = np.zeros(0, dtype=np.int64)  # bit history, bit 0 = this frame
        self._misses = np.zeros(0, dtype=int)
        self._unseen_s = np.zeros(0)
        self._next_id = 1
        self._time: float | None = None
        self._identifier = BeaconIdentifier(IdentifierConfig(
            n_agents=cfg.n_agents, window_frames=cfg.window_frames, max_cost=cfg.max_identity_cost,
            hysteresis=cfg.hysteresis))

    # -- the frame loop ----------------------------------------------------------------------

    def update(self, frame: Frame) -> list[TrackSnapshot]:
        """Predict, associate, update, manage the lifecycle, identify; return the reported tracks."""
        det = frame.detections
        if len(det) and (det.position is None or det.heading is None):
            raise ValueError(f"frame {frame.index}: {self.name} needs detections with position and heading")
        dt = 0.0 if self._time is None else frame.time - self._time
        if dt < 0:
            raise ValueError(f"frame {frame.index}: time went backwards ({self._time} s then {frame.time} s)")
        self._time = frame.time
        self._identifier.begin_frame(frame.time, frame.beacons)
        self._predict(dt)
        det_of_track = self._associate_and_update(det)
        hit = det_of_track >= 0
        self._hits = ((self._hits << 1) | hit) & ((1 << 30) - 1)
        self._misses = np.where(hit, 0, self._misses + 1)
        self._unseen_s = np.where(hit, 0.0, self._unseen_s + dt)
        for i in np.flatnonzero(hit):
            self._identifier.observe(int(self._ids[i]), float(det.heading[det_of_track[i]]))
        det_of_track = self._lifecycle(det_of_track)
        new = self._births(det, det_of_track)
        det_of_track = np.concatenate([det_of_track, new])
        for i, k in zip(range(len(self._ids) - len(new), len(self._ids)), new):
            self._identifier.observe(int(self._ids[i]), float(det.heading[k]))
        return self._report(det, det_of_track)

    # -- steps -------------------------------------------------------------------------------

    def _predict(self, dt: float) -> None:
        if not len(self._ids) or dt == 0:
            return
        F, Q = constant_acceleration(2, dt, self.config.q_jerk)
        if self.heuristics:
            coasting = self._misses > 0
            if coasting.any():
                decay = np.exp(-dt / self.config.coast_velocity_decay_s)  # type: ignore[attr-defined]
                self._mean[coasting, 2:4] *= decay
                self._mean[coasting, 4:6] = 0.0
        self._mean, self._cov = kalman.predict(self._mean, self._cov, F, Q)

    def _noise(self, position: np.ndarray) -> np.ndarray:
        """Measurement covariances ``(k, 2, 2)`` for positions ``(k, 2)``."""
        std = self.config.meas_std0_m + self.config.meas_std_per_m * np.hypot(position[:, 0], position[:, 1])
        return (std**2)[:, None, None] * np.eye(2)[None]

    def _distances(self, det: Detections) -> np.ndarray:
        """Squared Mahalanobis distances ``(tracks, detections)``, inf outside the gate."""
        if not len(self._ids) or not len(det):
            return np.full((len(self._ids), len(det)), np.inf)
        R = self._noise(self._mean[:, :2])
        d2 = gating_distance(self._mean, self._cov, det.position, H, R)
        return np.where(d2 <= self._gate, d2, np.inf)

    def _kalman_update(self, rows: np.ndarray, z: np.ndarray) -> None:
        if len(rows):
            R = self._noise(self._mean[rows, :2])
            self._mean[rows], self._cov[rows] = kalman.update(self._mean[rows], self._cov[rows], z, H, R)

    def _associate_and_update(self, det: Detections) -> np.ndarray:
        """Hungarian on the gated squared Mahalanobis distance; Kalman update of matched tracks."""
        det_of_track = np.full(len(self._ids), -1, dtype=int)
        if len(self._ids) and len(det):
            matches, _, _ = assign(self._distances(det))
            det_of_track[matches[:, 0]] = matches[:, 1]
            self._kalman_update(matches[:, 0], det.position[matches[:, 1]])
        return det_of_track

    def _lifecycle(self, det_of_track: np.ndarray) -> np.ndarray:
        """Confirm and delete tracks; return ``det_of_track`` of the survivors."""
        if not self.heuristics:
            keep = det_of_track >= 0
            self._confirmed[:] = True
        else:
            cfg = self.config
            recent = self._hits & ((1 << cfg.confirm_window) - 1)  # type: ignore[attr-defined]
            hits = np.bitwise_count(recent).astype(int)
            self._confirmed |= hits >= cfg.confirm_hits  # type: ignore[attr-defined]
            limit = np.where(self._in_view(self._mean[:, :2]), cfg.max_coast_s, cfg.max_out_of_view_s)  # type: ignore[attr-defined]
            keep = np.where(self._confirmed, self._unseen_s <= limit + 1e-9,
                            self._misses < cfg.tentative_max_misses)  # type: ignore[attr-defined]
        if not keep.all():
            self._identifier.drop(self._ids[~keep])
            self._mean, self._cov, self._ids = self._mean[keep], self._cov[keep], self._ids[keep]
            self._confirmed, self._hits = self._confirmed[keep], self._hits[keep]
            self._misses, self._unseen_s = self._misses[keep], self._unseen_s[keep]
        return det_of_track[keep]

    def _in_view(self, position: np.ndarray) -> np.ndarray:
        cfg = self.config
        d = np.hypot(position[:, 0], position[:, 1])
        bearing = np.abs(np.arctan2(position[:, 1], position[:, 0]))
        return (bearing <= np.radians(cfg.fov_deg) / 2) & (d >= cfg.min_range_m) & (d <= cfg.max_range_m)  # type: ignore[attr-defined]

    def _birth_candidates(self, det: Detections, det_of_track: np.ndarray) -> np.ndarray:
        """Indices of detections that start tracks."""
        free = np.ones(len(det), dtype=bool)
        free[det_of_track[det_of_track >= 0]] = False
        if self.heuristics and len(det):
            cfg = self.config
            free &= det.score >= cfg.birth_min_score  # type: ignore[attr-defined]
            if len(self._ids):
                gap = np.linalg.norm(det.position[:, None, :] - self._mean[None, :, :2], axis=2).min(axis=1)
                free &= gap > cfg.birth_exclusion_m  # type: ignore[attr-defined]
        return np.flatnonzero(free)

    def _births(self, det: Detections, det_of_track: np.ndarray) -> np.ndarray:
        new = self._birth_candidates(det, det_of_track)
        n = len(new)
        if not n:
            return new
        cfg = self.config
        mean = np.zeros((n, 6))
        mean[:, :2] = det.position[new]
        cov = np.zeros((n, 6, 6))
        cov[:, :2, :2] = self._noise(det.position[new])
        cov[:, 2, 2] = cov[:, 3, 3] = cfg.init_velocity_std**2
        cov[:, 4, 4] = cov[:, 5, 5] = cfg.init_accel_std**2
        self._mean = np.vstack([self._mean, mean])
        self._cov = np.concatenate([self._cov, cov])
        self._ids = np.concatenate([self._ids, np.arange(self._next_id, self._next_id + n)])
        self._next_id += n
        self._confirmed = np.concatenate([self._confirmed, np.full(n, not self.heuristics)])
        self._hits = np.concatenate([self._hits, np.ones(n, dtype=np.int64)])
        self._misses = np.concatenate([self._misses, np.zeros(n, dtype=int)])
        self._unseen_s = np.concatenate([self._unseen_s, np.zeros(n)])
        return new

    def _report(self, det: Detections, det_of_track: np.ndarray) -> list[TrackSnapshot]:
        eligible = [int(t) for t in self._ids[self._confirmed]]
        identity = self._identifier.assign(eligible)
        out = []
        for i, track_id in enumerate(self._ids):
            k = int(det_of_track[i])
            agent, prob = identity.get(int(track_id), (None, None))
            if not self._confirmed[i]:
                status = TrackStatus.TENTATIVE
            else:
                status = TrackStatus.CONFIRMED if k >= 0 else TrackStatus.LOST
            out.append(TrackSnapshot(
                track_id=int(track_id), status=status, position=self._mean[i, :2].copy(),
                velocity=self._mean[i, 2:4].copy(), heading=float(det.heading[k]) if k >= 0 else None,
                agent_id=agent, identity_prob=prob, detection_index=k,
            ))
        return out


@register_tracker("kalman_ha")
class KalmanHA(WorldTracker):
    """Kalman-HA: constant acceleration, Hungarian on Mahalanobis distance, no heuristics."""

    heuristics = False
    Config = WorldConfig

    def __init__(self, config: WorldConfig | None = None) -> None:
        super().__init__(config or WorldConfig())


@register_tracker("kalman_ha2")
class KalmanHA2(WorldTracker):
    """Kalman-HA2: Kalman-HA with our false-positive / false-negative heuristics."""

    heuristics = True
    Config = HeuristicsConfig

    def __init__(self, config: HeuristicsConfig | None = None) -> None:
        super().__init__(config or HeuristicsConfig())
