"""The observer's perception model (visibility, occlusion, misses, noise, visual heading), vectorised over leading
axes; positions in the observer frame (x forward, y left, metres)."""

from __future__ import annotations

import numpy as np

from lookalike.geometry.angles import wrap_angle
from lookalike.sim.robots_config import ObserverConfig, SensorConfig


def in_view(position_obs: np.ndarray, cfg: ObserverConfig) -> np.ndarray:
    """Whether each position ``(..., 2)`` lies inside the camera's field of view and range."""
    d = np.hypot(position_obs[..., 0], position_obs[..., 1])
    bearing = np.arctan2(position_obs[..., 1], position_obs[..., 0])
    return (np.abs(bearing) <= cfg.fov_rad / 2) & (d >= cfg.min_range_m) & (d <= cfg.max_range_m)


def occlusion_fraction(position_obs: np.ndarray, radius_m: float) -> np.ndarray:
    """Fraction ``(..., N)`` of each robot's angular width hidden by nearer robots ``(..., N, 2)``."""
    d = np.hypot(position_obs[..., 0], position_obs[..., 1])
    bearing = np.arctan2(position_obs[..., 1], position_obs[..., 0])
    half = np.arcsin(np.clip(radius_m / np.maximum(d, 1e-9), 0.0, 1.0))
    sep = np.abs(wrap_angle(bearing[..., :, None] - bearing[..., None, :]))
    overlap = (half[..., :, None] + half[..., None, :] - sep) / (2 * half[..., :, None])
    nearer = (d[..., None, :] < d[..., :, None]) & (position_obs[..., None, :, 0] > 0)
    overlap = np.where(nearer, np.clip(overlap, 0.0, 1.0), 0.0)
    return overlap.max(axis=-1) if overlap.shape[-1] else np.zeros(d.shape)


def detection_probability(distance_m: np.ndarray, occlusion: np.ndarray, sensor: SensorConfig,
                          observer: ObserverConfig) -> np.ndarray:
    """Probability that a robot in view at ``distance_m`` with ``occlusion`` (0..1) is detected."""
    near, far = sensor.best_range_m
    d = np.asarray(distance_m, dtype=float)
    below = np.clip((near - d) / max(near - observer.min_range_m, 1e-9), 0.0, 1.0)
    above = np.clip((d - far) / max(observer.max_range_m - far, 1e-9), 0.0, 1.0)
    p = (sensor.p_detect + below * (sensor.p_detect_near - sensor.p_detect)
         + above * (sensor.p_detect_far - sensor.p_detect))
    return p * np.clip(1.0 - np.asarray(occlusion) / sensor.occlusion_hide, 0.0, 1.0)


def visual_heading(true_heading: np.ndarray, bearing_abs: np.ndarray, sensor: SensorConfig,
                   seeds: np.random.SeedSequence) -> np.ndarray:
    """Classifier-like absolute headings: flipped, noisy and snapped to classes as :class:`SensorConfig` says (the
    flips and the noise drawn from two streams of ``seeds``, in the order of the leading axes)."""
    rel = true_heading - bearing_abs
    r_flip, r_noise = (np.random.default_rng(s) for s in seeds.spawn(2))
    flip = r_flip.random(rel.shape) < sensor.heading_flip_prob
    rel = rel + np.where(flip, np.pi, 0.0) + r_noise.normal(0.0, sensor.heading_noise_rad, rel.shape)
    if sensor.heading_classes > 0:
        width = 2 * np.pi / sensor.heading_classes
        rel = np.round(rel / width) * width
    return np.asarray(wrap_angle(rel + bearing_abs))


def position_noise_std(distance_m: np.ndarray, sensor: SensorConfig) -> np.ndarray:
    """Standard deviations ``(..., 2)`` of the position noise along observer x and y, metres."""
    d = np.asarray(distance_m, dtype=float)
    return np.stack([sensor.std_x0_m + sensor.std_x_per_m * d, sensor.std_y0_m + sensor.std_y_per_m * d], -1)
