"""Adaptive importance sampling of the posterior (fracid.inverse.sampling.posterior) against posteriors known by quadrature:
a curved (banana) valley, a bounded one, failed runs, reproducible draws; the floor of the effective sample size."""

import json

import numpy as np
import pytest

from fracid.inverse.core.space import ParameterSpace
from fracid.inverse.core.forward_operator import RunRecord
from fracid.inverse.sampling.mixture import weighted_quantile
from fracid.inverse.sampling.posterior import MIN_ESS, PosteriorSettings, ess_floor, posterior

BANANA_Y = np.array([0.0, 0.5, 0.3])
BANANA_C = np.diag([0.5, 0.1, 0.6]) ** 2


def banana(x, needed=None):
    """y = (a, b + 2 a^2, a + b): a curved valley in (a, b)."""
    return np.array([x[0], x[1] + 2.0 * x[0] ** 2, x[0] + x[1]])


def grid_moments(model, y, C, space, n=(401, 501)):
    """Posterior mean, std and 5/95 % quantiles on a fine grid of the bounds (the prior uniform there)."""
    axes = [np.linspace(lo, hi, k) for lo, hi, k in zip(space.lower, space.upper, n)]
    a, b = np.meshgrid(*axes, indexing="ij")
    outputs = np.array([model(x) for x in np.column_stack([a.ravel(), b.ravel()])])
    r = outputs - y
    ll = -0.5 * np.einsum("ni,ij,nj->n", r, np.linalg.inv(C), r)
    p = np.exp(ll - ll.max())
    p /= p.sum()
    pts = np.column_stack([a.ravel(), b.ravel()])
    mean = p @ pts
    std = np.sqrt(p @ (pts - mean) ** 2)
    q = np.array([[weighted_quantile(pts[:, j], p, [0.05, 0.95])] for j in range(2)]).reshape(2, 2)
    return mean, std, q


def gaussian_seed(model, x, C):
    """A Gauss-Newton-like Gaussian at x: (J^T C^-1 J)^-1 by central differences."""
    J = np.column_stack([(model(x + e) - model(x - e)) / 2e-6 for e in np.eye(len(x)) * 1e-6])
    return np.linalg.inv(J.T @ np.linalg.solve(C, J))


@pytest.mark.parametrize("lower, upper", [((-2.0, -3.0), (2.0, 2.0)),  # the valley well inside the bounds
                                          ((0.0, -3.0), (2.0, 2.0))])  # cut by the bound a >= 0: not a Gaussian
def test_banana_posterior_matches_quadrature(lower, upper):
    space = ParameterSpace(("a", "b"), lower, upper)
    mean, std, q = grid_moments(banana, BANANA_Y, BANANA_C, space)
    x0 = np.array([max(0.05, lower[0]), 0.4])
    settings = PosteriorSettings(samples_per_round=200, max_rounds=20, target_ess=1500)
    result = posterior(banana, BANANA_Y, BANANA_C, space, x0, gaussian_seed(banana, x0, BANANA_C), settings=settings)
    assert result.converged and result.failed == 0 and result.weights.sum() == pytest.approx(1.0)
    np.testing.assert_array_less(np.abs(result.mean - mean) / std, 0.1)
    np.testing.assert_allclose(result.std, std, rtol=0.1)
    # the 5 and 95 % quantiles, as masses (a tail quantile where the density is low is noisy as a value)
    below = [[result.weights[result.x[:, j] < q[j, k]].sum() for k in range(2)] for j in range(2)]
    np.testing.assert_allclose(below, [[0.05, 0.95]] * 2, atol=0.02)
    assert result.credible_intervals(0.9).shape == (2, 2)
    assert np.all(result.x >= space.lower) and np.all(result.x <= space.upper)


