import numpy as np
import pytest
from scipy.linalg import solve_discrete_are

from lookalike.motion import (
    chi2_gate,
    constant_acceleration,
    constant_velocity,
    gating_distance,
    predict,
    project,
    update,
)


def test_constant_velocity_matrices_closed_form():
    F, Q = constant_velocity(1, 0.5, q=2.0)
    np.testing.assert_allclose(F, [[1, 0.5], [0, 1]])
    # Continuous white-noise acceleration: Q = q [[dt^3/3, dt^2/2], [dt^2/2, dt]]
    np.testing.assert_allclose(Q, 2.0 * np.array([[0.5**3 / 3, 0.5**2 / 2], [0.5**2 / 2, 0.5]]))
    F2, _ = constant_velocity(2, 1.0)
    assert F2.shape == (4, 4)
    np.testing.assert_allclose(F2[:2, 2:], np.eye(2))


def test_constant_acceleration_transition():
    F, Q = constant_acceleration(2, 0.1)
    assert F.shape == Q.shape == (6, 6)
    np.testing.assert_allclose(F[0, [0, 2, 4]], [1, 0.1, 0.005])
    np.testing.assert_allclose(Q, Q.T)
    assert np.all(np.linalg.eigvalsh(Q) >= -1e-15)


def test_bad_model_arguments():
    with pytest.raises(ValueError, match="dt"):
        constant_velocity(2, float("nan"))
    with pytest.raises(ValueError, match="dim"):
        constant_acceleration(0, 1.0)


def test_constant_velocity_target_predicted_exactly_without_noise():
    dt = 0.04
    F, _ = constant_velocity(2, dt)
    mean = np.array([[1.0, 2.0, 3.0, -4.0], [0.0, 0.0, 0.5, 0.5]])
    cov = np.repeat(np.eye(4)[None], 2, axis=0)
    for _ in range(25):
        mean, cov = predict(mean, cov, F, np.zeros((4, 4)))
    np.testing.assert_allclose(mean[0], [1 + 3.0, 2 - 4.0, 3.0, -4.0])
    np.testing.assert_allclose(mean[1], [0.5, 0.5, 0.5, 0.5])


def test_static_target_covariance_reaches_riccati_steady_state():
    # A 1-D constant-velocity track observed in position: the predicted covariance converges to the
    # solution of the discrete algebraic Riccati equation.
    F, Q = constant_velocity(1, 1.0, q=0.1)
    H = np.array([[1.0, 0.0]])
    R = np.array([[0.5]])
    mean, cov = np.zeros((1, 2)), np.eye(2)[None] * 100.0
    for _ in range(500):
        mean, cov = predict(mean, cov, F, Q)
        mean, cov = update(mean, cov, np.zeros((1, 1)), H, R)
    pred_cov = F @ cov[0] @ F.T + Q
    expected = solve_discrete_are(F.T, H.T, Q, R)
    np.testing.assert_allclose(pred_cov, expected, rtol=1e-8)
    np.testing.assert_allclose(mean, 0.0, atol=1e-12)


def test_scalar_update_matches_formula():
    mean, cov = np.array([[2.0]]), np.array([[[4.0]]])
    H, R = np.eye(1), np.array([[1.0]])
    m, P = update(mean, cov, np.array([[7.0]]), H, R)
    gain = 4.0 / 5.0
    np.testing.assert_allclose(m, [[2.0 + gain * 5.0]])
    np.testing.assert_allclose(P, [[[(1 - gain) * 4.0]]])


def test_batched_equals_one_at_a_time():
    rng = np.random.default_rng(1)
    F, Q = constant_velocity(2, 0.1)
    H = np.hstack([np.eye(2), np.zeros((2, 2))])
    R = np.eye(2) * 0.3
    mean = rng.normal(size=(5, 4))
    A = rng.normal(size=(5, 4, 4))
    cov = A @ A.transpose(0, 2, 1) + np.eye(4)
    z = rng.normal(size=(5, 2))
    mb, pb = update(*predict(mean, cov, F, Q), z, H, R)
    for i in range(5):
        mi, pi = update(*predict(mean[i : i + 1], cov[i : i + 1], F, Q), z[i : i + 1], H, R)
        np.testing.assert_allclose(mb[i], mi[0])
        np.testing.assert_allclose(pb[i], pi[0])


def test_gating_distance_is_mahalanobis():
    mean = np.array([[0.0, 0.0, 0.0, 0.0]])
    cov = np.diag([4.0, 1.0, 1.0, 1.0])[None]
    H = np.hstack([np.eye(2), np.zeros((2, 2))])
    R = np.zeros((2, 2))
    d = gating_distance(mean, cov, np.array([[2.0, 0.0], [0.0, 3.0]]), H, R)
    np.testing.assert_allclose(d, [[1.0, 9.0]])
    z_hat, S = project(mean, cov, H, R)
    np.testing.assert_allclose(S[0], np.diag([4.0, 1.0]))


def test_chi2_gate_known_value():
    assert chi2_gate(4) == pytest.approx(9.4877, abs=1e-4)
    assert chi2_gate(2) == pytest.approx(5.9915, abs=1e-4)
    with pytest.raises(ValueError):
        chi2_gate(0)


@pytest.mark.parametrize("dof", range(1, 9))
def test_chi2_gate_equals_scipy(dof):
    from scipy.stats import chi2

    for p in (0.01, 0.5, 0.9, 0.95, 0.99, 0.9999):
        assert chi2_gate(dof, p) == pytest.approx(chi2.ppf(p, dof), rel=1e-12)
