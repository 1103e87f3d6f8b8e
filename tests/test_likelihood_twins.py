"""The twins of issue 28: the mesh's discretisation error (data of a fine bar identified on a coarse one) and the
model's own error (a cohesive crack's curve fitted by gradient damage), each identified without and with its
term. The numbers measured are printed (pytest -s) and stated beside each assertion."""

import numpy as np
import pytest
from scipy.stats import chi2

import fracid
from fracid.data.covariance_matrix import Diagonal
from fracid.fem.material.cohesive import CohesiveParameters
from fracid.fem.material.parameters import DamageParameters
from fracid.fem.path.path_following import StepOptions
from fracid.inverse.core.forward_operator import ForwardOperator, Observation
from fracid.inverse.core.space import ParameterSpace
from fracid.inverse.likelihood.settings import DiscretisationError
from fracid.inverse.likelihood.discretisation import ORDER_RANGE
from fracid.inverse.methods.strategy import identify
from fracid.models import CohesiveCrackModel, DamageModel
from fracid.specimens import DogBone

BAR_POINTS = np.linspace(0.004, 0.03, 16)  # end displacement [mm]: pre-peak, peak and softening
BAR_TRUTH = np.array([2.0, 250.0])  # c [mm^2], beta [-]; l = sqrt(2 c) = 2 mm
BAR_SPACE = ParameterSpace(("c", "beta"), [0.5, 100.0], [4.0, 500.0])
BAR_SETTINGS = {"n": 16, "k": 4, "groups": [range(i, i + 4) for i in range(0, 16, 4)], "progress": False}


def _bar(n_elements):
    return ForwardOperator([Observation(fracid.BarWithWeakZone(n_elements=n_elements), BAR_POINTS)],
                           fracid.DamageParameters(), ("c", "beta"))


def _distance(result, truth):
    """(the truth's distance from the estimate in std per parameter, its squared Mahalanobis distance)."""
    d = np.asarray(result.x) - truth
    return d / result.std, float(d @ np.linalg.solve(result.C, d))


def test_fine_mesh_data_identified_on_a_coarse_mesh():
    """Data of 320 elements (h = 0.31 mm, std 0.2 % of the peak), identified with 40 (h = 2.5 mm): the mesh's error
    (2 % of the peak in the tail) is 10 times the std. Measured: without the term beta's truth lies 4.5 std away
    (c 2.6 std), the squared Mahalanobis distance 813 (99 % of chi^2(2): 9.21); with it 0.61 (c 0.25 and beta
    0.16 std), the stds 2 and 3 times wider; the mesh's std 10.4 times the measurement's."""
    y = _bar(320)(BAR_TRUTH).y
    C = Diagonal(np.full(y.size, (0.002 * np.abs(y).max()) ** 2))
    coarse = _bar(40)
    without = identify(coarse, y, C, BAR_SPACE, **BAR_SETTINGS)
    with_term = identify(coarse, y, C, BAR_SPACE, discretisation_error="richardson", **BAR_SETTINGS)
    z0, m0 = _distance(without, BAR_TRUTH)
    z1, m1 = _distance(with_term, BAR_TRUTH)
    print(f"\nwithout: x {without.x}, std {without.std}, z {z0}, Mahalanobis^2 {m0:.3g}"
          f"\nwith:    x {with_term.x}, std {with_term.std}, z {z1}, Mahalanobis^2 {m1:.3g}")
    limit = chi2.ppf(0.99, 2)
    assert np.max(np.abs(z0)) > 3.0 and m0 > limit  # shown: the measurement std alone is too narrow
    assert m1 < limit  # the truth inside the 99 % joint region
    terms = with_term.error_terms
    row = terms["blocks"][0]
    assert row["discretisation_std"] > 5 * row["measurement_std"]  # measured 10.4 times
    assert terms["discretisation"]["orders"] == [1.0] and terms["runs"]["computed"] >= 1
    np.testing.assert_allclose(with_term.std_exp, np.sqrt(C.diag()))  # the measurement's std is kept
    assert any("mesh's error dominates" in note for note in with_term.notes)
    # the order observed from a third mesh (20 elements): pre-asymptotic in the tail (measured 0.55), the truth
    # inside the region too (measured 0.17)
    observed = identify(coarse, y, C, BAR_SPACE, discretisation_error=DiscretisationError(observed_order=True),
                        **BAR_SETTINGS)
    order = observed.error_terms["discretisation"]["observed"][0]
    print(f"observed order {order:.3g}: Mahalanobis^2 {_distance(observed, BAR_TRUTH)[1]:.3g}")
    assert ORDER_RANGE[0] <= order < 1.0 and _distance(observed, BAR_TRUTH)[1] < limit


