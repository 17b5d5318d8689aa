"""State spaces: one per track parametrisation, each with box↔state converters, ``F``, ``Q``, ``H``/``R`` and ``P0``;
batched over tracks (``mean (k, n)``, ``cov (k, n, n)``) and stateless. Steps are nominal frame intervals, or seconds
for ``WorldCA``."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from lookalike.geometry.boxes import xywh_to_cxcywh
from lookalike.motion import kalman
from lookalike.motion.models import constant_acceleration, constant_velocity, kinematic_transition


def diagonal(values: np.ndarray) -> np.ndarray:
    """``(k, m, m)`` diagonal matrices from rows ``(k, m)``."""
    out = np.zeros(values.shape + (values.shape[1],))
    idx = np.arange(values.shape[1])
    out[:, idx, idx] = values
    return out


def _observe_first(n_measured: int, n_state: int) -> np.ndarray:
    return np.hstack([np.eye(n_measured), np.zeros((n_measured, n_state - n_measured))])


def xywh_to_xyah(xywh: np.ndarray) -> np.ndarray:
    """``(n, 4)`` boxes to ``[centre x, centre y, aspect w/h, height]``."""
    h = np.maximum(xywh[:, 3], 1e-6)
    return np.column_stack([xywh[:, 0] + xywh[:, 2] / 2, xywh[:, 1] + xywh[:, 3] / 2, xywh[:, 2] / h, xywh[:, 3]])


def xyah_to_xywh(xyah: np.ndarray) -> np.ndarray:
    """Inverse of :func:`xywh_to_xyah`."""
    w = xyah[:, 2] * xyah[:, 3]
    return np.column_stack([xyah[:, 0] - w / 2, xyah[:, 1] - xyah[:, 3] / 2, w, xyah[:, 3]])


def cxcywh_to_xywh(cxcywh: np.ndarray) -> np.ndarray:
    """``(n, 4)`` centre/size boxes to left/top/width/height, sizes floored at 1e-3 pixels."""
    out = np.array(cxcywh, dtype=float).reshape(-1, 4)
    size = out[:, 2:]
    np.maximum(size, 1e-3, out=size)
    out[:, :2] -= size / 2
    return out


def _require_noises(space: object, low_open: bool = True) -> None:
    """``ValueError`` naming the first of ``space``'s numbers (its dataclass fields) that is not finite and > 0 (``>=
    0`` without ``low_open``): a zero or NaN noise makes every state NaN."""
    for name, value in vars(space).items():
        if not (math.isfinite(value) and (value > 0 if low_open else value >= 0)):
            bound = "> 0" if low_open else ">= 0"
            raise ValueError(f"{type(space).__name__}.{name} must be a finite number {bound}, got {value}")


_P, _V = np.arange(4), np.arange(4, 8)  # the value and velocity rows of an 8-number box state


def _blocks(cov: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """``(k, 4)`` strided views of ``cov (k, 8, 8)``'s value/value, value/velocity, velocity/value and
    velocity/velocity diagonals (writing them writes ``cov`` when it is C-contiguous)."""
    flat = cov.reshape(len(cov), 64)
    return flat[:, 0:28:9], flat[:, 4:32:9], flat[:, 32:60:9], flat[:, 36:64:9]


@dataclass(frozen=True)
class BoxCXCYWH:
    """``[cx, cy, w, h, vx, vy, vw, vh]`` (pixels, pixels/frame) with noise proportional to the box
    size: ``pos_noise``·[w, h] for positions and measurements, ``vel_noise``·[w, h] for velocities."""

    pos_noise: float
    vel_noise: float
    H = _observe_first(4, 8)

    def __post_init__(self) -> None:
        _require_noises(self)

    @staticmethod
    def measure(xywh: np.ndarray) -> np.ndarray:
        return xywh_to_cxcywh(xywh)

    @staticmethod
    def box(mean: np.ndarray) -> np.ndarray:
        return cxcywh_to_xywh(mean[:, :4])

    def R(self, size: np.ndarray) -> np.ndarray:
        """``(k, 4, 4)`` measurement covariances for box sizes ``(k, 2)``."""
        std = self.pos_noise * np.hstack([size, size])
        R: np.ndarray = np.einsum("ki,ij->kij", std**2, np.eye(4))
        return R

    def initial(self, z: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        n = len(z)
        size = np.maximum(z[:, 2:4], 1.0)
        p, v = self.pos_noise, self.vel_noise
        std = np.hstack([2 * p * size, 2 * p * size, 10 * v * size, 10 * v * size])
        return np.hstack([z, np.zeros((n, 4))]), np.einsum("ki,ij->kij", std**2, np.eye(8))

    def predict(self, mean: np.ndarray, cov: np.ndarray, steps: float) -> tuple[np.ndarray, np.ndarray]:
        """``F x`` and ``F P Fᵀ + Q`` on the 2×2 (value, velocity) blocks of each box number."""
        size = np.maximum(mean[:, 2:4], 1.0)
        sq = size * size
        var = np.concatenate((sq, sq), axis=1)  # (k, 4) for [cx, cy, w, h]
        p11, p12, p21, p22 = _blocks(cov)
        if steps == 1.0:  # x * 1.0 == x exactly: the same numbers without the multiplications by steps
            mean[:, 6:8][mean[:, 2:4] + mean[:, 6:8] <= 1.0] = 0.0  # sizes stay > 1
            mean_p = mean.copy()
            mean_p[:, :4] += mean[:, 4:]
            a = p12 + p22
            v11 = p11 + p21 + a
            v21 = p21 + p22
        else:
            var *= max(steps, 0.0)
            mean[:, 6:8][mean[:, 2:4] + mean[:, 6:8] * steps <= 1.0] = 0.0
            mean_p = mean.copy()
            mean_p[:, :4] += steps * mean[:, 4:]
            a = p12 + steps * p22
            v11 = p11 + steps * p21 + steps * a
            v21 = p21 + steps * p22
        cov_p = np.array(cov, order="C")
        q11, q12, q21, q22 = _blocks(cov_p)
        q11[...] = v11 + self.pos_noise**2 * var
        q21[...] = v21
        q22[...] = p22 + self.vel_noise**2 * var
        q12[...] = a
        return mean_p, cov_p

    def update(self, mean: np.ndarray, cov: np.ndarray, z: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Kalman update with measurements ``z (k, 4)`` (noise :meth:`R` of their sizes) on the 2×2 blocks."""
        std = self.pos_noise * np.concatenate((z[:, 2:4], z[:, 2:4]), axis=1)
        p11, p12, p21, p22 = _blocks(cov)
        s = p11 + std * std
        k1, k2 = p11 / s, p21 / s
        innovation = z - mean[:, :4]
        mean_u = mean.copy()
        mean_u[:, :4] += k1 * innovation
        mean_u[:, 4:] += k2 * innovation
        cov_u = np.array(cov, order="C")
        u11, u12, u21, u22 = _blocks(cov_u)
        u11[...] = p11 - k1 * p11
        u12[...] = p12 - k1 * p21
        u21[...] = p21 - k2 * p11
        u22[...] = p22 - k2 * p21
        return mean_u, cov_u

    # Column form: a table ``(24, k)``, a column per track: rows 0-7 the mean, then the four 2×2-block
    # diagonals of the covariance, p11 (8-11), p12 (12-15), p21 (16-19), p22 (20-23); the numbers are
    # those of the full-covariance methods above, bit for bit.

    @staticmethod
    def measure_columns(xywh: np.ndarray) -> np.ndarray:
        """:meth:`measure`'s numbers on columns: ``(4, n)`` cx, cy, w, h of boxes given as columns ``xywh (4, n)``."""
        z = np.empty(xywh.shape)
        np.add(xywh[0:2], xywh[2:4] / 2.0, out=z[0:2])
        z[2:4] = xywh[2:4]
        return z

    @staticmethod
    def box_columns(columns: np.ndarray, out: np.ndarray) -> None:
        """:meth:`box`'s numbers on columns: rows 0-3 (cx, cy, w, h) of ``columns`` written into ``out (4, m)`` as
        left, top, width, height, sizes floored at 1e-3 pixels."""
        size = np.maximum(columns[2:4], 1e-3, out=out[2:4])
        np.subtract(columns[0:2], size / 2, out=out[0:2])

    def initial_rows(self, z: np.ndarray) -> np.ndarray:
        """New tracks at measurements ``z (n, 4)`` as rows ``(n, 24)`` of the column table (its transpose)."""
        n = len(z)
        size = np.maximum(z[:, 2:4], 1.0)
        p, v = self.pos_noise, self.vel_noise
        rows = np.zeros((n, 24))
        rows[:, :4] = z
        rows[:, 8:10] = rows[:, 10:12] = (2 * p * size) ** 2
        rows[:, 20:22] = rows[:, 22:24] = (10 * v * size) ** 2
        return rows

    def predict_columns(self, columns: np.ndarray, steps: float) -> None:
        """:meth:`predict` on a column table ``(24, k)``, in place."""
        x = columns
        size = np.maximum(x[2:4], 1.0)
        var = size * size  # the squared sizes w², h² (the variances' unit)
        if steps == 1.0:  # x * 1.0 == x exactly: the same numbers without the multiplications by steps
            x[6:8][x[2:4] + x[6:8] <= 1.0] = 0.0  # sizes stay > 1
            x[0:4] += x[4:8]
            x[8:12] += x[16:20]  # p11 + p21
            x[12:16] += x[20:24]  # a = p12 + p22
            x[16:20] += x[20:24]  # p21 + p22
            x[8:12] += x[12:16]  # + a
        else:
            var *= max(steps, 0.0)
            x[6:8][x[2:4] + x[6:8] * steps <= 1.0] = 0.0
            x[0:4] += steps * x[4:8]
            x[8:12] += steps * x[16:20]
            p22 = steps * x[20:24]
            x[12:16] += p22
            x[16:20] += p22
            x[8:12] += steps * x[12:16]
        q = self.pos_noise**2 * var
        x[8:10] += q
        x[10:12] += q
        q = self.vel_noise**2 * var
        x[20:22] += q
        x[22:24] += q

    def innovation_columns(self, columns: np.ndarray, z: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Innovations ``(4, m)`` of measurement columns ``z (4, m)`` and their (diagonal) variances ``(4, m)``."""
        std = self.pos_noise * z[2:4]
        r = std * std
        s = np.empty(z.shape)
        np.add(columns[8:10], r, out=s[0:2])
        np.add(columns[10:12], r, out=s[2:4])
        return z - columns[0:4], s

    @staticmethod
    def correct_columns(columns: np.ndarray, innovation: np.ndarray, s: np.ndarray) -> None:
        """The Kalman update of ``columns (24, m)``, in place, from :meth:`innovation_columns`."""
        m = columns.shape[1]
        x = columns
        gain = np.empty((2, 4, m))
        np.divide(x[8:12], s, out=gain[0])  # p11 / s
        np.divide(x[16:20], s, out=gain[1])  # p21 / s
        x[0:8] += (gain * innovation).reshape(8, m)
        blocks = x[8:24].reshape(2, 2, 4, m)  # [[p11, p12], [p21, p22]]
        blocks -= gain[:, None] * blocks[None, :, 0]  # - gain ⊗ [p11, p21]


@dataclass(frozen=True)
class BoxXYAH:
    """Deep SORT's ``[x, y, a, h]`` (centre pixels, aspect w/h, height pixels) plus velocities, noise
    proportional to the height (``position_std_frac``, ``velocity_std_frac``) and ``aspect_std``."""

    position_std_frac: float
    velocity_std_frac: float
    aspect_std: float
    H = _observe_first(4, 8)

    def __post_init__(self) -> None:
        _require_noises(self)

    @staticmethod
    def measure(xywh: np.ndarray) -> np.ndarray:
        return xywh_to_xyah(xywh)

    @staticmethod
    def box(mean: np.ndarray) -> np.ndarray:
        return xyah_to_xywh(mean[:, :4])

    def R(self, height: np.ndarray) -> np.ndarray:
        pos = self.position_std_frac * height
        a = np.full_like(height, self.aspect_std)
        return diagonal(np.column_stack([pos, pos, a * 10, pos]) ** 2)

    def Q(self, height: np.ndarray, steps: float) -> np.ndarray:
        pos = self.position_std_frac * height
        vel = self.velocity_std_frac * height
        a = np.full_like(height, self.aspect_std)
        return diagonal(np.column_stack([pos, pos, a, pos, vel, vel, a * 1e-1, vel]) ** 2 * steps)

    def initial(self, z: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        n = len(z)
        h = z[:, 3]
        p, v = 2 * self.position_std_frac * h, 10 * self.velocity_std_frac * h
        std = np.column_stack([p, p, np.full(n, 1e-2), p, v, v, np.full(n, 1e-5), v])
        return np.hstack([z, np.zeros((n, 4))]), diagonal(std**2)

    def predict(self, mean: np.ndarray, cov: np.ndarray, steps: float) -> tuple[np.ndarray, np.ndarray]:
        mean, cov = kalman.predict(mean, cov, kinematic_transition(4, 1, steps), self.Q(mean[:, 3], steps))
        mean[:, 3] = np.maximum(mean[:, 3], 1.0)
        return mean, cov


@dataclass(frozen=True)
class CentreCV:
    """DiverSORT's centre-only ``[x, y, vx, vy]`` (pixels, pixels/frame); box size from the latest detection.
    Noises ``accel_std_frac`` and ``position_std_frac`` are fractions of the box height."""

    position_std_frac: float
    accel_std_frac: float
    H = _observe_first(2, 4)

    def __post_init__(self) -> None:
        _require_noises(self)

    @staticmethod
    def measure(xywh: np.ndarray) -> np.ndarray:
        return xywh[:, :2] + xywh[:, 2:] / 2

    @staticmethod
    def box(mean: np.ndarray, xywh: np.ndarray) -> np.ndarray:
        """Boxes centred on the state with the sizes of ``xywh``."""
        w, h = xywh[:, 2], xywh[:, 3]
        return np.column_stack([mean[:, 0] - w / 2, mean[:, 1] - h / 2, w, h])

    def R(self, height: np.ndarray) -> np.ndarray:
        R = np.zeros((len(height), 2, 2))
        R[:, [0, 1], [0, 1]] = ((self.position_std_frac * np.maximum(height, 1.0)) ** 2)[:, None]
        return R

    def initial(self, centre: np.ndarray, height: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        n = len(centre)
        std = self.position_std_frac * height
        cov = np.zeros((n, 4, 4))
        cov[:, [0, 1], [0, 1]] = (std**2)[:, None]
        cov[:, [2, 3], [2, 3]] = ((0.5 * height) ** 2)[:, None]  # unknown speed: half a height per frame
        return np.hstack([centre, np.zeros((n, 2))]), cov

    def predict(self, mean: np.ndarray, cov: np.ndarray, steps: float,
                height: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        F, Q = constant_velocity(2, steps, 1.0)
        accel = self.accel_std_frac * height
        return kalman.predict(mean, cov, F, Q[None] * (accel**2)[:, None, None])


@dataclass(frozen=True)
class WorldCA:
    """World-frame constant acceleration ``[x, y, vx, vy, ax, ay]`` (metres, seconds) with white jerk
    ``q_jerk`` (m²/s⁵) and position noise ``meas_std0_m + meas_std_per_m · distance``."""

    q_jerk: float
    meas_std0_m: float
    meas_std_per_m: float
    init_velocity_std: float
    init_accel_std: float
    H = _observe_first(2, 6)

    def __post_init__(self) -> None:
        _require_noises(self, low_open=False)

    def R(self, position: np.ndarray) -> np.ndarray:
        """Measurement covariances ``(k, 2, 2)`` for positions ``(k, 2)`` in metres."""
        std = self.meas_std0_m + self.meas_std_per_m * np.hypot(position[:, 0], position[:, 1])
        R: np.ndarray = (std**2)[:, None, None] * np.eye(2)[None]
        return R

    def initial(self, position: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        n = len(position)
        mean = np.zeros((n, 6))
        mean[:, :2] = position
        cov = np.zeros((n, 6, 6))
        cov[:, :2, :2] = self.R(position)
        cov[:, 2, 2] = cov[:, 3, 3] = self.init_velocity_std**2
        cov[:, 4, 4] = cov[:, 5, 5] = self.init_accel_std**2
        return mean, cov

    def predict(self, mean: np.ndarray, cov: np.ndarray, dt: float) -> tuple[np.ndarray, np.ndarray]:
        F, Q = constant_acceleration(2, dt, self.q_jerk)
        return kalman.predict(mean, cov, F, Q)
