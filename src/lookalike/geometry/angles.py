"""Angle arithmetic in radians: wrapping to (-π, π], circular differences and means."""

from __future__ import annotations

import numpy as np


def wrap_angle(angle_rad: np.ndarray | float) -> np.ndarray | float:
    """Wrap angles to the interval (-π, π]."""
    a = np.asarray(angle_rad, dtype=float)
    wrapped = np.pi - np.mod(np.pi - a, 2.0 * np.pi)
    return float(wrapped) if wrapped.ndim == 0 else wrapped


def angle_diff(a_rad: np.ndarray | float, b_rad: np.ndarray | float) -> np.ndarray | float:
    """Signed circular difference ``a - b`` wrapped to (-π, π] (broadcasts)."""
    return wrap_angle(np.subtract(a_rad, b_rad))


def circular_mean(
    angles_rad: np.ndarray, weights: np.ndarray | None = None, axis: int | None = None
) -> np.ndarray | float:
    """Mean direction of angles (optionally weighted) along ``axis``, in (-π, π]."""
    a = np.asarray(angles_rad, dtype=float)
    w = np.ones_like(a) if weights is None else np.asarray(weights, dtype=float)
    s = np.sum(w * np.sin(a), axis=axis)
    c = np.sum(w * np.cos(a), axis=axis)
    return wrap_angle(np.arctan2(s, c))
