"""Bounded Gauss-Newton (least_squares with the sensitivity as Jacobian): the same MAP estimate and
covariance as the Kalman filter, on analytic models only."""

import numpy as np
import pytest
from scipy.optimize import lsq_linear

from fracid.inverse.core.forward_operator import RunRecord
from fracid.inverse.methods.gauss_newton import gauss_newton
from fracid.inverse.methods.kalman import batch_kalman, kalman_filter
from fracid.inverse.core.sensitivity import ForwardRunError, evaluate_points


def linear_problem(seed=0, n=12):
    rng = np.random.default_rng(seed)
    A = rng.normal(size=(n, 3))
    b = rng.normal(size=n)
    R = np.diag(rng.uniform(0.05, 0.2, size=n) ** 2)
    y = A @ np.array([1.0, -2.0, 0.5]) + b + rng.multivariate_normal(np.zeros(n), R)
    x0 = np.array([0.5, -1.0, 0.0])
    C0 = np.array([[1.0, 0.3, 0.0], [0.3, 2.0, 0.0], [0.0, 0.0, 0.5]])

    def h(x, needed=None):
        return A @ x + b

    G = C0 @ A.T @ np.linalg.inv(A @ C0 @ A.T + R)
    return h, A, y, R, x0, C0, (x0 + G @ (y - A @ x0 - b), C0 - G @ A @ C0)


T = np.linspace(0.1, 2.0, 20)


def saturating(x, needed=None):
    """y_t = x0 (1 - exp(-x1 t)) + x2 t^2."""
    return x[0] * (1.0 - np.exp(-x[1] * T)) + x[2] * T**2


def saturating_jacobian(x):
    return np.column_stack([1.0 - np.exp(-x[1] * T), x[0] * T * np.exp(-x[1] * T), T**2])


def exact(jacobian, calls=None):
    """A sensitivity method with the analytic S: one run per call (as direct differentiation)."""

    def sensitivity(evaluate, x, needed=None, executor=None):
        if calls is not None:
            calls.append(np.array(x))
        record = evaluate_points(evaluate, [x], needed, executor)[0]
        if not record.ok:
            raise ForwardRunError(f"the forward run at x = {x.tolist()} failed: {record.error}")
        return record.y, jacobian(x), [record]

    return sensitivity


def saturating_problem():
    y = saturating(np.array([2.0, 1.5, 0.3]))  # noise-free
    return y, np.eye(T.size) * 0.01**2, np.diag([1.0, 1.0, 0.25])


def test_linear_gaussian_gives_the_closed_form_posterior_and_the_kalman_filters():
    h, A, y, R, x0, C0, (x_post, C_post) = linear_problem()
    result = gauss_newton(h, y, R, x0, C0)
    np.testing.assert_allclose(result.x, x_post, rtol=1e-8)
    np.testing.assert_allclose(result.C, C_post, rtol=1e-8, atol=1e-12)
    assert result.converged and result.status == "converged" and not result.failures
    np.testing.assert_allclose(result.y, h(result.x), rtol=1e-12)
    assert result.iterations == len(result.history) and [e["iteration"] for e in result.history] == \
        list(range(1, result.iterations + 1))
    assert result.runs == 7 * result.iterations  # central differences: 2 p + 1 runs per linearisation
    for other in (kalman_filter(h, y, R, x0, C0, restart="linearize"), batch_kalman(h, y, R, x0, C0)):
        np.testing.assert_allclose(result.x, other.x, rtol=1e-6)
        np.testing.assert_allclose(result.C, other.C, rtol=1e-6, atol=1e-12)


@pytest.mark.parametrize("units", [(1.0, 1.0, 1.0), (1e4, 1e-4, 1.0)], ids=["unit", "E-and-kappa-magnitudes"])
def test_nonlinear_model_reaches_the_kalman_filters_map_point(units):
    units = np.array(units)  # parameters in units of very different magnitudes: the scaling copes
    y, R, C0 = saturating_problem()
    x0, C0 = np.array([1.8, 1.2, 0.2]) * units, C0 * np.outer(units, units)

    def model(x, needed=None):
        return saturating(x / units)

    sensitivity = exact(lambda x: saturating_jacobian(x / units) / units)
    result = gauss_newton(model, y, R, x0, C0, sensitivity=sensitivity, tol=1e-3)
    kalman = kalman_filter(model, y, R, x0, C0, restart="linearize", sensitivity=sensitivity, tol=1e-3)
    assert result.converged and kalman.converged
    assert np.all(np.abs(result.x - kalman.x) <= 1e-3 * kalman.std)
    D = np.outer(kalman.std, kalman.std)  # in std units, whatever the parameters' magnitudes
    np.testing.assert_allclose(result.C / D, kalman.C / D, atol=0.05)
    assert result.iterations > 2  # nonlinear: several linearisations


