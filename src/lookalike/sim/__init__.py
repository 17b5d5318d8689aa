"""Simulators that make labelled data."""

from lookalike.sim.boxes import BoxScene, BoxSceneConfig, simulate_boxes
from lookalike.sim.network import ReportArrays, simulate_reports
from lookalike.sim.presets import DEFAULT_NOISE, NOISE_MODELS, PRESET_NAMES, noise_sensor, preset, preset_label
from lookalike.sim.robots import RobotArrays, RobotSequence, simulate_arrays, simulate_robots
from lookalike.sim.robots_config import (
    MotionConfig,
    NetworkConfig,
    ObserverConfig,
    RobotWorldConfig,
    SensorConfig,
)

__all__ = [
    "BoxScene",
    "DEFAULT_NOISE",
    "BoxSceneConfig",
    "MotionConfig",
    "NOISE_MODELS",
    "NetworkConfig",
    "ObserverConfig",
    "PRESET_NAMES",
    "ReportArrays",
    "RobotArrays",
    "RobotSequence",
    "RobotWorldConfig",
    "SensorConfig",
    "noise_sensor",
    "preset",
    "preset_label",
    "simulate_arrays",
    "simulate_boxes",
    "simulate_reports",
    "simulate_robots",
]
