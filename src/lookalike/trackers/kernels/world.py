"""Small batched kernels of the world trackers' per-frame path (Kalman-HA and its beacon identifier), each bit for bit
what the general function returns with fewer calls (numpy's LAPACK gufuncs, ``einsum``, :func:`pairs`).

:func:`compiled` gives the optional numba kernels (:mod:`~lookalike.trackers.kernels.world_numba`) unless
``LOOKALIKE_WORLD_NUMBA=0``; the two whose rounding depends on the BLAS build (:func:`lower_solve_exact`,
:func:`update_exact`) are used only where they matched numpy when they loaded."""

from __future__ import annotations

from collections.abc import Callable
from types import ModuleType

import numpy as np

from lookalike._compiled import KernelSwitch
from lookalike.association.solver import solve_allowed

try:  # numpy's gufuncs behind np.linalg.cholesky / np.linalg.solve (the same kernels, no wrapper)
    from numpy.linalg import _umath_linalg as _kernels
except ImportError:  # pragma: no cover (a numpy without them: the public functions)
    _kernels = None  # type: ignore[assignment]

try:  # the kernel np.einsum calls without path optimisation (the default), without its wrapper
    from numpy._core.multiarray import c_einsum as _einsum_kernel
except ImportError:  # pragma: no cover
    _einsum_kernel = np.einsum  # type: ignore[assignment,unused-ignore]
einsum: Callable[..., np.ndarray] = _einsum_kernel


def filled(shape: int | tuple[int, ...], value: float, dtype: type = float) -> np.ndarray:
    """``np.full(shape, value, dtype)`` without its Python wrapper."""
    out: np.ndarray = np.empty(shape, dtype)
    out.fill(value)
    return out


def cholesky(a: np.ndarray) -> np.ndarray:
    """Lower Cholesky factors of the stacked float64 matrices ``a`` (positive definite: a
    non-definite one gives NaN rather than ``LinAlgError``)."""
    if _kernels is None:  # pragma: no cover
        return np.linalg.cholesky(a)
    out: np.ndarray = _kernels.cholesky_lo(a, signature="d->d")
    return out


def solve(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``np.linalg.solve(a, b)`` for stacked float64 ``a (..., m, m)`` and ``b (..., m, n)``."""
    if _kernels is None:  # pragma: no cover
        return np.linalg.solve(a, b)
    out: np.ndarray = _kernels.solve(a, b, signature="dd->d")
    return out


_NONE = np.zeros(0, dtype=int)
_NONE.flags.writeable = False


def pairs(cost: np.ndarray, allowed: np.ndarray, max_cost: float = np.inf,
          unit: bool = False) -> tuple[np.ndarray, np.ndarray]:
    """Rows and columns of :func:`~lookalike.association.solver.assign_pairs` on ``where(allowed, cost, inf)`` (no NaN)
    with ``max_cost`` (``allowed``: ``cost <= max_cost``, or the pairs to consider with ``max_cost = inf``). ``unit``:
    allowed costs >= 0 and ``max_cost <= 1`` (the solver's scale is 1: no rescaling)."""
    if not cost.size or not allowed.any():
        return _NONE, _NONE
    most = np.maximum.reduce
    if most(np.add.reduce(allowed, axis=0)) == 1 and most(np.add.reduce(allowed, axis=1)) == 1:
        rows, cols = allowed.nonzero()
        return rows, cols
    if not (unit and max_cost <= 1.0):
        return solve_allowed(cost, allowed, max_cost)
    # |max_cost - min| <= 1: the solver's scale is 1, every entry within [0, 1 + 1e-6]
    return decided_pairs(2, np.where(allowed, cost, max_cost + 1e-6), allowed)


def decided_pairs(decision: int, work: np.ndarray, allowed: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """:func:`pairs` once its checks are made: ``decision`` 0 (nothing allowed), 1 (the disjoint ``allowed`` pairs) or
    2 (solve ``work`` and keep the allowed pairs)."""
    if decision == 0:
        return _NONE, _NONE
    if decision == 1:
        rows, cols = allowed.nonzero()
        return rows, cols
    rows, cols = (_solver or _load_solver())(work)
    keep = allowed[rows, cols]
    return rows[keep], cols[keep]


_solver: Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]] | None = None


def _load_solver() -> Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]]:
    """scipy's ``linear_sum_assignment`` (what ``association.solver``'s wrapper calls), kept after its first use."""
    global _solver
    from lookalike._lsap import solver

    found: Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]] = solver()
    _solver = found
    return found


def _load() -> ModuleType | None:
    from lookalike.trackers.kernels import world_numba

    global _lower_solve_exact, _update_exact
    # (the kernels' cos is libm's; numpy may use its own vector code: they must agree on every value here)
    angles = np.linspace(-4.0 * np.pi, 4.0 * np.pi, 4099)
    if not np.array_equal(world_numba.cosines(angles), np.cos(angles)):
        return None
    _lower_solve_exact = _same_lower_solves(world_numba)
    _update_exact = _same_updates(world_numba)
    return world_numba


_lower_solve_exact = _update_exact = False
CHECKED_RHS = 16  # the most right-hand sides (detections) the 2×2 solve replica is checked with


def update_exact() -> bool:
    """Whether the compiled kernels are in use and ``update_hits`` matched ``einsum`` bit for bit when they loaded."""
    return compiled() is not None and _update_exact


