"""Kalman filter: the linear-Gaussian check against the closed-form Bayesian posterior, and the update."""

import numpy as np
import pytest

from fracid.inverse.methods.assimilation import kalman_update
from fracid.inverse.methods.kalman import batch_kalman, kalman_filter


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


# --- bounds and failed runs ----------------------------------------------------------------------------


def recording(h, fails=lambda x: False):
    """h that records every point it is asked for, and fails (a failed RunRecord) where ``fails``."""
    from fracid.inverse.core.forward_operator import RunRecord

    asked = []

    def evaluate(x, needed=None):
        asked.append(np.array(x, float))
        if fails(x):
            return RunRecord(np.array(x, float), np.full(12, np.nan), status="failed", error="diverged")
        return RunRecord(np.array(x, float), h(x))

    return evaluate, asked


@pytest.mark.parametrize("groups", [None, "all"])
def test_estimates_stay_inside_the_bounds_and_are_flagged(groups):
    h, y, R, x0, C0, (x_post, _) = linear_problem()
    lower, upper = np.array([0.0, -1.5, -1.0]), np.array([2.0, 0.0, 1.0])
    assert x_post[1] < lower[1]  # the unconstrained posterior leaves the box
    evaluate, asked = recording(h)
    groups = [np.arange(12)] if groups == "all" else None
    result = kalman_filter(evaluate, y, R, x0, C0, groups=groups, bounds=(lower, upper))
    asked = np.array(asked)
    reach = 0.0101 * np.abs(asked) + 1e-12  # the sensitivities' +-1 % perturbations around points of the box
    assert np.all(asked >= lower - reach) and np.all(asked <= upper + reach)
    assert np.all(result.x >= lower) and np.all(result.x <= upper)
    assert result.at_bound.tolist() == [False, True, False] and result.x[1] == lower[1]
    assert not result.failed and result.status.startswith(("converged", "not converged"))
    for entry in result.history:
        assert np.all(entry["x"] >= lower) and np.all(entry["x"] <= upper)


def test_projection_is_the_most_probable_point_in_the_box():
    from fracid.inverse.methods.kalman import project_to_box

    C = np.array([[1.0, 0.95], [0.95, 1.0]])
    x = np.array([2.0, 1.8])
    lower, upper = np.array([-1.0, -1.0]), np.array([1.0, 3.0])
    z = project_to_box(x, C, lower, upper)
    grid = np.stack(np.meshgrid(np.linspace(-1, 1, 401), np.linspace(-1, 3, 801)), -1).reshape(-1, 2)
    d = grid - x
    best = grid[np.argmin(np.einsum("ij,jk,ik->i", d, np.linalg.inv(C), d))]
    np.testing.assert_allclose(z, best, atol=0.01)
    assert z[0] == 1.0 and z[1] < 1.8  # slides along the valley; clipping would keep 1.8
    np.testing.assert_array_equal(project_to_box(np.array([0.5, 0.5]), C, lower, upper), [0.5, 0.5])


def test_failed_runs_are_backtracked_towards_the_last_good_point():
    """The model fails beyond x0 > 1.2: the steps into that region are shortened, never raised."""
    h, y, R, x0, C0, (x_post, _) = linear_problem()
    y = y + 5.0 * (h(np.array([1.6, -2.0, 0.5])) - h(np.array([1.0, -2.0, 0.5])))  # pulls x[0] to ~3.4
    evaluate, asked = recording(h, fails=lambda x: x[0] > 1.2)
    result = kalman_filter(evaluate, y, R, x0, C0, max_iterations=6)
    assert result.failures and all(f["error"] == "diverged" for f in result.failures)
    assert not result.failed and np.all(np.isfinite(result.y)) and result.x[0] <= 1.2
    assert result.status  # converged, not converged or stopped: always said


def test_a_filter_that_cannot_run_anywhere_stops_with_a_status():
    h, y, R, x0, C0, _ = linear_problem()
    evaluate, _ = recording(h, fails=lambda x: True)
    result = kalman_filter(evaluate, y, R, x0, C0)
    assert result.failed and result.status.startswith("failed:") and "diverged" in result.status
    np.testing.assert_array_equal(result.x, x0)


def test_a_refused_relinearisation_falls_back_once_to_the_last_full_run(monkeypatch):
    """A first pass that ends beside its last full run, its objective a little above it, does not stop the
    filter: the next pass is linearised at that run (a Gauss-Newton step from it), once per such point."""
    import fracid.inverse.methods.kalman as kalman

    x_true = np.array([1.2, 0.6])
    t = np.linspace(0.1, 2.0, 16)

    def h(x, needed=None):  # nonlinear: the first step-by-step pass stops short of the posterior
        return x[0] * np.exp(-x[1] * t) + 0.3 * x[0] ** 2

    y, R = h(x_true), np.eye(t.size) * 1e-6
    x0, C0 = np.array([0.8, 1.0]), np.diag([0.5, 0.5])
    reference = kalman_filter(h, y, R, x0, C0, groups=[np.arange(8), np.arange(8, 16)])
    assert reference.converged
    real, refused = kalman._decreases, []

    def refuse_first(*args):  # the first relinearisation refused, as when the estimate sits a little above
        if not refused:
            refused.append(1)
            return lambda x, y: False
        return real(*args)

    monkeypatch.setattr(kalman, "_decreases", refuse_first)
    result = kalman_filter(h, y, R, x0, C0, groups=[np.arange(8), np.arange(8, 16)], max_iterations=10)
    assert refused and result.converged  # the next pass linearised at the last full run, and on to the end
    np.testing.assert_allclose(result.x, reference.x, rtol=1e-4)
    monkeypatch.setattr(kalman, "_decreases", lambda *a: lambda x, y: False)  # every estimate refused
    stuck = kalman_filter(h, y, R, x0, C0, groups=[np.arange(8), np.arange(8, 16)], max_iterations=10)
    assert not stuck.converged and stuck.iterations == 2  # the fallback once per point: no endless passes