def test_failed_runs_get_no_weight_and_are_counted():
    """Runs fail where a < -0.5 (a tenth of the mass or so): they are counted, and the posterior is the
    one of the model where it runs (quadrature with the failed region cut out)."""

    def fragile(x, needed=None):
        if x[0] < -0.5:
            return RunRecord(np.asarray(x), np.full(3, np.nan), status="failed", error="diverged")
        return banana(x)

    space = ParameterSpace(("a", "b"), (-2.0, -3.0), (2.0, 2.0))
    settings = PosteriorSettings(samples_per_round=200, max_rounds=20, target_ess=1000)
    x0 = np.array([0.05, 0.4])
    result = posterior(fragile, BANANA_Y, BANANA_C, space, x0, gaussian_seed(banana, x0, BANANA_C), settings=settings)
    assert result.failed > 0 and np.all(result.weights[result.x[:, 0] < -0.5] == 0.0)
    cut = ParameterSpace(("a", "b"), (-0.5, -3.0), (2.0, 2.0))
    mean, std, _ = grid_moments(banana, BANANA_Y, BANANA_C, cut)
    np.testing.assert_array_less(np.abs(result.mean - mean) / std, 0.1)
    assert result.history[0]["failed"] >= 0 and sum(h["failed"] for h in result.history) == result.failed


def test_the_same_seed_draws_the_same_points():
    """A rerun draws the same points, so that a run store gives back every run (resumable)."""
    space = ParameterSpace(("a", "b"), (-2.0, -3.0), (2.0, 2.0))
    x0, settings = np.array([0.05, 0.4]), PosteriorSettings(samples_per_round=50, max_rounds=3, target_ess=1e9)
    C0 = gaussian_seed(banana, x0, BANANA_C)
    first = posterior(banana, BANANA_Y, BANANA_C, space, x0, C0, settings=settings)
    again = posterior(banana, BANANA_Y, BANANA_C, space, x0, C0, settings=settings)
    np.testing.assert_array_equal(first.x, again.x)
    assert not first.converged and first.rounds == 3


def banana_posterior(samples_per_round, max_rounds, target_ess):
    space = ParameterSpace(("a", "b"), (-2.0, -3.0), (2.0, 2.0))
    x0 = np.array([0.05, 0.4])
    settings = PosteriorSettings(samples_per_round=samples_per_round, max_rounds=max_rounds, target_ess=target_ess)
    return posterior(banana, BANANA_Y, BANANA_C, space, x0, gaussian_seed(banana, x0, BANANA_C), settings=settings)


def test_between_the_floor_and_the_target_the_intervals_are_rough():
    result = banana_posterior(100, 4, 1000)  # ESS about 100: above the floor of 50, below the target
    assert ess_floor(1000) <= result.ess < 1000 and not result.sampling_failed and not result.converged
    assert "below the target" in result.status and "rough" in result.status
    assert np.all(np.isfinite(result.credible_intervals(0.9)))


def test_below_the_ess_floor_the_sampling_failed_and_gives_no_intervals():
    """8 draws for a target of 500: ESS about 1, far below the floor of 50. The status says failed with the
    advice, the intervals are NaN (null in the JSON), the summary shows none."""
    result = banana_posterior(8, 1, 500)
    assert result.ess < MIN_ESS and result.sampling_failed and not result.converged
    assert result.status.startswith("failed: effective sample size")
    for words in ("< 50", "samples_per_round", "max_rounds", "inflation", "identification"):
        assert words in result.status, (words, result.status)
    assert np.all(np.isnan(result.credible_intervals(0.9)))
    assert np.all(np.isfinite(result.quantiles([0.05, 0.95])))  # the raw quantiles stay available
    info = json.loads(json.dumps(result.to_dict(), allow_nan=False))
    assert info["sampling_failed"] and info["interval_90"] == [[None, None], [None, None]]
    assert "no credible intervals" in result.summary() and "90 % interval" not in result.summary()


@pytest.mark.parametrize("target, floor", [(500.0, 50.0), (4000.0, 200.0), (30.0, 30.0)])
def test_the_floor_is_50_or_5_percent_of_the_target_never_above_it(target, floor):
    assert ess_floor(target) == floor


def test_log_scale_prior_is_log_uniform():
    """A flat likelihood: the posterior is the prior, log-uniform on [1, 100] for a log-scaled parameter,
    so its median is 10."""
    space = ParameterSpace(("k",), (1.0,), (100.0,), log=(True,))
    flat = lambda x, needed=None: np.array([0.0])  # noqa: E731
    result = posterior(flat, np.array([0.0]), np.eye(1), space, np.array([10.0]), np.eye(1) * 100.0,
                       settings=PosteriorSettings(samples_per_round=500, max_rounds=4, target_ess=1500))
    assert weighted_quantile(result.x[:, 0], result.weights, 0.5)[0] == pytest.approx(10.0, rel=0.1)


