"""Chi-square gating thresholds for squared Mahalanobis distances."""

from __future__ import annotations

from functools import lru_cache

from scipy.stats import chi2


@lru_cache(maxsize=64)
def chi2_gate(dof: int, probability: float = 0.95) -> float:
    """The ``probability`` quantile of the chi-square distribution with ``dof`` degrees of freedom.

    ``chi2_gate(4) == 9.4877…``: a squared Mahalanobis distance above it is outside the gate.
    """
    if dof < 1:
        raise ValueError(f"dof must be at least 1, got {dof}")
    if not 0.0 < probability < 1.0:
        raise ValueError(f"probability must be in (0, 1), got {probability}")
    return float(chi2.ppf(probability, dof))
