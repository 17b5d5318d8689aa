"""The numba kernels of :mod:`lookalike.trackers.kernels.world`: the numpy path's floating-point operations value by
value in the same order (``fastmath`` off), so bit for bit the same results. Seconds, radians, metres (world frame)."""

from __future__ import annotations

import math

import numpy as np

from lookalike._compiled import exact_jit

_jit = exact_jit()


@_jit
def _maximum(x: float, y: float) -> float:
    """``np.maximum`` of two floats (NaN wins)."""
    return x if (x >= y or x != x) else y


@_jit
def _minimum(x: float, y: float) -> float:
    """``np.minimum`` of two floats (NaN wins)."""
    return x if (x <= y or x != x) else y


@_jit
def _wrap(x: float) -> float:
    """``pi - np.mod(pi - x, 2 pi)``: numpy's float remainder (``fmod``, moved to the divisor's sign)."""
    two_pi = 2.0 * np.pi
    m: float = np.fmod(np.pi - x, two_pi)
    if m != 0.0:
        if m < 0.0:  # (NaN: no change, as in numpy)
            m += two_pi
    else:
        m = 0.0
    return np.pi - m


@_jit
def _agent_headings(th: np.ndarray, q: np.ndarray, q_count: np.ndarray, max_turn_rate: float,
                    max_extrapolation_s: float) -> np.ndarray:
    """``BeaconIdentifier._headings``: the agents' headings ``(W, N)`` at the times ``q (W,)`` (``q_count``: NaN as
    +inf) from the report histories ``th (2, N, r)`` (send times, headings; NaN padded at the front)."""
    n, r = th.shape[1], th.shape[2]
    n_times = q.shape[0]
    agent = np.full((n_times, n), np.nan)
    for a in range(n):
        k = 0
        for j in range(r):
            if th[0, a, j] == th[0, a, j]:
                k += 1
        if k == 0:
            continue
        first = r - k
        t_last, h_last, t_prev = th[0, a, r - 1], th[1, a, r - 1], th[0, a, r - 2]
        rate = 0.0
        if t_last > t_prev:  # (turning: two reports or more)
            turn = _wrap(h_last - th[1, a, r - 2]) / (t_last - t_prev)
            rate = _minimum(_maximum(turn, -max_turn_rate), max_turn_rate)
        for w in range(n_times):
            at_or_before = 0
            for j in range(r):
                if th[0, a, j] <= q_count[w]:
                    at_or_before += 1
            if at_or_before >= k:
                agent[w, a] = h_last + rate * _minimum(_maximum(q[w] - t_last, 0.0), max_extrapolation_s)
            elif at_or_before == 0:
                agent[w, a] = th[1, a, first]
            else:
                before = first + at_or_before - 1
                t_before, h_before = th[0, a, before], th[1, a, before]
                span = th[0, a, before + 1] - t_before
                frac = (q[w] - t_before) / span if span > 0 else 0.0
                agent[w, a] = h_before + frac * _wrap(th[1, a, before + 1] - h_before)
    return agent


@_jit
def window_costs(th: np.ndarray, q: np.ndarray, q_count: np.ndarray, samples: np.ndarray, max_turn_rate: float,
                 max_extrapolation_s: float, out: np.ndarray) -> None:
    """``BeaconIdentifier._costs`` into ``out (k, N)``: the mean ``(1 - cos)/2`` of each sample row ``samples (k, W)``
    (track headings; NaN: none) against each agent's heading at the window times, over the finite terms (else inf)."""
    agent = _agent_headings(th, q, q_count, max_turn_rate, max_extrapolation_s)
    n_times, n = agent.shape
    for row in range(samples.shape[0]):
        for a in range(n):
            total = 0.0
            count = 0
            for w in range(n_times):
                d = samples[row, w] - agent[w, a]
                if d != d:  # (no sample or no heading: a NaN term, not counted)
                    continue
                c = (1.0 - math.cos(d)) * 0.5
                if math.isfinite(c):
                    count += 1
                    total = c if count == 1 else total + c
            out[row, a] = total / count if count > 0 else np.inf


