"""The one Kalman filter (stateless, batched), motion models and chi-square gating."""

from lookalike.motion.gating import chi2_gate
from lookalike.motion.kalman import gating_distance, predict, project, update
from lookalike.motion.models import constant_acceleration, constant_velocity

__all__ = [
    "chi2_gate",
    "constant_acceleration",
    "constant_velocity",
    "gating_distance",
    "predict",
    "project",
    "update",
]
