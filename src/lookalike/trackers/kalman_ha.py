"""Kalman-HA and Kalman-HA2 (seed A's baselines): world-frame trackers identified by beacons.

Both track ground positions (observer frame, metres) with one constant-acceleration Kalman filter
per track (state ``[x, y, vx, vy, ax, ay]``, the frames' real time steps), measurement noise
``std = meas_std0_m + meas_std_per_m · distance`` and Hungarian association on the squared
Mahalanobis distance inside a chi-square gate. Tracks are identified with the N reporting agents
by the beacon identifier (:mod:`lookalike.trackers.parts.identity`), and every detection taken by an
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

from lookalike.trackers.parts.world_rules import HeuristicsConfig, WorldConfig, WorldRules
from lookalike.trackers.parts.world_tracker import WorldTracker
from lookalike.trackers.registry import register_tracker


@register_tracker("kalman_ha")
class KalmanHA(WorldTracker):
    """Kalman-HA: constant acceleration, Hungarian on Mahalanobis distance, no heuristics."""

    Config = WorldConfig

    def __init__(self, config: WorldConfig | None = None) -> None:
        super().__init__(config or WorldConfig(), WorldRules.none())


@register_tracker("kalman_ha2")
class KalmanHA2(WorldTracker):
    """Kalman-HA2: Kalman-HA with our false-positive / false-negative heuristics."""

    Config = HeuristicsConfig

    def __init__(self, config: HeuristicsConfig | None = None) -> None:
        cfg = config or HeuristicsConfig()
        super().__init__(cfg, WorldRules.from_config(cfg))
