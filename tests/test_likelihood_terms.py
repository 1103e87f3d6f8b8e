"""The error terms of fracid.inverse.likelihood on problems with known answers: Richardson extrapolation of a
sequence of known order and its guard, the refined meshes, the model-error std of a linear model, its marginal
likelihood against quadrature and the posterior with it, the settings' checks."""

import numpy as np
import pytest
from scipy.integrate import quad

import fracid
from fracid.data.covariance_matrix import Diagonal
from fracid.settings.checks import SettingError
from fracid.inverse.core.space import ParameterSpace
from fracid.inverse.likelihood.correlation import block_modes
from fracid.inverse.likelihood.discretisation import ORDER_RANGE, observed_order, richardson_error
from fracid.inverse.likelihood.marginal import MarginalLikelihood
from fracid.inverse.likelihood.model_error import error_groups, estimate_sigma, with_model_error
from fracid.inverse.likelihood.settings import (DiscretisationError, ModelError, discretisation_from_config,
                                                model_error_from_config)
from fracid.inverse.sampling.posterior import PosteriorSettings, posterior
from fracid.specimens import NotchedBeam
from fracid.specimens.protocol import SpecimenDefaults, refined

T = np.linspace(0.0, 1.0, 12)
EXACT = np.sin(3 * T) + 2.0  # the mesh-converged values


def _mesh(h, order=2.0):
    """Values of a mesh of size h converging at ``order``: y_h = y + C(t) h^p."""
    return EXACT + (1.0 + T) * h**order


def test_richardson_recovers_the_error_of_a_sequence_of_known_order():
    for order in (1.0, 2.0, 3.0):
        y_c, y_h, y_f = _mesh(0.4, order), _mesh(0.2, order), _mesh(0.1, order)
        assert observed_order(y_c, y_h, y_f, 2.0) == pytest.approx(order, rel=1e-9)
        np.testing.assert_allclose(richardson_error(y_h, y_f, 2.0, order), y_h - EXACT, rtol=1e-9)
    # a nominal order 1 where the true one is 2: twice the change, 1.5 times the true error (conservative)
    np.testing.assert_allclose(richardson_error(_mesh(0.2), _mesh(0.1), 2.0, 1.0), 1.5 * (_mesh(0.2) - EXACT))


def test_the_order_is_guarded_when_not_observable():
    y = _mesh(0.2)
    assert observed_order(y, y, y, 2.0) is None  # no change between the meshes: round-off
    assert observed_order(_mesh(0.4), y, y + 1e-13, 2.0) is None
    assert observed_order(_mesh(0.4, 0.1), _mesh(0.2, 0.1), _mesh(0.1, 0.1), 2.0) == ORDER_RANGE[0]  # pre-asymptotic
    assert observed_order(_mesh(0.4, 7.0), _mesh(0.2, 7.0), _mesh(0.1, 7.0), 2.0) == ORDER_RANGE[1]
    assert observed_order(y + np.nan, y, y + 1.0, 2.0) is None


def test_refined_meshes_of_every_kind_of_size_field():
    bar = fracid.BarWithWeakZone(n_elements=40)
    assert refined(bar, 2.0).n_elements == 80 and refined(bar, 0.5).n_elements == 20
    beam = NotchedBeam(h_fine=2.0)
    assert refined(beam, 2.0).h_fine == 1.0 and refined(beam, 2.0).h_coarse == beam.h_coarse
    from fracid.specimens import WedgeSplitting

    assert refined(WedgeSplitting(h_fine=10.0, h_coarse=40.0), 2.0).h_fine == 5.0  # through its resolution's field
    from fracid.specimens import TensionStrip

    strip = TensionStrip()
    assert refined(strip, 2.0).n_elements in (2 * strip.n_elements, 2 * strip.n_elements + 1)  # an odd count
    fixed = FixedMesh()
    with pytest.raises(ValueError, match="no field sets its element size"):
        refined(fixed, 2.0)


