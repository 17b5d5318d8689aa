"""Frozen configuration of the robot world. Units: metres, seconds, radians; rates per second unless the name says
``per_frame``. Observer frame: x forward, y left; headings absolute in (-π, π]."""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any


def _require(owner: str, name: str, value: float, low: float, high: float = math.inf,
             low_open: bool = False) -> None:
    ok = (value > low if low_open else value >= low) and value <= high and math.isfinite(value)
    if not ok:
        bracket = "(" if low_open else "["
        raise ValueError(f"{owner}.{name} must be in {bracket}{low}, {high}], got {value!r}")


@dataclass(frozen=True)
class MotionConfig:
    """Random bounded omnidirectional motion: behaviour segments (mean ``segment_s``) of walk, stand, turn or walk while
    turning (probabilities in that order); velocity follows its target with acceleration below ``max_accel``."""

    max_speed_mps: float = 0.5
    max_accel_mps2: float = 0.8
    max_turn_rate: float = 1.5
    max_turn_accel: float = 4.0
    segment_s: float = 2.5
    p_walk: float = 0.45
    p_stand: float = 0.2
    p_turn: float = 0.15
    p_walk_turn: float = 0.2
    robot_radius_m: float = 0.2

    def __post_init__(self) -> None:
        own = "MotionConfig"
        for name in ("max_speed_mps", "max_accel_mps2", "max_turn_rate", "max_turn_accel", "segment_s",
                     "robot_radius_m"):
            _require(own, name, getattr(self, name), 0.0, low_open=True)
        probs = (self.p_walk, self.p_stand, self.p_turn, self.p_walk_turn)
        for name, p in zip(("p_walk", "p_stand", "p_turn", "p_walk_turn"), probs):
            _require(own, name, p, 0.0, 1.0)
        if abs(sum(probs) - 1.0) > 1e-9:
            raise ValueError(f"{own}: p_walk + p_stand + p_turn + p_walk_turn must be 1, got {sum(probs)}")


@dataclass(frozen=True)
class ObserverConfig:
    """The observer's camera at field position ``position_m`` (origin at the centre, x along the length); its yaw is
    ``yaw_rad`` plus two sinusoids of amplitude ``pan_amplitude_rad`` (random phases)."""

    position_m: tuple[float, float] = (-4.3, 0.0)
    yaw_rad: float = 0.0
    pan_amplitude_rad: float = 0.35
    pan_period_s: float = 25.0
    fov_rad: float = math.radians(80.0)
    min_range_m: float = 0.3
    max_range_m: float = 7.0

    def __post_init__(self) -> None:
        own = "ObserverConfig"
        _require(own, "fov_rad", self.fov_rad, 0.0, 2 * math.pi, low_open=True)
        _require(own, "min_range_m", self.min_range_m, 0.0)
        _require(own, "max_range_m", self.max_range_m, self.min_range_m, low_open=True)
        _require(own, "pan_amplitude_rad", self.pan_amplitude_rad, 0.0, math.pi)
        _require(own, "pan_period_s", self.pan_period_s, 0.0, low_open=True)


@dataclass(frozen=True)
class SensorConfig:
    """The detector and heading-classifier model.

    Position noise: Gaussian in the observer frame, ``std = std0 + std_per_m · distance`` (by default larger in depth;
    :func:`lookalike.sim.presets.noise_sensor` makes the paper's). Visual heading: flipped (+π) with
    ``heading_flip_prob``, Gaussian noise ``heading_noise_rad``, snapped to its ``heading_classes`` bin. Detection
    probability: ``p_detect`` within ``best_range_m``, linear to ``p_detect_far``/``p_detect_near`` at the range limits,
    times ``1 - occlusion / occlusion_hide``. False positives: Poisson ``fp_per_frame`` over the visible sector. Scores:
    Beta ``tp_score_beta`` / ``fp_score_beta``."""

    std_x0_m: float = 0.05
    std_x_per_m: float = 0.04
    std_y0_m: float = 0.03
    std_y_per_m: float = 0.015
    heading_classes: int = 10
    heading_noise_rad: float = math.radians(12.0)
    heading_flip_prob: float = 0.03
    heading_std_rad: float = math.radians(20.0)
    p_detect: float = 0.93
    p_detect_near: float = 0.6
    p_detect_far: float = 0.4
    best_range_m: tuple[float, float] = (1.0, 5.0)
    occlusion_hide: float = 0.7
    fp_per_frame: float = 0.5
    tp_score_beta: tuple[float, float] = (6.0, 2.0)
    fp_score_beta: tuple[float, float] = (2.5, 3.0)

    def __post_init__(self) -> None:
        own = "SensorConfig"
        for name in ("std_x0_m", "std_x_per_m", "std_y0_m", "std_y_per_m", "heading_noise_rad",
                     "heading_std_rad", "fp_per_frame"):
            _require(own, name, getattr(self, name), 0.0)
        if int(self.heading_classes) != self.heading_classes or self.heading_classes < 0:
            raise ValueError(f"{own}.heading_classes must be a non-negative integer (0: continuous), "
                             f"got {self.heading_classes!r}")
        for name in ("heading_flip_prob", "p_detect", "p_detect_near", "p_detect_far"):
            _require(own, name, getattr(self, name), 0.0, 1.0)
        _require(own, "occlusion_hide", self.occlusion_hide, 0.0, 1.0, low_open=True)
        if not 0 <= self.best_range_m[0] <= self.best_range_m[1]:
            raise ValueError(f"{own}.best_range_m must be (near, far) with 0 <= near <= far, got {self.best_range_m}")
        for name in ("tp_score_beta", "fp_score_beta"):
            a, b = getattr(self, name)
            if a <= 0 or b <= 0:
                raise ValueError(f"{own}.{name} must hold two positive Beta parameters, got {(a, b)}")


