"""MotionFit: the process-noise scale follows how badly the model fits, and never falls below 1."""

from __future__ import annotations

import numpy as np
import pytest

from lookalike.trackers.parts.motion_fit import CHI2_2DOF_MEDIAN, MotionFit


def _feed(fit: MotionFit, rng: np.random.Generator, true_var: float, rounds: int) -> None:
    """Innovations with variance ``true_var`` while the model claims ``fit.scale`` (unit base variance)."""
    for _ in range(rounds):
        S = np.tile(np.eye(2) * fit.scale, (10, 1, 1))
        fit.observe(rng.normal(0, np.sqrt(true_var), size=(10, 2)), S)


def test_a_model_that_fits_keeps_its_noise() -> None:
    fit = MotionFit(batch=30)
    _feed(fit, np.random.default_rng(0), 1.0, 60)
    assert fit.scale < 1.3


def test_erratic_targets_raise_the_noise_until_the_median_fits() -> None:
    rng = np.random.default_rng(1)
    fit = MotionFit(batch=30)
    _feed(fit, rng, 25.0, 200)
    assert 15 < fit.scale < 40  # converges near 25: the variance the innovations really have
    S = np.tile(np.eye(2) * fit.scale, (4000, 1, 1))
    x = rng.normal(0, 5.0, size=(4000, 2))
    nis = np.einsum("ki,kij,kj->k", x, np.linalg.inv(S), x)
    assert np.median(nis) == pytest.approx(CHI2_2DOF_MEDIAN, rel=0.5)


def test_scale_is_clipped_and_inputs_checked() -> None:
    fit = MotionFit(batch=1, max_scale=10.0)
    fit.observe(np.array([[1e6, 0.0]]), np.eye(2)[None])
    assert fit.scale == 10.0
    fit.observe(np.zeros((0, 2)), np.zeros((0, 2, 2)))
    assert fit.scale == 10.0
    with pytest.raises(ValueError, match="batch"):
        MotionFit(batch=0)