@pytest.mark.parametrize("key, value", [("defensive", 1.0), ("samples_per_round", 1), ("target_ess", 0.5),
                                        ("inflation", 0.0)])
def test_bad_settings_are_refused(key, value):
    with pytest.raises(ValueError, match=key):
        PosteriorSettings(**{key: value})


def test_weighted_quantile_of_equal_weights_is_the_median():
    values = np.array([3.0, 1.0, 2.0])
    assert weighted_quantile(values, np.ones(3) / 3, 0.5)[0] == pytest.approx(2.0)


def quadrature_log_evidence(model, y, C, space, n=(401, 501)):
    """log of the evidence on a grid: the mean over the bounds' box of the normalised Gaussian likelihood."""
    axes = [np.linspace(lo, hi, k) for lo, hi, k in zip(space.lower, space.upper, n)]
    a, b = np.meshgrid(*axes, indexing="ij")
    r = np.array([model(x) for x in np.column_stack([a.ravel(), b.ravel()])]) - y
    ll = -0.5 * np.einsum("ni,ij,nj->n", r, np.linalg.inv(C), r) - 0.5 * np.linalg.slogdet(2 * np.pi * C)[1]
    top = ll.max()
    # trapezoidal mean over the box (the prior's density is 1 / volume)
    weights = np.outer(*[np.r_[0.5, np.ones(k - 2), 0.5] / (k - 1) for k in n]).ravel()
    return top + np.log(np.sum(weights * np.exp(ll - top)))


@pytest.mark.parametrize("lower, upper", [((-2.0, -3.0), (2.0, 2.0)), ((-4.0, -6.0), (4.0, 4.0))])
def test_log_evidence_matches_quadrature_within_its_error(lower, upper):
    """The evidence of the banana model: its importance estimate against quadrature, within 3 of its stated
    errors (and that error below 0.05); a box twice as wide costs log 4 (the prior's Occam factor)."""
    space = ParameterSpace(("a", "b"), lower, upper)
    x0 = np.array([0.05, 0.4])
    settings = PosteriorSettings(samples_per_round=200, max_rounds=20, target_ess=1500)
    result = posterior(banana, BANANA_Y, BANANA_C, space, x0, gaussian_seed(banana, x0, BANANA_C), settings=settings)
    expected = quadrature_log_evidence(banana, BANANA_Y, BANANA_C, space)
    assert 0.0 < result.log_evidence_error < 0.05
    assert abs(result.log_evidence - expected) < 3 * result.log_evidence_error, (result.log_evidence, expected)
    assert result.to_dict()["log_evidence"] == pytest.approx(result.log_evidence)


def test_log_evidence_of_a_linear_model_is_the_closed_form():
    """y = A x + noise, a box far wider than the posterior: Z = |2 pi C|^-1/2 |2 pi (A^T C^-1 A)^-1|^1/2
    exp(-chi2_min / 2) / volume."""
    A = np.array([[1.0, 0.5], [0.2, 1.0], [1.0, -1.0], [0.3, 0.3]])
    C = np.diag([0.1, 0.2, 0.15, 0.1]) ** 2
    y = A @ np.array([0.3, -0.2]) + np.array([0.05, -0.1, 0.02, 0.0])
    space = ParameterSpace(("a", "b"), (-3.0, -3.0), (3.0, 3.0))
    F = A.T @ np.linalg.solve(C, A)
    x_hat = np.linalg.solve(F, A.T @ np.linalg.solve(C, y))
    r = y - A @ x_hat
    expected = (-0.5 * r @ np.linalg.solve(C, r) - 0.5 * np.linalg.slogdet(2 * np.pi * C)[1]
                + 0.5 * np.linalg.slogdet(2 * np.pi * np.linalg.inv(F))[1] - np.log(36.0))
    settings = PosteriorSettings(samples_per_round=300, max_rounds=10, target_ess=2000)
    result = posterior(lambda x, needed=None: A @ x, y, C, space, x_hat, np.linalg.inv(F), settings=settings)
    assert abs(result.log_evidence - expected) < max(3 * result.log_evidence_error, 0.02), (result.log_evidence, expected)
