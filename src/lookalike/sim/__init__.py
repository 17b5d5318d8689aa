"""Simulators that make labelled data."""

from lookalike.sim.boxes import BoxScene, BoxSceneConfig, simulate_boxes
from lookalike.sim.network import ReportArrays, simulate_reports
from lookalike.sim.presets import PRESET_NAMES, preset, preset_label
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
    "BoxSceneConfig",
    "MotionConfig",
    "NetworkConfig",
    "ObserverConfig",
    "PRESET_NAMES",
    "ReportArrays",
    "RobotArrays",
    "RobotSequence",
    "RobotWorldConfig",
    "SensorConfig",
    "preset",
    "preset_label",
    "simulate_arrays",
    "simulate_boxes",
    "simulate_reports",
    "simulate_robots",
]