class FixedMesh(SpecimenDefaults):
    """A specimen whose mesh no field sizes (a mesh file's)."""

    def resolution(self, internal_length=None):
        from fracid.specimens.protocol import Resolution

        return Resolution("file", "mesh.msh", 1.0, "its smallest element side, 1 mm,", "")


def _linear(n, p, seed, sigma_e=1.0, sigma_m=2.0):
    rng = np.random.default_rng(seed)
    A = rng.normal(size=(n, p)) * 5.0
    y = A @ rng.normal(size=p) + rng.normal(0.0, np.hypot(sigma_e, sigma_m), n)
    x = np.linalg.lstsq(A, y, rcond=None)[0]  # the MAP of a vague prior
    return A, y, y - A @ x


def _sigma(A, y, r, settings=ModelError(prior="log-uniform", bounds=(1e-3, 10.0))):
    n = y.size
    groups = error_groups(settings, [("b", 0, n)], [], y, np.arange(n, dtype=float))
    return estimate_sigma(r, A, Diagonal(np.ones(n)), groups, 1e-12 * np.eye(A.shape[1]), settings)[0]


def test_model_error_std_of_a_linear_model_is_recovered():
    """Residuals with a known extra std 2 over a measurement std 1: recovered within 3 % from 4000 values, and
    unbiased in the variance over 200 small problems of many parameters (40 values, 10 parameters): the Laplace
    term log det(J^T C^-1 J) counts the parameters' degrees of freedom, without it the variance is 25 % low."""
    A, y, r = _linear(4000, 3, 0)
    assert _sigma(A, y, r) == pytest.approx(2.0, rel=0.03)
    assert _sigma(A, y, r, ModelError()) == pytest.approx(2.0, rel=0.03)  # the half-Cauchy prior, scale 5 % of the peak
    variances = [_sigma(*_linear(40, 10, seed)) ** 2 for seed in range(200)]
    assert np.mean(variances) == pytest.approx(4.0, rel=0.08)


def test_model_error_covariances_equal_dense_algebra():
    n, blocks = 10, [("a", 0, 4), ("b", 4, 10)]
    base, control = Diagonal(np.linspace(1.0, 2.0, n)), np.linspace(0.0, 1.0, n)
    y = np.arange(1.0, n + 1)
    groups = error_groups(ModelError(), blocks, [], y, control)
    np.testing.assert_allclose(with_model_error(base, [0.5, 2.0], groups).dense(),
                               base.dense() + np.diag([0.25] * 4 + [4.0] * 6))
    assert error_groups(ModelError(groups="quantity"), blocks, ["force", "force"], y, control).names == ["a+b"]
    bias = error_groups(ModelError(kind="bias", correlation_length=0.3), blocks, [], y, control)
    t = control[4:]
    kernel = np.exp(-0.5 * ((t[:, None] - t[None, :]) / (0.3 * (t[-1] - t[0]))) ** 2)
    np.testing.assert_allclose(with_model_error(base, [0.0, 2.0], bias).dense()[4:, 4:], base.dense()[4:, 4:] + 4 * kernel,
                               atol=1e-8)
    U = block_modes(np.arange(n, dtype=float), control, blocks, 1e6)  # a very long length: one mode per block
    assert U.shape[1] == 2 and np.allclose(np.abs(U[:, 1]), np.r_[np.zeros(4), np.arange(4.0, n)], atol=1e-6)


