"""The world-frame trackers' configuration (:class:`WorldConfig`, :class:`HeuristicsConfig`) and their lifecycle rules
as data (:class:`WorldRules`)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from lookalike.trackers.base import COUNT, NON_NEGATIVE, POSITIVE, PROBABILITY, UNIT, Range, check_params, param
from lookalike.trackers.parts.lifecycle import Lifecycle
from lookalike.types import Detections


@dataclass(frozen=True)
class WorldConfig:
    """Parameters shared by the world-frame trackers (metres, seconds, radians)."""

    n_agents: int = param(3, "number of reporting agents N", range=(0, 10_000))
    q_jerk: float = param(4.0, "white-jerk spectral density of the constant-acceleration model (m²/s⁵)",
                          range=NON_NEGATIVE)
    meas_std0_m: float = param(0.05, "position noise at distance 0 (m)", range=NON_NEGATIVE)
    meas_std_per_m: float = param(0.04, "growth of the position noise per metre of distance", range=NON_NEGATIVE)
    init_velocity_std: float = param(0.5, "initial velocity standard deviation (m/s)", range=NON_NEGATIVE)
    init_accel_std: float = param(1.0, "initial acceleration standard deviation (m/s²)", range=NON_NEGATIVE)
    gate_probability: float = param(0.99, "chi-square gate probability (2 dof)", range=PROBABILITY)
    window_frames: int = param(30, "identifier: frames of heading samples compared with the reports",
                               range=(1, 1_000_000))
    max_identity_cost: float = param(0.3, "identifier: largest mean (1 - cos)/2 heading cost assigned", range=UNIT)
    hysteresis: float = param(0.08, "identifier: cost bonus of a track's current agent", range=NON_NEGATIVE)

    def __post_init__(self) -> None:
        check_params(self)


@dataclass(frozen=True)
class HeuristicsConfig(WorldConfig):
    """Kalman-HA2's lifecycle heuristics on top of :class:`WorldConfig`."""

    birth_min_score: float = param(0.45, "lowest detector score that starts a track", range=UNIT)
    birth_exclusion_m: float = param(0.35, "no birth this close to an existing track's prediction (m)",
                                     range=NON_NEGATIVE)
    confirm_hits: int = param(3, "hits needed to confirm a tentative track ...", range=(1, 1_000_000))
    confirm_window: int = param(5, "... within this many latest frames", range=(1, 1_000_000))
    tentative_max_misses: int = param(2, "consecutive misses that delete a tentative track", range=COUNT)
    max_coast_s: float = param(0.7, "longest coasting of a confirmed track predicted in view (s)", range=NON_NEGATIVE)
    max_out_of_view_s: float = param(3.0, "longest coasting of a confirmed track predicted out of view (s)",
                                     range=NON_NEGATIVE)
    coast_velocity_decay_s: float = param(1.0, "time constant of the velocity decay while coasting (s)", range=POSITIVE)
    fov_deg: float = param(80.0, "camera field of view (degrees) for out-of-view handling",
                           range=Range(0, 360, low_open=True))
    min_range_m: float = param(0.3, "nearest visible distance (m)", range=NON_NEGATIVE)
    max_range_m: float = param(7.0, "farthest visible distance (m)", range=POSITIVE)

    def __post_init__(self) -> None:
        super().__post_init__()
        if self.confirm_hits > self.confirm_window:
            raise ValueError(f"{type(self).__name__}.confirm_hits ({self.confirm_hits}) exceeds confirm_window "
                             f"({self.confirm_window})")


@dataclass(frozen=True)
class WorldRules:
    """A world tracker's lifecycle rules: Kalman-HA's (:meth:`none`) or Kalman-HA2's heuristics (:meth:`from_config`);
    None: the rule is off. Seconds, metres."""

    lifecycle: Lifecycle  # confirmation (``n_init`` hits within ``confirm_window`` frames) and deletion
    born_confirmed: bool = True  # a new track is confirmed (and identified) at once
    confirm_window: int | None = None  # latest frames whose hits confirm (None: every track confirmed)
    coast_decay_s: float | None = None  # time constant of a missed track's velocity decay
    birth_min_score: float | None = None  # lowest score that starts a track
    birth_exclusion_m: float | None = None  # no birth this close to a track's prediction
    view: tuple[float, float, float] | None = None  # the camera's (fov_deg, min_range_m, max_range_m)
    max_coast_s: float = 0.0  # longest coasting while predicted in view ...
    max_out_of_view_s: float = 0.0  # ... and out of it

    @classmethod
    def none(cls) -> WorldRules:
        """Kalman-HA: every track confirmed at birth and deleted at its first miss."""
        return cls(Lifecycle(n_init=1, tentative_max_misses=1, max_misses=0))

    @classmethod
    def from_config(cls, cfg: HeuristicsConfig) -> WorldRules:
        """Kalman-HA2's heuristics from its configuration."""
        return cls(Lifecycle(n_init=cfg.confirm_hits, tentative_max_misses=cfg.tentative_max_misses),
                   born_confirmed=False, confirm_window=cfg.confirm_window,
                   coast_decay_s=cfg.coast_velocity_decay_s, birth_min_score=cfg.birth_min_score,
                   birth_exclusion_m=cfg.birth_exclusion_m, view=(cfg.fov_deg, cfg.min_range_m, cfg.max_range_m),
                   max_coast_s=cfg.max_coast_s, max_out_of_view_s=cfg.max_out_of_view_s)

    def in_view(self, position: np.ndarray) -> np.ndarray:
        """``(k,)`` True for positions ``(k, 2)`` (metres) inside the camera's view."""
        if self.view is None:
            return np.ones(len(position), dtype=bool)
        fov_deg, near, far = self.view
        d = np.hypot(position[:, 0], position[:, 1])
        bearing = np.abs(np.arctan2(position[:, 1], position[:, 0]))
        inside: np.ndarray = (bearing <= np.radians(fov_deg) / 2) & (d >= near) & (d <= far)
        return inside


def positions(det: Detections) -> np.ndarray:
    """The detections' ground positions ``(n, 2)`` in metres (``(0, 2)`` for a batch without them)."""
    return np.zeros((0, 2)) if det.position is None else det.position


def headings(det: Detections) -> np.ndarray:
    """The detections' visual headings ``(n,)`` in radians (empty for a batch without them)."""
    return np.zeros(0) if det.heading is None else det.heading