@dataclass(frozen=True)
class NetworkConfig:
    """Heading reports (IMU noise ``imu_noise_rad``) sent at ``rate_hz``, delayed by ``delay_s`` plus exponential jitter
    of mean ``jitter_s``, lost with ``loss_prob``, in bursts (from ``burst_rate_hz``, mean ``burst_s``)."""

    rate_hz: float = 10.0
    delay_s: float = 0.03
    jitter_s: float = 0.02
    loss_prob: float = 0.1
    burst_rate_hz: float = 0.05
    burst_s: float = 1.0
    imu_noise_rad: float = math.radians(2.0)

    def __post_init__(self) -> None:
        own = "NetworkConfig"
        _require(own, "rate_hz", self.rate_hz, 0.0, low_open=True)
        for name in ("delay_s", "jitter_s", "burst_rate_hz", "burst_s", "imu_noise_rad"):
            _require(own, name, getattr(self, name), 0.0)
        _require(own, "loss_prob", self.loss_prob, 0.0, 1.0)

    def expected_loss(self) -> float:
        """Long-run fraction of reports lost (independent losses and bursts together)."""
        mean_good = math.inf if self.burst_rate_hz == 0 else 1.0 / self.burst_rate_hz
        bursty = 0.0 if self.burst_s == 0 or math.isinf(mean_good) else self.burst_s / (self.burst_s + mean_good)
        return 1.0 - (1.0 - self.loss_prob) * (1.0 - bursty)


@dataclass(frozen=True)
class RobotWorldConfig:
    """A robot-world scenario: N robots, an observer, at most M detections per frame, a ``field_m`` field."""

    n_agents: int = 3
    max_detections: int = 5
    frame_rate_hz: float = 30.0
    field_m: tuple[float, float] = (9.0, 6.0)
    observer: ObserverConfig = field(default_factory=ObserverConfig)
    motion: MotionConfig = field(default_factory=MotionConfig)
    sensor: SensorConfig = field(default_factory=SensorConfig)
    network: NetworkConfig = field(default_factory=NetworkConfig)

    def __post_init__(self) -> None:
        own = "RobotWorldConfig"
        if int(self.n_agents) != self.n_agents or self.n_agents < 0:
            raise ValueError(f"{own}.n_agents must be a non-negative integer, got {self.n_agents!r}")
        if int(self.max_detections) != self.max_detections or self.max_detections < 1:
            raise ValueError(f"{own}.max_detections must be a positive integer, got {self.max_detections!r}")
        _require(own, "frame_rate_hz", self.frame_rate_hz, 0.0, low_open=True)
        if min(self.field_m) <= 2 * self.motion.robot_radius_m:
            raise ValueError(f"{own}.field_m must exceed the robot diameter, got {self.field_m}")

    @property
    def dt_s(self) -> float:
        """Seconds between frames."""
        return 1.0 / self.frame_rate_hz

    def to_dict(self) -> dict[str, Any]:
        """A JSON-ready nested dictionary (tuples become lists)."""
        return dataclasses.asdict(self)

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> RobotWorldConfig:
        """Inverse of :meth:`to_dict`; unknown keys raise ``ValueError``."""
        parts = {"observer": ObserverConfig, "motion": MotionConfig, "sensor": SensorConfig,
                 "network": NetworkConfig}
        return _build(cls, {k: _build(parts[k], v) if k in parts else v for k, v in data.items()})


def _build(cls: type, data: Mapping[str, Any]) -> Any:
    names = {f.name: f for f in dataclasses.fields(cls)}
    unknown = sorted(set(data) - set(names))
    if unknown:
        raise ValueError(f"{cls.__name__}: unknown field(s) {unknown}")
    values = {k: tuple(v) if isinstance(v, list) else v for k, v in data.items()}
    return cls(**values)
