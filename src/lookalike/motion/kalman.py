"""A stateless linear Kalman filter, vectorised over tracks: ``mean (k, n)``, ``cov (k, n, n)``, ``z (k, m)``,
``H (m, n)``; ``F``, ``Q``, ``R`` shared or per track. Inputs are never mutated."""

from __future__ import annotations

import numpy as np


def predict(mean: np.ndarray, cov: np.ndarray, F: np.ndarray, Q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Time update: ``x' = F x``, ``P' = F P Fᵀ + Q``."""
    mean_p = np.einsum("...ij,kj->ki", F, mean) if F.ndim == 3 else mean @ F.T
    cov_p = F @ cov @ np.swapaxes(F, -1, -2) + Q
    return mean_p, cov_p


def project(mean: np.ndarray, cov: np.ndarray, H: np.ndarray, R: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Measurement-space prediction: ``ẑ = H x`` ``(k, m)`` and innovation covariance ``S = H P Hᵀ + R``."""
    return mean @ H.T, H @ cov @ H.T + R


def update(mean: np.ndarray, cov: np.ndarray, z: np.ndarray, H: np.ndarray, R: np.ndarray
           ) -> tuple[np.ndarray, np.ndarray]:
    """Measurement update with ``z (k, m)``: the posterior ``(mean, cov)``, ``P' = (I - K H) P``."""
    z_hat, S = project(mean, cov, H, R)
    PHt = cov @ H.T  # (k, n, m)
    # K = PHt S^-1  <=>  S K^T = PHt^T (S symmetric)
    K = np.swapaxes(np.linalg.solve(S, np.swapaxes(PHt, -1, -2)), -1, -2)
    innovation = z - z_hat
    mean_u = mean + np.einsum("kij,kj->ki", K, innovation)
    cov_u = cov - K @ np.swapaxes(PHt, -1, -2)
    return mean_u, cov_u


def gating_distance(mean: np.ndarray, cov: np.ndarray, z: np.ndarray, H: np.ndarray, R: np.ndarray) -> np.ndarray:
    """Squared Mahalanobis distance of every measurement ``z (d, m)`` to every track: ``(k, d)``."""
    z_hat, S = project(mean, cov, H, R)
    L = np.linalg.cholesky(S)  # (k, m, m)
    diff = z[None, :, :] - z_hat[:, None, :]  # (k, d, m)
    # Solve L y = diff^T for each track.
    y = np.linalg.solve(L, np.swapaxes(diff, -1, -2))  # (k, m, d)
    out: np.ndarray = np.sum(y * y, axis=1)
    return out
