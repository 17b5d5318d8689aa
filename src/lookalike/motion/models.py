"""Motion models: transition ``F(dt)`` and process noise ``Q(dt)`` for any dimension, state ordered by derivative
(e.g. ``[x, y, vx, vy]``); ``q`` is the spectral density of the white-noise highest derivative."""

from __future__ import annotations

import math
from functools import lru_cache

import numpy as np


def _check(dim: int, dt: float) -> None:
    if dim < 1:
        raise ValueError(f"dim must be at least 1, got {dim}")
    if not (dt >= 0 and math.isfinite(dt)):
        raise ValueError(f"dt must be a finite non-negative number of seconds, got {dt}")


def _f1(order: int, dt: float) -> np.ndarray:
    n = order + 1
    f1 = np.zeros((n, n))
    for i in range(n):
        for j in range(i, n):
            f1[i, j] = dt ** (j - i) / math.factorial(j - i)
    return f1


def kinematic_transition(dim: int, order: int, dt: float) -> np.ndarray:
    """The cached, read-only ``F(dt)`` of a kinematic model of ``order`` (1: velocity, 2: acceleration)."""
    _check(dim, dt)
    return _transition(dim, order, float(dt))


@lru_cache(maxsize=256)
def _transition(dim: int, order: int, dt: float) -> np.ndarray:
    F = np.kron(_f1(order, dt), np.eye(dim))
    F.setflags(write=False)
    return F


@lru_cache(maxsize=256)
def _kinematic(dim: int, order: int, dt: float, q: float) -> tuple[np.ndarray, np.ndarray]:
    n = order + 1
    # Continuous white noise on the highest derivative, integrated exactly over dt.
    q1 = np.zeros((n, n))
    for i in range(n):
        for j in range(n):
            p = (n - 1 - i) + (n - 1 - j) + 1
            q1[i, j] = q * dt**p / (p * math.factorial(n - 1 - i) * math.factorial(n - 1 - j))
    F, Q = _transition(dim, order, dt), np.kron(q1, np.eye(dim))
    Q.setflags(write=False)
    return F, Q


def _model(dim: int, order: int, dt: float, q: float) -> tuple[np.ndarray, np.ndarray]:
    _check(dim, dt)
    F, Q = _kinematic(dim, order, float(dt), float(q))
    return F.copy(), Q.copy()


def constant_velocity(dim: int, dt: float, q: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
    """``(F, Q)`` for constant velocity in ``dim`` dimensions; state ``[p (dim), v (dim)]``."""
    return _model(dim, 1, dt, q)


def constant_acceleration(dim: int, dt: float, q: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
    """``(F, Q)`` for constant acceleration; state ``[p (dim), v (dim), a (dim)]``."""
    return _model(dim, 2, dt, q)
