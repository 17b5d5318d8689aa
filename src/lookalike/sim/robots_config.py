"""Frozen configuration of the robot world: field, observer, motion, sensors, network.

Units: metres, seconds, radians; rates per second unless the name says ``per_frame``. The observer frame is x forward, y
left (metres), headings are absolute (world) in (-π, π]."""

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
    """Random bounded omnidirectional motion, piecewise by behaviour segments.

    Each robot switches behaviour after exponentially distributed times (mean ``segment_s``): walk (random velocity up
    to ``max_speed_mps``), stand still, turn on the spot (random turn rate up to ``max_turn_rate``), or walk while
    turning; probabilities in that order. Velocity follows its target with a first-order lag so that acceleration stays
    below ``max_accel``."""

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
    """The observer's camera: fixed position on the field, a slowly panning yaw.

    ``position_m`` is in field coordinates (origin at the centre, x along the length). The yaw is ``yaw_rad`` plus a sum
    of two sinusoids of amplitude ``pan_amplitude_rad`` (random phases), so robots leave and re-enter the ``fov_rad``
    wide view."""

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

    Position noise is Gaussian in the observer frame, ``std = std0 + std_per_m · distance``. The defaults make it larger
    along x (depth) than along y (across the image): our noise model, the reverse of Farazi and Behnke's, which is
    larger across the image (:func:`lookalike.sim.presets.noise_sensor` makes either; ``preset(name, noise="paper")`` is
    Farazi and Behnke's). The visual heading behaves like a 10-class classifier: with probability ``heading_flip_prob``
    the front and back are confused (+π); the relative heading gets Gaussian noise ``heading_noise_rad`` and is then
    snapped to the centre of its ``heading_classes`` bin (mean error ≈ 17° by default). Detection probability is
    ``p_detect`` within ``best_range_m``, falling linearly to ``p_detect_far`` at the maximum range and to
    ``p_detect_near`` at the minimum range, times ``1 - occlusion / occlusion_hide`` (0 once ``occlusion_hide`` of the
    width is hidden). False positives: Poisson with mean ``fp_per_frame``, uniform over the visible sector. Scores are
    Beta distributed, true positives ``tp_score_beta``, false positives ``fp_score_beta``."""

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
    """Heading reports over an unreliable network.

    Every robot sends its IMU heading (noise ``imu_noise_rad``) at ``rate_hz`` with a random phase; each report is
    delayed by ``delay_s`` plus an exponential jitter of mean ``jitter_s`` (so reports can arrive out of order), lost
    independently with ``loss_prob``, and lost for sure during loss bursts: bursts start at ``burst_rate_hz`` (per
    second of good link) and last an exponential time of mean ``burst_s``."""

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
    """A robot-world scenario: N identical robots, an observer, at most M detections per frame.

    ``max_detections`` is the set-up's M: when more are made, the M with the highest scores are kept. ``field_m`` is
    (length, width) of the field in metres."""

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
        kwargs: dict[str, Any] = {}
        for key, value in data.items():
            if key in parts:
                kwargs[key] = _build(parts[key], value)
            else:
                kwargs[key] = value
        return _build(cls, kwargs)


def _build(cls: type, data: Mapping[str, Any]) -> Any:
    names = {f.name: f for f in dataclasses.fields(cls)}
    unknown = sorted(set(data) - set(names))
    if unknown:
        raise ValueError(f"{cls.__name__}: unknown field(s) {unknown}")
    values = {k: tuple(v) if isinstance(v, list) else v for k, v in data.items()}
    return cls(**values)