def test_a_truth_outside_the_box_gives_an_estimate_on_the_bound():
    h, A, y, R, x0, C0, (x_post, _) = linear_problem()
    lower, upper = np.array([0.0, -1.5, -1.0]), np.array([2.0, 0.0, 1.0])
    assert x_post[1] < lower[1]
    result = gauss_newton(h, y, R, x0, C0, bounds=(lower, upper), sensitivity=exact(lambda x: A))
    assert result.converged and result.at_bound.tolist() == [False, True, False]
    assert result.x[1] == lower[1] and np.all(result.x >= lower) and np.all(result.x <= upper)
    # the constrained MAP: a bounded linear least-squares problem in whitened form
    W_exp, W0 = (np.linalg.cholesky(np.linalg.inv(M)).T for M in (R, C0))  # W^T W = M^-1
    rhs = np.concatenate([W_exp @ (y - h(np.zeros(3))), W0 @ x0])
    constrained_map = lsq_linear(np.vstack([W_exp @ A, W0]), rhs, bounds=(lower, upper), method="bvls").x
    np.testing.assert_allclose(result.x, constrained_map, rtol=1e-6, atol=1e-9)
    np.testing.assert_allclose(result.x, batch_kalman(h, y, R, x0, C0, bounds=(lower, upper)).x, rtol=1e-6, atol=1e-9)


def test_an_exact_jacobian_costs_one_run_per_linearisation():
    y, R, C0 = saturating_problem()
    x0 = np.array([1.0, 0.3, 0.0])
    calls = []
    result = gauss_newton(saturating, y, R, x0, C0, sensitivity=exact(saturating_jacobian, calls), tol=1e-3)
    assert result.converged
    assert result.runs == len(calls) and result.run_equivalents == len(calls)
    assert len({c.tobytes() for c in calls}) == len(calls)  # the residual and the Jacobian share a call
    differences = gauss_newton(saturating, y, R, x0, C0, tol=1e-3)
    assert differences.converged and result.runs < differences.runs
    assert np.all(np.abs(result.x - differences.x) <= 0.05 * result.std)


@pytest.mark.parametrize("method", ["exact", "central differences"])
def test_failed_runs_shrink_the_step_and_are_recorded(method):
    """The model fails for x1 > 1.8, where the third trial point lands; the MAP (x1 ~ 1.5) is outside it."""
    y, R, C0 = saturating_problem()
    x0 = np.array([1.0, 0.3, 0.0])
    sensitivity = exact(saturating_jacobian) if method == "exact" else None
    reference = gauss_newton(saturating, y, R, x0, C0, sensitivity=exact(saturating_jacobian), tol=1e-3)

    def failing(x, needed=None):
        if x[1] > 1.8:
            return RunRecord(np.array(x, float), np.full(T.size, np.nan), status="failed", error="diverged")
        return RunRecord(np.array(x, float), saturating(x))

    kwargs = {} if sensitivity is None else {"sensitivity": sensitivity}
    result = gauss_newton(failing, y, R, x0, C0, tol=1e-3, **kwargs)
    assert result.converged and result.x[1] < 1.8 and np.all(np.isfinite(result.y))
    assert result.failures and all("diverged" in f["error"] and f["x"][1] > 1.8 for f in result.failures)
    assert np.all(np.abs(result.x - reference.x) <= 0.05 * reference.std)


def test_a_failure_at_the_starting_point_stops_with_a_status():
    h, A, y, R, x0, C0, _ = linear_problem()
    result = gauss_newton(lambda x, needed=None: np.full(12, np.nan), y, R, x0, C0)
    assert result.status.startswith("failed:") and result.failed and not result.converged
    assert len(result.failures) == 1 and result.runs == 1
    np.testing.assert_array_equal(result.x, x0)


def test_too_few_iterations_say_not_converged():
    y, R, C0 = saturating_problem()
    result = gauss_newton(saturating, y, R, np.array([1.0, 0.3, 0.0]), C0, sensitivity=exact(saturating_jacobian),
                          max_iterations=2)
    assert not result.converged and result.iterations == 2 and result.status.startswith("not converged: 2 iterations")