@_jit
def identity_rows_work(th: np.ndarray, q: np.ndarray, q_count: np.ndarray, win: np.ndarray, current: np.ndarray,
                       rows: np.ndarray, max_turn_rate: float, max_extrapolation_s: float, hysteresis: float,
                       max_cost: float) -> tuple[int, np.ndarray, np.ndarray, np.ndarray]:
    """``BeaconIdentifier.assign_arrays`` up to the solver for the sample rows ``win[rows]`` held by agents
    ``current[rows]`` (-1: none). Returns ``(decision, cost, work, allowed)`` as ``world_kernels.pairs`` decides (0
    none, 1 disjoint, 2 solve)."""
    k, w, n = rows.shape[0], win.shape[1], th.shape[1]
    samples = np.empty((k, w))
    for i in range(k):
        for j in range(w):
            samples[i, j] = win[rows[i], j]
    cost = np.empty((k, n))
    window_costs(th, q, q_count, samples, max_turn_rate, max_extrapolation_s, cost)
    work = cost.copy()
    for i in range(k):
        a = current[rows[i]]
        if a >= 0:
            work[i, a] = _maximum(work[i, a] - hysteresis, 0.0)
    allowed, found, disjoint = _allowed(work, max_cost)
    for i in range(k):
        for j in range(n):
            if not allowed[i, j]:
                work[i, j] = max_cost + 1e-6
    return (0 if not found else 1 if disjoint else 2), cost, work, allowed


