"""Trackers: the protocol, the registry by name and the implementations."""

from lookalike.trackers.base import Tracker
from lookalike.trackers.boxtrack import BoxTrack
from lookalike.trackers.deepsort import DeepSort
from lookalike.trackers.diversort import DiverSort
from lookalike.trackers.health import HealthConfig, HealthMonitor, HealthStatus
from lookalike.trackers.jpda import JpdaTracker
from lookalike.trackers.kalman_ha import KalmanHA, KalmanHA2
from lookalike.trackers.registry import (
    ParameterInfo,
    make_tracker,
    register_tracker,
    tracker_class,
    tracker_names,
    tracker_parameters,
)
from lookalike.trackers.sort import Sort
from lookalike.types.tracks import TrackStatus

__all__ = [
    "BoxTrack",
    "DeepSort",
    "DiverSort",
    "HealthConfig",
    "HealthMonitor",
    "HealthStatus",
    "JpdaTracker",
    "KalmanHA",
    "KalmanHA2",
    "ParameterInfo",
    "Sort",
    "TrackStatus",
    "Tracker",
    "make_tracker",
    "register_tracker",
    "tracker_class",
    "tracker_names",
    "tracker_parameters",
]
