"""Chi-square gating thresholds for squared Mahalanobis distances, without scipy: the closed-form CDF for integer and
half-integer orders, inverted by bisection to the last bit."""

from __future__ import annotations

import math
from functools import lru_cache


def chi2_cdf(x: float, dof: int) -> float:
    """``P(X <= x)`` for ``X`` chi-square with ``dof`` (a positive integer) degrees of freedom."""
    if x <= 0.0:
        return 0.0
    half = x / 2.0
    if dof % 2 == 0:  # P(k, h) = 1 - e^-h sum_{j<k} h^j / j!
        term, total = 1.0, 1.0
        for j in range(1, dof // 2):
            term *= half / j
            total += term
        return max(0.0, 1.0 - math.exp(-half) * total)
    # P(1/2, h) = erf(sqrt h); P(a + 1, h) = P(a, h) - h^a e^-h / Gamma(a + 1)
    value = math.erf(math.sqrt(half))
    a = 0.5
    for _ in range((dof - 1) // 2):
        value -= math.exp(a * math.log(half) - half - math.lgamma(a + 1.0))
        a += 1.0
    return max(0.0, value)


@lru_cache(maxsize=64)
def chi2_gate(dof: int, probability: float = 0.95) -> float:
    """The ``probability`` quantile of chi-square with ``dof`` degrees of freedom (``chi2_gate(4) == 9.4877…``)."""
    if dof < 1:
        raise ValueError(f"dof must be at least 1, got {dof}")
    if not 0.0 < probability < 1.0:
        raise ValueError(f"probability must be in (0, 1), got {probability}")
    lo, hi = 0.0, float(dof) + 10.0
    while chi2_cdf(hi, dof) < probability:
        hi *= 2.0
    for _ in range(200):
        mid = (lo + hi) / 2.0
        if mid in (lo, hi):
            break
        if chi2_cdf(mid, dof) < probability:
            lo = mid
        else:
            hi = mid
    return hi