def test_marginal_likelihood_equals_the_integral_over_the_prior():
    n, settings = 20, ModelError(bounds=(1e-3, 2.0), scale=0.1)
    y = np.full(n, 10.0)
    groups = error_groups(settings, [("b", 0, n)], [], y, np.arange(n, dtype=float))
    base = Diagonal(np.full(n, 0.25))
    residuals = np.random.default_rng(1).normal(0.0, [[0.5], [1.3]], (2, n))
    marginal = MarginalLikelihood(base, groups, settings, centre=[1.0])
    got = marginal(residuals)

    def prior(u):  # half-Cauchy of scale 0.1 x 10 in log sigma, normalised over the bounds
        s = np.exp(u)
        return s / (1 + s**2)

    lo, hi = np.log(1e-3 * 10), np.log(2.0 * 10)
    mass = quad(prior, lo, hi)[0]
    for r, value in zip(residuals, got):
        def ratio(u):
            v = 0.25 + np.exp(2 * u)
            return np.exp(-0.5 * (r @ r / v - r @ r / 0.25) - 0.5 * n * np.log(v / 0.25)) * prior(u) / mass

        expected = np.log(quad(ratio, lo, hi, points=[np.log(np.std(r))], limit=200)[0])
        # the posterior's convention: -1/2 chi^2 of the base plus the log of this ratio of likelihoods
        assert value == pytest.approx(expected - 0.5 * r @ r / 0.25, abs=2e-3)


def test_posterior_with_the_model_error_marginalised_matches_quadrature():
    """y = a t + e with std 0.1 measured and 0.4 of model error: the sampled posterior of a (its std four times
    the measurement's alone) and of sigma_m match a quadrature over (a, sigma_m)."""
    n = 30
    t = np.linspace(0.1, 1.0, n)
    y = 2.0 * t + np.random.default_rng(3).normal(0.0, np.hypot(0.1, 0.4), n)
    settings = ModelError(bounds=(1e-3, 2.0))
    groups = error_groups(settings, [("b", 0, n)], [], y, t)
    base = Diagonal(np.full(n, 0.01))
    space = ParameterSpace(("a",), [0.0], [4.0])
    marginal = MarginalLikelihood(base, groups, settings, centre=[0.4])
    run = PosteriorSettings(samples_per_round=400, max_rounds=8, target_ess=1500)
    result = posterior(lambda x, needed=None: x[0] * t, y, base, space, [2.0], [[0.05**2]], settings=run,
                       marginal=marginal)
    a = np.linspace(0.0, 4.0, 4001)
    log_p = marginal((a[:, None] * t[None, :]) - y)
    p = np.exp(log_p - log_p.max())
    p /= p.sum()
    mean, std = p @ a, np.sqrt(p @ (a - p @ a) ** 2)
    assert result.mean[0] == pytest.approx(mean, abs=0.1 * std) and result.std[0] == pytest.approx(std, rel=0.1)
    measurement_only = 0.1 / np.sqrt(t @ t)
    assert std > 3.0 * measurement_only
    sigma = result.model_error[0]
    assert sigma["interval_90"][0] < 0.4 < sigma["interval_90"][1] and sigma["mean"] == pytest.approx(0.4, rel=0.25)


def test_settings_from_the_configuration_words_and_tables():
    assert discretisation_from_config(None) is None and discretisation_from_config("off") is None
    assert discretisation_from_config("richardson") == DiscretisationError()
    assert discretisation_from_config({"refinement": 1.5, "observed_order": True}).observed_order
    assert model_error_from_config("bias").kind == "bias" and model_error_from_config("off") is None
    assert model_error_from_config({"kind": "variance", "bounds": [0.01, 0.5]}).bounds == (0.01, 0.5)
    for raw, key in (("richard", "discretisation_error"), ({"refinement": 1.0}, "discretisation_error.refinement"),
                     ({"order": 9}, "discretisation_error.order"), ({"iterate": True}, "discretisation_error.iterate"),
                     ({"observed_order": "yes"}, "discretisation_error.observed_order")):
        with pytest.raises(SettingError) as err:
            discretisation_from_config(raw)
        assert err.value.key == key
    for raw, key in (("gaussian", "model_error"), ({"prior": "flat"}, "model_error.prior"),
                     ({"bounds": [0.5, 0.1]}, "model_error.bounds"), ({"scale": -1}, "model_error.scale"),
                     ({"iterations": 0}, "model_error.iterations")):
        with pytest.raises(SettingError) as err:
            model_error_from_config(raw)
        assert err.value.key == key
