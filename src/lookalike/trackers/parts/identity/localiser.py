"""Agent positions (observer frame, metres) from the detections an identifier assigns to each agent: both localisers
have ``update(time_s, measured (N, 2), weight (N,)) -> (N, 2)`` (NaN rows: not detected, or no position yet)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from lookalike.motion import chi2_gate, kalman
from lookalike.trackers.kernels.world import einsum, solve

LOCALISERS = ("lowpass", "kalman")
TRANSITIONS = 16  # distinct frame intervals whose Kalman transition is kept


class LowPassLocaliser:
    """The robot-identification paper's low-pass filter ``T_j ← α·L_k + (1 − α)·T_j`` (``α``: class probability)."""

    def __init__(self, n_agents: int) -> None:
        self.n_agents = n_agents
        self.reset()

    def reset(self) -> None:
        """Forget every position."""
        self._position = np.full((self.n_agents, 2), np.nan)

    def update(self, time_s: float, measured: np.ndarray, weight: np.ndarray) -> np.ndarray:
        """Filtered positions ``(N, 2)`` after this frame's assigned detections."""
        seen = np.isfinite(measured).all(axis=1)
        new = seen & np.isnan(self._position).any(axis=1)
        alpha = np.clip(weight, 0.0, 1.0)[:, None]
        blend = alpha * measured + (1 - alpha) * self._position
        position: np.ndarray = np.where(new[:, None], measured, np.where(seen[:, None], blend, self._position))
        self._position = position
        out: np.ndarray = position.copy()
        return out


@dataclass(frozen=True)
class KalmanLocaliserConfig:
    """Parameters of :class:`KalmanLocaliser` (metres, seconds); defaults chosen on tuning seeds
    (research/notes/robot-identification.md)."""

    accel_std: float = 1.4  # m/s², white acceleration of the velocity model
    velocity_decay_s: float = 0.6  # velocity relaxes to 0 with this time constant
    std0_m: float = 0.05  # measurement noise at distance 0
    std_per_m: float = 0.08  # growth of the measurement noise per metre of distance
    min_weight: float = 0.05  # class probabilities below this count as this
    weight_power: float = 1.0  # measurement variance divided by α ** weight_power
    ignore_below: float = 0.5  # assignments with α below this do not update the filter
    gate_probability: float = 0.9999
    max_rejects: int = 60  # frames of gated-out assignments before the filter restarts there
    max_coast_s: float = 5.0  # no position once an agent has had no detection this long

    def __post_init__(self) -> None:
        for name in ("accel_std", "velocity_decay_s", "std0_m", "min_weight"):
            if not getattr(self, name) > 0:
                raise ValueError(f"KalmanLocaliserConfig.{name} must be > 0, got {getattr(self, name)!r}")
        if self.std_per_m < 0 or not 0 < self.gate_probability < 1 or self.max_rejects < 1 or self.max_coast_s < 0:
            raise ValueError(f"KalmanLocaliserConfig: need std_per_m >= 0, 0 < gate_probability < 1, "
                             f"max_rejects >= 1, max_coast_s >= 0; got {self}")


_H = np.hstack([np.eye(2), np.zeros((2, 2))])
_EYE2 = np.eye(2)