@_jit
def identity_results(pair_rows: np.ndarray, pair_agents: np.ndarray, cost: np.ndarray, current: np.ndarray,
                     rows: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``BeaconIdentifier.assign_arrays``'s agent per row (-1: none) and probability ``1 - cost`` (NaN: none) from the
    assigned pairs; each row's agent kept in ``current[rows]`` (a repeated row keeps the last)."""
    k = rows.shape[0]
    agent = np.full(k, -1, np.int64)
    prob = np.full(k, np.nan)
    for p in range(pair_rows.shape[0]):
        i, a = pair_rows[p], pair_agents[p]
        agent[i] = a
        prob[i] = 1.0 - cost[i, a]
    for i in range(k):
        current[rows[i]] = agent[i]
    return agent, prob


@_jit
def gate_work(y: np.ndarray, gate: float) -> tuple[int, np.ndarray, np.ndarray]:
    """The world trackers' association up to the solver from the whitened innovations ``y (k, 2, d)``: squared
    Mahalanobis distances, the pairs inside ``gate`` and ``solver.solve_allowed``'s matrix without a cost limit.
    Returns ``(decision, work, allowed)`` as ``world_kernels.pairs`` decides (0 none, 1 disjoint, 2 solve)."""
    k, d = y.shape[0], y.shape[2]
    work = np.empty((k, d))
    for i in range(k):
        for j in range(d):
            a, b = y[i, 0, j], y[i, 1, j]
            work[i, j] = a * a + b * b
    return _gate_decision(work, gate)


@_jit
def _times_inverse(x: float, pivot: float, divide: bool) -> float:
    """``x / pivot`` when ``divide``, else ``x`` times the reciprocal of ``pivot`` (LAPACK's two roundings)."""
    return x / pivot if divide else x * (1.0 / pivot)


@_jit
def solve_lower(l00: float, l10: float, l11: float, b0: float, b1: float, divide: bool) -> tuple[float, float, bool]:
    """``np.linalg.solve(L, b)`` for ``L = [[l00, 0], [l10, l11]]`` as OpenBLAS's ``dgesv`` rounds it, and whether the
    inputs were plain (finite, non-zero pivots; else the result is unusable). Checked against numpy at load."""
    if not (math.isfinite(l00) and math.isfinite(l10) and math.isfinite(l11) and math.isfinite(b0)
            and math.isfinite(b1) and l00 != 0.0 and l11 != 0.0):
        return 0.0, 0.0, False
    if abs(l10) > abs(l00):  # (rows swapped: the pivot is l10)
        m = l00 * (1.0 / l10)
        x1 = _times_inverse(b0 - m * b1, -(m * l11), divide)
        return _times_inverse(b1 - l11 * x1, l10, divide), x1, True
    m = l10 * (1.0 / l00)
    return _times_inverse(b0, l00, divide), _times_inverse(b1 - m * b0, l11, divide), True


@_jit
def gate_work_lower(factor: np.ndarray, z: np.ndarray, mean: np.ndarray,
                    gate: float) -> tuple[int, np.ndarray, np.ndarray]:
    """:func:`gate_work` from the innovation covariances' lower Cholesky factors ``(k, 2, 2)``, detections ``z (d, 2)``
    and means ``mean (k, >= 2)``, whitening here (:func:`solve_lower`); decision -1 when not plain."""
    k, d = factor.shape[0], z.shape[0]
    work = np.empty((k, d))
    for i in range(k):
        l00, l10, l11 = factor[i, 0, 0], factor[i, 1, 0], factor[i, 1, 1]
        for j in range(d):
            a, b, plain = solve_lower(l00, l10, l11, z[j, 0] - mean[i, 0], z[j, 1] - mean[i, 1], d == 1)
            if not plain:
                return -1, work, np.zeros((k, d), np.bool_)
            work[i, j] = a * a + b * b
    return _gate_decision(work, gate)


@_jit
def _allowed(work: np.ndarray, limit: float) -> tuple[np.ndarray, bool, bool]:
    """Which entries of ``work (k, d)`` are at most ``limit``, whether any is, and whether they are disjoint."""
    k, d = work.shape
    allowed = np.zeros((k, d), np.bool_)
    per_row = np.zeros(k, np.int64)
    per_column = np.zeros(d, np.int64)
    for i in range(k):
        for j in range(d):
            if work[i, j] <= limit:
                allowed[i, j] = True
                per_row[i] += 1
                per_column[j] += 1
    found = per_row.sum() > 0
    return allowed, found, found and per_row.max() <= 1 and per_column.max() <= 1


@_jit
def _gate_decision(work: np.ndarray, gate: float) -> tuple[int, np.ndarray, np.ndarray]:
    """The rest of :func:`gate_work`, in place on the squared distances ``work (k, d)``."""
    k, d = work.shape
    allowed, found, disjoint = _allowed(work, gate)
    if not found or disjoint:
        return (1 if found else 0), work, allowed
    low = np.inf
    for i in range(k):
        for j in range(d):
            if allowed[i, j]:
                low = _minimum(low, work[i, j])
    top = 0.0  # (the forbidden pairs' 0.0 takes part in the maximum)
    for i in range(k):
        for j in range(d):
            work[i, j] = work[i, j] - low if allowed[i, j] else 0.0
            top = _maximum(top, work[i, j])
    shortest = min(k, d)
    if top > 0 and top * shortest > 1e290:
        for i in range(k):
            for j in range(d):
                work[i, j] = work[i, j] / top
        top = 1.0
    penalty = (top + 1.0) * (shortest + 1)
    for i in range(k):
        for j in range(d):
            if not allowed[i, j]:
                work[i, j] = penalty
    return 2, work, allowed


@_jit
def update_hits(mean: np.ndarray, cov: np.ndarray, rows: np.ndarray, cols: np.ndarray, gain: np.ndarray,
                cov_hit: np.ndarray, z: np.ndarray) -> None:
    """Kalman update of tracks ``rows`` by detections ``cols`` in place: ``mean[i] += Kᵀ (z[j] - mean[i, :2])`` summed
    as ``einsum`` does (``gain (k, 2, n)``: K transposed), ``cov[i] = cov_hit[i]``. Checked against numpy at load."""
    n = mean.shape[1]
    for r in range(rows.shape[0]):
        i, j = rows[r], cols[r]
        v0, v1 = z[j, 0] - mean[i, 0], z[j, 1] - mean[i, 1]
        for a in range(n):
            total = 0.0
            total = total + gain[i, 0, a] * v0
            total = total + gain[i, 1, a] * v1
            mean[i, a] = mean[i, a] + total
        for a in range(cov.shape[1]):
            for b in range(cov.shape[2]):
                cov[i, a, b] = cov_hit[i, a, b]


@_jit
def solve_lower_many(factor: np.ndarray, b: np.ndarray, divide: bool) -> np.ndarray:
    """:func:`solve_lower` of each factor ``(k, 2, 2)`` and ``b (k, 2)``, NaN where not plain (for the check)."""
    out = np.full((factor.shape[0], 2), np.nan)
    for i in range(factor.shape[0]):
        x0, x1, plain = solve_lower(factor[i, 0, 0], factor[i, 1, 0], factor[i, 1, 1], b[i, 0], b[i, 1], divide)
        if plain:
            out[i, 0], out[i, 1] = x0, x1
    return out


@_jit
def shift_reports(th: np.ndarray, agent_id: np.ndarray, t_sent: np.ndarray, heading: np.ndarray) -> bool:
    """``BeaconIdentifier._shift_common``: when the reports are of distinct agents ``0 .. N-1``, each newer than its
    agent's latest, shift them into ``th (2, N, r)`` and return True; otherwise change nothing, return False."""
    n, r = th.shape[1], th.shape[2]
    seen = np.zeros(n, np.bool_)
    for i in range(agent_id.shape[0]):
        a = agent_id[i]
        if a < 0 or a >= n or seen[a] or t_sent[i] <= th[0, a, r - 1]:
            return False
        seen[a] = True
    for i in range(agent_id.shape[0]):
        a = agent_id[i]
        for j in range(r - 1):
            th[0, a, j] = th[0, a, j + 1]
            th[1, a, j] = th[1, a, j + 1]
        th[0, a, r - 1] = t_sent[i]
        th[1, a, r - 1] = heading[i]
    return True


@_jit
def birth_candidates(det_of_track: np.ndarray, score: np.ndarray, min_score: float, check_score: bool,
                     position: np.ndarray, mean: np.ndarray, exclusion_m: float, check_exclusion: bool) -> np.ndarray:
    """``WorldTracker._birth_candidates``: the detections no track took, scoring at least ``min_score`` (when
    ``check_score``), farther than ``exclusion_m`` from every track's position (when ``check_exclusion``)."""
    n = position.shape[0]
    free = np.ones(n + 1, np.bool_)  # (the extra last entry takes the misses' -1)
    for i in range(det_of_track.shape[0]):
        free[det_of_track[i]] = False
    out = np.empty(n, np.int64)
    found = 0
    for i in range(n):
        if not free[i] or (check_score and not score[i] >= min_score):
            continue
        if check_exclusion and mean.shape[0]:
            nearest = 0.0
            for j in range(mean.shape[0]):
                dx, dy = position[i, 0] - mean[j, 0], position[i, 1] - mean[j, 1]
                gap = np.sqrt(dx * dx + dy * dy)
                nearest = gap if j == 0 else _minimum(nearest, gap)
            if not nearest > exclusion_m:
                continue
        out[found] = i
        found += 1
    return out[:found]


@_jit
def lifecycle_work(det_of_track: np.ndarray, hit_bits: np.ndarray, misses: np.ndarray, unseen_s: np.ndarray,
                   hits: np.ndarray, confirmed: np.ndarray, dt: float, confirm_window: int, n_init: int,
                   tentative_max_misses: int, max_misses: int, in_view: np.ndarray, limit_in_s: float,
                   limit_out_s: float) -> np.ndarray:
    """``WorldTracker._lifecycle`` with ``Lifecycle.alive``, in place on the table's columns; ``confirm_window`` 0: no
    window (every track confirmed); miss limits -1: none. Returns the survivors' mask."""
    k = det_of_track.shape[0]
    keep = np.empty(k, np.bool_)
    window_mask = (1 << confirm_window) - 1 if confirm_window > 0 else 0
    for i in range(k):
        hit = det_of_track[i] >= 0
        hit_bits[i] = ((hit_bits[i] << 1) | (1 if hit else 0)) & ((1 << 30) - 1)
        if hit:
            misses[i] = 0
            unseen_s[i] = 0.0
        else:
            misses[i] = misses[i] + 1
            unseen_s[i] = unseen_s[i] + dt
        if confirm_window > 0:
            bits = hit_bits[i] & window_mask
            count = 0
            while bits:
                count += bits & 1
                bits >>= 1
            hits[i] = count
            if count >= n_init:
                confirmed[i] = True
        else:
            confirmed[i] = True
        if confirmed[i]:
            ok = max_misses < 0 or misses[i] <= max_misses
            if confirm_window > 0:
                ok = ok and unseen_s[i] <= (limit_in_s if in_view[i] else limit_out_s)
            keep[i] = ok
        else:
            keep[i] = tentative_max_misses < 0 or misses[i] < tentative_max_misses
    return keep


@_jit
def cosines(x: np.ndarray) -> np.ndarray:
    """The kernels' ``cos`` of each value of ``x`` (compared with numpy's before the kernels are used)."""
    out = np.empty_like(x)
    for i in range(x.shape[0]):
        out[i] = math.cos(x[i])
    return out