DOGBONE = DogBone(size=50.0, h_fine=5.0)
DOGBONE_POINTS = np.linspace(0.002, 0.04, 20)  # elongation [mm]
STEPS = StepOptions(maximum=DOGBONE_POINTS[-1] / 30)
GRADIENT_SPACE = ParameterSpace(("kappa_i", "beta"), [3e-5, 100.0], [3e-4, 3000.0], log=(False, True))


@pytest.fixture(scope="module")
def executor():
    from fracid.runtime.executors import make_executor

    with make_executor(2) as pool:
        yield pool


@pytest.fixture(scope="module")
def cohesive_fitted_by_gradient_damage(executor):
    """The curve of a cohesive crack (ft 3 MPa, Gf 0.1 N/mm) with a std of 0.5 % of its peak, fitted by gradient
    damage (c = 10 mm^2 fixed, kappa_i and beta identified) without and with the model error."""
    cohesive = CohesiveParameters(E=30000.0, nu=0.2, ft=3.0, Gf=0.1)
    source = ForwardOperator([Observation(DOGBONE, DOGBONE_POINTS)], cohesive, ("ft",), model=CohesiveCrackModel(),
                             steps=STEPS)
    y = source(np.array([cohesive.ft])).y
    C = Diagonal(np.full(y.size, (0.005 * np.abs(y).max()) ** 2))
    gradient = ForwardOperator([Observation(DOGBONE, DOGBONE_POINTS)], DamageParameters(E=30000.0, c=10.0),
                               GRADIENT_SPACE.names, model=DamageModel("gradient"), steps=STEPS)
    settings = {"n": 16, "k": 4, "max_iterations": 6, "progress": False, "executor": executor,
                "groups": [np.arange(i, min(i + 7, y.size)) for i in range(0, y.size, 7)]}
    return (y, C, identify(gradient, y, C, GRADIENT_SPACE, **settings),
            identify(gradient, y, C, GRADIENT_SPACE, model_error="variance", **settings))


def test_model_error_of_the_wrong_model_matches_its_misfit(cohesive_fitted_by_gradient_damage):
    """Measured: RMS misfit 411 N (4.7 % of the peak), sigma_m 431 N (ratio 1.05), over a measurement std of
    43.3 N; the stds of kappa_i and beta 10.0 times wider, as the total std (433 N) over the measurement's."""
    y, C, without, with_error = cohesive_fitted_by_gradient_damage
    rms = float(np.sqrt(np.mean((with_error.y_fit - y) ** 2)))
    row = with_error.error_terms["blocks"][0]
    sigma = row["model_error_std"]
    widening = with_error.std / without.std
    print(f"\nRMS misfit {rms:.4g} ({100 * rms / np.abs(y).max():.3g} % of the peak), sigma_m {sigma:.4g}, "
          f"total std {row['total_std']:.4g}, measurement std {row['measurement_std']:.4g}; stds {without.std} -> "
          f"{with_error.std} (x {widening})")
    assert sigma == pytest.approx(rms, rel=0.2)
    assert rms > 5 * row["measurement_std"]  # the model's error, not the noise
    np.testing.assert_allclose(widening, row["total_std"] / row["measurement_std"], rtol=0.2)
    assert with_error.error_terms["fixed_point"] and with_error.converged
    assert any("model's own error dominates" in note for note in with_error.notes)


@pytest.mark.slow  # 40 s of the 300 draws' runs: the fast loop (-m "not slow") leaves it out
def test_posterior_with_the_model_error_marginalised(cohesive_fitted_by_gradient_damage, executor):
    """The posterior on the exact model, sigma_m integrated out per draw (300 draws, ESS 205): its stds those of the
    widened Gaussian (measured: 7 % and 6 % wider), ten times the measurement's alone; sigma_m's 90 % interval
    [331, 571] N holds the identified 431 N."""
    from types import SimpleNamespace

    from fracid.inverse.sampling.posterior import PosteriorSettings
    from fracid.inverse.sampling.sample import sample_posterior

    y, C, without, with_error = cohesive_fitted_by_gradient_damage
    gradient = ForwardOperator([Observation(DOGBONE, DOGBONE_POINTS)], DamageParameters(E=30000.0, c=10.0),
                               GRADIENT_SPACE.names, model=DamageModel("gradient"), steps=STEPS)
    settings = PosteriorSettings(samples_per_round=100, max_rounds=3, target_ess=150, seed=1)
    post = sample_posterior(gradient, SimpleNamespace(y=y, covariance=C), GRADIENT_SPACE, with_error, settings,
                            executor=executor, progress=False)
    sigma = post.model_error[0]
    print(f"\nposterior: {post.summary()}\nstd {post.std} (Gaussian with the term {with_error.std}, without "
          f"{without.std}); sigma_m {sigma['mean']:.4g} {sigma['interval_90']}")
    np.testing.assert_allclose(post.std, with_error.std, rtol=0.3)
    assert np.all(post.std > 5 * without.std)
    low, high = sigma["interval_90"]
    assert low < with_error.error_terms["blocks"][0]["model_error_std"] < high
