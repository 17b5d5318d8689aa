"""Kalman-HA and Kalman-HA2, the robot-identification paper's baselines: ground positions (observer frame, metres), a
constant-acceleration Kalman filter per track, Hungarian association inside a chi-square gate, identities from the
beacon identifier (:mod:`lookalike.trackers.parts.identity`).

- Kalman-HA: a track starts at every unmatched detection and ends at its first miss.
- Kalman-HA2 (heuristics the paper cites without listing; ours): births gated by score and distance to tracks,
  confirmation by hits in a window, coasting limits in and out of view, only confirmed tracks identified."""

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
