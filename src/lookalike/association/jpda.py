"""Joint probabilistic data association: exact marginal association probabilities, per independent cluster by
enumeration (at most ``max_events`` events) or by a dynamic programme over detection subsets."""

from __future__ import annotations

import numpy as np

MAX_DP_DETECTIONS = 20


def _check(likelihood: np.ndarray, miss: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    L = np.asarray(likelihood, dtype=float)
    q = np.asarray(miss, dtype=float)
    if L.ndim != 2:
        raise ValueError(f"likelihood: expected a (tracks, detections) matrix, got shape {L.shape}")
    if q.shape != (L.shape[0],):
        raise ValueError(f"miss: expected shape ({L.shape[0]},), got {q.shape}")
    if not (np.isfinite(L).all() and (L >= 0).all()):
        raise ValueError("likelihood: entries must be finite and >= 0 (0 outside the gate)")
    if not (np.isfinite(q).all() and (q >= 0).all()):
        raise ValueError("miss: entries must be finite and >= 0")
    return L, q


def jpda_marginals(
    likelihood: np.ndarray, miss: np.ndarray, max_events: int = 5000
) -> tuple[np.ndarray, np.ndarray]:
    """Marginals ``beta (k, m)`` (track i took detection j) and ``beta_miss (k,)`` of the non-negative hypothesis
    weights ``likelihood (k, m)`` and ``miss (k,)``; rows sum to 1 (all-zero tracks: ``beta_miss = 1``)."""
    L, q = _check(likelihood, miss)
    k, m = L.shape
    beta = np.zeros((k, m))
    beta_miss = np.ones(k)
    if k == 0:
        return beta, beta_miss
    # Scale each track's weights (does not change its marginals) to avoid under/overflow.
    scale = np.maximum(q, L.max(axis=1, initial=0.0))
    scale[scale == 0] = 1.0
    L, q = L / scale[:, None], q / scale
    gated = L > 0
    adjacency = np.zeros((k + m, k + m), dtype=bool)
    adjacency[:k, k:] = gated
    from scipy.sparse import csr_matrix  # imported on first use: scipy.sparse is slow to import
    from scipy.sparse.csgraph import connected_components

    n_comp, comp = connected_components(csr_matrix(adjacency), directed=False)
    for c in range(n_comp):
        tracks = np.flatnonzero(comp[:k] == c)
        if not len(tracks):
            continue
        dets = np.flatnonzero(comp[k:] == c)
        sub_L, sub_q = L[np.ix_(tracks, dets)], q[tracks]
        n_events = float(np.prod((sub_L > 0).sum(axis=1) + 1.0))
        if n_events <= max_events:
            b, b0 = _enumerate(sub_L, sub_q)
        elif len(dets) <= MAX_DP_DETECTIONS:
            b, b0 = _subset_dp(sub_L, sub_q)
        else:
            raise ValueError(
                f"jpda_marginals: a cluster of {len(tracks)} tracks and {len(dets)} detections exceeds the exact "
                f"methods' limits (max_events={max_events}, {MAX_DP_DETECTIONS} detections); tighten the gate"
            )
        beta[np.ix_(tracks, dets)] = b
        beta_miss[tracks] = b0
    return beta, beta_miss


def _enumerate(L: np.ndarray, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Explicit enumeration of the feasible joint events of one cluster."""
    k, m = L.shape
    options = [np.concatenate([[-1], np.flatnonzero(L[i] > 0)]) for i in range(k)]
    grids = np.meshgrid(*options, indexing="ij")
    events = np.stack([g.ravel() for g in grids], axis=1)  # (E, k), -1 = missed
    s = np.sort(events, axis=1)
    clash = ((s[:, 1:] == s[:, :-1]) & (s[:, 1:] >= 0)).any(axis=1)
    events = events[~clash]
    W = np.hstack([L, q[:, None]])  # column m = missed
    cols = np.where(events < 0, m, events)
    weight = np.prod(W[np.arange(k)[None, :], cols], axis=1)
    total = weight.sum()
    if total <= 0:
        return np.zeros((k, m)), np.ones(k)
    out = np.zeros((k, m + 1))
    for i in range(k):
        out[i] = np.bincount(cols[:, i], weights=weight, minlength=m + 1)
    out /= total
    return out[:, :m], out[:, m]


def _subset_dp(L: np.ndarray, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Exact marginals by forward/backward sums over subsets of used detections."""
    k, m = L.shape
    n = 1 << m
    masks = np.arange(n)
    free = [masks[(masks >> j) & 1 == 0] for j in range(m)]
    forward = np.zeros((k + 1, n))
    forward[0, 0] = 1.0
    for i in range(k):
        f = forward[i] * q[i]
        for j in range(m):
            if L[i, j] > 0:
                f[free[j] | (1 << j)] += forward[i, free[j]] * L[i, j]
        forward[i + 1] = f
    backward = np.zeros((k + 1, n))
    backward[k] = 1.0  # g[i][mask]: weight of tracks i.. using detections outside mask
    for i in range(k - 1, -1, -1):
        g = backward[i + 1] * q[i]
        for j in range(m):
            if L[i, j] > 0:
                g[free[j]] += L[i, j] * backward[i + 1, free[j] | (1 << j)]
        backward[i] = g
    total = backward[0, 0]
    if total <= 0:
        return np.zeros((k, m)), np.ones(k)
    beta = np.zeros((k, m))
    beta_miss = np.zeros(k)
    for i in range(k):
        beta_miss[i] = (forward[i] * q[i] * backward[i + 1]).sum() / total
        for j in range(m):
            if L[i, j] > 0:
                beta[i, j] = (forward[i, free[j]] * L[i, j] * backward[i + 1, free[j] | (1 << j)]).sum() / total
    return beta, beta_miss
