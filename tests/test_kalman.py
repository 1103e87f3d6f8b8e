"""Kalman filter: the linear-Gaussian check against the closed-form Bayesian posterior, and the update."""

import numpy as np
import pytest

from fracid.inverse.kalman import batch_kalman, kalman_filter, kalman_update


def linear_problem(seed=0, n=12, p=3):
    rng = np.random.default_rng(seed)
    A = rng.normal(size=(n, p))
    b = rng.normal(size=n)
    x_true = np.array([1.0, -2.0, 0.5])
    R = np.diag(rng.uniform(0.05, 0.2, size=n) ** 2)
    y = A @ x_true + b + rng.multivariate_normal(np.zeros(n), R)
    x0 = np.array([0.5, -1.0, 0.0])
    C0 = np.diag([1.0, 2.0, 0.5])
    C0[0, 1] = C0[1, 0] = 0.3

    def h(x, needed=None):
        return A @ x + b

    G = C0 @ A.T @ np.linalg.inv(A @ C0 @ A.T + R)
    posterior = (x0 + G @ (y - A @ x0 - b), C0 - G @ A @ C0)
    return h, y, R, x0, C0, posterior


@pytest.mark.parametrize("groups", [None, [[0, 1, 2], [3], [4, 5, 6, 7], [8, 9, 10, 11]]], ids=["one-by-one", "groups"])
def test_step_by_step_filter_equals_bayesian_posterior(groups):
    h, y, R, x0, C0, (x_post, C_post) = linear_problem()
    result = kalman_filter(h, y, R, x0, C0, groups=groups)
    np.testing.assert_allclose(result.x, x_post, rtol=1e-10, atol=1e-12)
    np.testing.assert_allclose(result.C, C_post, rtol=1e-10, atol=1e-12)
    assert result.converged and result.iterations == 2  # linear: the second pass changes nothing
    assert len(result.history) == 2 * (12 if groups is None else 4)


def test_batch_filter_equals_bayesian_posterior():
    h, y, R, x0, C0, (x_post, C_post) = linear_problem(seed=1)
    result = batch_kalman(h, y, R, x0, C0)
    np.testing.assert_allclose(result.x, x_post, rtol=1e-10, atol=1e-12)
    np.testing.assert_allclose(result.C, C_post, rtol=1e-10, atol=1e-12)


def test_thesis_restart_drifts_from_the_posterior():
    """Re-using the estimate as prior mean re-uses the data: documented, and visible on a linear model."""
    h, y, R, x0, C0, (x_post, _) = linear_problem()
    result = kalman_filter(h, y, R, x0, C0, restart="prior-mean", max_iterations=3)
    assert not np.allclose(result.x, x_post, rtol=1e-6)


def test_joseph_update_is_symmetric_positive_definite_and_matches_standard_form():
    rng = np.random.default_rng(2)
    C = np.array([[2.0, 0.5], [0.5, 1.0]])
    S = rng.normal(size=(3, 2))
    R = np.eye(3) * 0.1
    x, C_new, K = kalman_update(np.zeros(2), C, S, np.ones(3), R)
    np.testing.assert_allclose(C_new, C - K @ S @ C, rtol=1e-12, atol=1e-14)
    assert np.allclose(C_new, C_new.T) and np.all(np.linalg.eigvalsh(C_new) > 0)


def test_bad_inputs_are_refused():
    h, y, R, x0, C0, _ = linear_problem()
    with pytest.raises(ValueError, match="C_exp"):
        kalman_filter(h, y, R[:3, :3], x0, C0)
    with pytest.raises(ValueError, match="positive definite"):
        kalman_filter(h, y, R, x0, -C0)
    with pytest.raises(ValueError, match="groups"):
        kalman_filter(h, y, R, x0, C0, groups=[[0, 1], [1, 2]])
    with pytest.raises(ValueError, match="restart"):
        kalman_filter(h, y, R, x0, C0, restart="again")