class KalmanLocaliser:
    """Per-agent constant-velocity Kalman filters on ``[x, y, vx, vy]`` with decaying velocity, noise growing with
    distance and shrinking with ``α``, a chi-square gate with restarts, no position after ``max_coast_s`` unseen."""

    def __init__(self, n_agents: int, config: KalmanLocaliserConfig | None = None) -> None:
        self.n_agents = n_agents
        self.config = config or KalmanLocaliserConfig()
        self._gate = chi2_gate(2, self.config.gate_probability)
        self.reset()

    def reset(self) -> None:
        """Forget every agent's state."""
        n = self.n_agents
        self._mean = np.zeros((n, 4))
        self._cov = np.tile(np.eye(4), (n, 1, 1))
        self._started = np.zeros(n, dtype=bool)
        self._rejects = np.zeros(n, dtype=int)
        self._last_seen = np.full(n, -np.inf)
        self._time: float | None = None
        # ``F, Q`` of the last TRANSITIONS distinct ``dt`` (frame intervals repeat), in fixed storage (no growth)
        self._dts: list[float] = [math.nan] * TRANSITIONS
        self._fq = np.zeros((TRANSITIONS, 2, 4, 4))
        self._slot = 0

    def _transition(self, dt: float) -> tuple[np.ndarray, np.ndarray]:
        """``F, Q`` over ``dt`` seconds."""
        if dt in self._dts:
            k = self._dts.index(dt)
            return self._fq[k, 0], self._fq[k, 1]
        cfg = self.config
        decay = float(np.exp(-dt / cfg.velocity_decay_s))
        gain = cfg.velocity_decay_s * (1.0 - decay)  # ∫ velocity over dt
        F = np.eye(4)
        F[0, 2] = F[1, 3] = gain
        F[2, 2] = F[3, 3] = decay
        q = cfg.accel_std**2
        q1 = np.array([[dt**3 / 3, dt**2 / 2], [dt**2 / 2, dt]]) * q
        Q = np.zeros((4, 4))
        Q[np.ix_([0, 2], [0, 2])] = q1
        Q[np.ix_([1, 3], [1, 3])] = q1
        k, self._slot = self._slot, (self._slot + 1) % TRANSITIONS
        self._dts[k] = dt
        self._fq[k, 0], self._fq[k, 1] = F, Q
        return self._fq[k, 0], self._fq[k, 1]

    def update(self, time_s: float, measured: np.ndarray, weight: np.ndarray) -> np.ndarray:
        """Filtered positions ``(N, 2)`` after this frame's assigned detections."""
        cfg = self.config
        dt = 0.0 if self._time is None else max(time_s - self._time, 0.0)
        self._time = time_s
        if dt > 0:
            F, Q = self._transition(dt)
            self._mean, self._cov = kalman.predict(self._mean, self._cov, F, Q)
        weight = np.asarray(weight)
        seen = np.logical_and.reduce(np.isfinite(measured), axis=1) & (weight >= cfg.ignore_below)
        z = np.where(seen[:, None], measured, 0.0)
        std = (cfg.std0_m + cfg.std_per_m * np.hypot(z[:, 0], z[:, 1])) / np.minimum(
            np.maximum(weight, cfg.min_weight), 1.0) ** (cfg.weight_power / 2)
        R = (std**2)[:, None, None] * _EYE2
        start = seen & ~self._started
        self._started |= start
        live = (seen & ~start).nonzero()[0]
        every = len(live) == self.n_agents  # (every agent's filter updated: no copies of the rows)
        if len(live):
            m, P, zj, Rj = ((self._mean, self._cov, z, R) if every
                            else (self._mean[live], self._cov[live], z[live], R[live]))
            zhat, S = kalman.project(m, P, _H, Rj)
            d = zj - zhat
            d2 = einsum("ki,ki->k", d, solve(S, d[..., None])[..., 0])
            accept = d2 <= self._gate
            if accept.all():
                if every:
                    self._mean, self._cov = _corrected(m, P, zj, zhat, S)
                else:
                    self._mean[live], self._cov[live] = _corrected(m, P, zj, zhat, S)
                self._rejects[live] = 0
            else:
                restart = ~accept & (self._rejects[live] + 1 >= cfg.max_rejects)
                if accept.any():
                    mu, Pu = _corrected(m[accept], P[accept], zj[accept], zhat[accept], S[accept])
                    self._mean[live[accept]], self._cov[live[accept]] = mu, Pu
                start[live[restart]] = True
                self._rejects[live] = np.where(accept | restart, 0, self._rejects[live] + 1)
        for j in start.nonzero()[0]:  # (new filters, and those restarted)
            self._mean[j] = (z[j, 0], z[j, 1], 0.0, 0.0)
            self._cov[j] = np.diag([std[j] ** 2, std[j] ** 2, 0.5, 0.5])
        self._last_seen = np.where(seen, time_s, self._last_seen)
        fresh = self._started & (time_s - self._last_seen <= cfg.max_coast_s)
        return np.where(fresh[:, None], self._mean[:, :2], np.nan)


def _corrected(mean: np.ndarray, cov: np.ndarray, z: np.ndarray, z_hat: np.ndarray, S: np.ndarray
               ) -> tuple[np.ndarray, np.ndarray]:
    """``kalman.update(mean, cov, z, _H, R)`` given its projection ``z_hat, S``: the same arithmetic, with numpy's
    solve and einsum kernels called without their wrappers."""
    PHt_T = (cov @ _H.T).swapaxes(-1, -2)
    K = solve(S, PHt_T).swapaxes(-1, -2)
    return mean + einsum("kij,kj->ki", K, z - z_hat), cov - K @ PHt_T


def make_localiser(name: str, n_agents: int, config: KalmanLocaliserConfig | None = None
                   ) -> LowPassLocaliser | KalmanLocaliser:
    """Localiser ``name`` (``"lowpass"`` or ``"kalman"``) for ``n_agents`` agents."""
    if name == "lowpass":
        return LowPassLocaliser(n_agents)
    if name == "kalman":
        return KalmanLocaliser(n_agents, config)
    raise ValueError(f"localiser: unknown name {name!r}; known: {', '.join(LOCALISERS)}")