def _same_updates(kernels: ModuleType) -> bool:
    """Compare ``kernels.update_hits`` with numpy on 2,000 random updates (with zeros and negative zeros)."""
    rng = np.random.default_rng(20261203)
    k = 2000
    gain = rng.normal(0.0, 1.0, (k, 2, 6)) * rng.choice([0.0, -0.0, 1e-3, 1.0, 1e3], (k, 2, 6))
    mean = rng.normal(0.0, 3.0, (k, 6)) * rng.choice([0.0, -0.0, 1.0], (k, 6))
    z = mean[:, :2] + rng.normal(0.0, 0.5, (k, 2)) * rng.choice([0.0, 1.0], (k, 1))
    rows = rng.permutation(k)
    expected = mean[rows] + einsum("kij,kj->ki", gain[rows].swapaxes(-1, -2), z - mean[rows, :2])
    got, cov = mean.copy(), np.zeros((k, 6, 6))
    kernels.update_hits(got, cov, rows, np.arange(k), gain, np.ones((k, 6, 6)), z)
    return bool(np.array_equal(got[rows].view(np.int64), expected.view(np.int64)) and (cov == 1.0).all())


def lower_solve_exact(n_rhs: int = 1) -> bool:
    """Whether the compiled 2×2 lower-triangular solve is in use and matched numpy's ``solve`` bit for bit on the check
    systems for ``n_rhs`` right-hand sides (checked up to :data:`CHECKED_RHS`)."""
    return n_rhs <= CHECKED_RHS and compiled() is not None and _lower_solve_exact


def _same_lower_solves(kernels: ModuleType) -> bool:
    """Compare ``kernels.solve_lower`` with numpy's ``solve`` on 4,800 random 2×2 Cholesky systems."""
    rng = np.random.default_rng(20261202)
    for d in (1, 2, 5, 10, CHECKED_RHS):
        k = 960 // d
        var = rng.uniform(1e-4, 4.0, (k, 2))
        corr = rng.uniform(-0.999, 0.999, k)
        S = np.empty((k, 2, 2))
        S[:, 0, 0], S[:, 1, 1] = var[:, 0], var[:, 1]
        S[:, 0, 1] = S[:, 1, 0] = corr * np.sqrt(var[:, 0] * var[:, 1])
        factor = cholesky(S)
        b = rng.normal(0.0, 2.0, (k, 2, d))
        expected = solve(factor, b)  # (k, 2, d)
        got = kernels.solve_lower_many(np.repeat(factor, d, axis=0), b.swapaxes(1, 2).reshape(k * d, 2), d == 1)
        if not np.array_equal(got, expected.swapaxes(1, 2).reshape(k * d, 2)):
            return False
    return True


_SWITCH: KernelSwitch[ModuleType] = KernelSwitch("LOOKALIKE_WORLD_NUMBA", _load, decide_once=True)
use_compiled = _SWITCH.use_compiled  # (None: the environment is read again at the next call of compiled)
compiled = _SWITCH.compiled  # the world_numba module; None when off, without numba, or its cos differs from numpy's


def warm() -> bool:
    """Load (and compile at the first use) the kernels now, not at the first frame; whether they are in use."""
    kernels = compiled()
    if kernels is None:
        return False
    # (each kernel called with the argument types of the trackers' calls: float64 and int arrays, C order)
    th, times, samples = np.full((2, 2, 2), np.nan), np.zeros(1), np.zeros((1, 1))
    kernels.window_costs(th, times, times, samples, 1.0, 1.0, np.empty((1, 2)))
    _, cost, _, _ = kernels.identity_rows_work(th, times, times, np.full((2, 1), np.nan), np.full(2, -1),
                                               np.zeros(1, dtype=int), 1.0, 1.0, 0.1, 0.3)
    kernels.identity_results(np.zeros(0, dtype=int), np.zeros(0, dtype=int), cost, np.full(2, -1),
                             np.zeros(1, dtype=int))
    kernels.gate_work(np.zeros((1, 2, 1)), 1.0)
    kernels.gate_work_lower(np.ones((1, 2, 2)), np.zeros((1, 2)), np.zeros((1, 6)), 1.0)
    kernels.update_hits(np.zeros((1, 6)), np.zeros((1, 6, 6)), np.zeros(1, dtype=int), np.zeros(1, dtype=int),
                        np.zeros((1, 2, 6)), np.zeros((1, 6, 6)), np.zeros((1, 2)))
    ints, flags = np.zeros(1, dtype=int), np.zeros(1, dtype=bool)
    kernels.lifecycle_work(ints, ints.copy(), ints.copy(), np.zeros(1), ints.copy(), flags, 0.0, 5, 3, 2, -1,
                           flags.copy(), 1.0, 1.0)
    ids, values, pairs_ = np.zeros(1, dtype=int), np.zeros(1), np.zeros((1, 2))
    for flag in (True, False):  # (the node's detections and reports arrive read-only)
        ids.flags.writeable = values.flags.writeable = pairs_.flags.writeable = flag
        kernels.shift_reports(th, ids, values, values)
        kernels.birth_candidates(np.zeros(1, dtype=int), values, 0.5, True, pairs_, np.zeros((1, 6)), 0.35, True)
    return True
