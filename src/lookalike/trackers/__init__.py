"""Trackers: the protocol, the registry by name and the implementations.

Names are imported on first use (``from lookalike.trackers import Sort`` imports only :mod:`lookalike.trackers.sort`),
so that listing or building one tracker does not load the others."""

from __future__ import annotations

from typing import TYPE_CHECKING

from lookalike._lazy import lazy_attributes

if TYPE_CHECKING:
    from lookalike.trackers.base import Tracker
    from lookalike.trackers.boxtrack import BoxTrack
    from lookalike.trackers.deepsort import DeepSort
    from lookalike.trackers.diversort import DiverSort
    from lookalike.trackers.jpda import JpdaTracker
    from lookalike.trackers.kalman_ha import KalmanHA, KalmanHA2
    from lookalike.trackers.parts.health import HealthConfig, HealthMonitor, HealthStatus
    from lookalike.trackers.registry import (
        ParameterInfo,
        UnknownTrackerError,
        make_tracker,
        register_tracker,
        tracker_class,
        tracker_names,
        tracker_parameters,
    )
    from lookalike.trackers.sort import Sort
    from lookalike.types.tracks import TrackStatus

_HOME = {
    "Tracker": "lookalike.trackers.base",
    "BoxTrack": "lookalike.trackers.boxtrack",
    "DeepSort": "lookalike.trackers.deepsort",
    "DiverSort": "lookalike.trackers.diversort",
    "HealthConfig": "lookalike.trackers.parts.health",
    "HealthMonitor": "lookalike.trackers.parts.health",
    "HealthStatus": "lookalike.trackers.parts.health",
    "JpdaTracker": "lookalike.trackers.jpda",
    "KalmanHA": "lookalike.trackers.kalman_ha",
    "KalmanHA2": "lookalike.trackers.kalman_ha",
    "ParameterInfo": "lookalike.trackers.registry",
    "make_tracker": "lookalike.trackers.registry",
    "register_tracker": "lookalike.trackers.registry",
    "tracker_class": "lookalike.trackers.registry",
    "tracker_names": "lookalike.trackers.registry",
    "tracker_parameters": "lookalike.trackers.registry",
    "UnknownTrackerError": "lookalike.trackers.registry",
    "Sort": "lookalike.trackers.sort",
    "TrackStatus": "lookalike.types.tracks",
}


__getattr__, __dir__ = lazy_attributes("lookalike.trackers", _HOME, globals())


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
    "UnknownTrackerError",
    "make_tracker",
    "register_tracker",
    "tracker_class",
    "tracker_names",
    "tracker_parameters",
]
