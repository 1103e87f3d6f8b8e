"""Size effect: Bazant's law and its fit (recovery, covariance, input checks), nominal strengths,
a series of forward runs with a failed run recorded, and the figure."""

from dataclasses import dataclass

import numpy as np
import pytest
from scipy.optimize import curve_fit

import fracid
from fracid.inverse.studies.size_effect import nominal_strength, size_effect_series, specimen_size
from fracid.inverse.studies.size_effect_law import SizeEffectFit, bazant_law, fit_size_effect
from fracid.fem.path.path_following import ConvergenceError, PathResult
from fracid.runtime.executors import make_executor
from fracid.report.figures import to_png
from fracid.report.size_effect_figure import size_effect_figure
from fracid.specimens.beam import NotchedBeam
from fracid.specimens.dogbone import DogBone

SIZES = np.array([50.0, 100.0, 200.0, 400.0, 800.0, 1600.0])  # mm
B_FT, D0 = 3.0, 200.0  # MPa, mm: D / D0 from 1/4 to 8, both asymptotes are felt
EXACT = bazant_law(SIZES, B_FT, D0)
NOISE = 0.01  # relative standard deviation of the noisy strengths


def noisy(seed: int) -> np.ndarray:
    return EXACT * (1.0 + NOISE * np.random.default_rng(seed).standard_normal(SIZES.size))


# -- the law ------------------------------------------------------------------------------------------


def test_law_limits():
    assert bazant_law(0.0, B_FT, D0) == B_FT
    assert bazant_law(3 * D0, B_FT, D0) == pytest.approx(B_FT / 2)
    huge = 1e12
    assert bazant_law(huge, B_FT, D0) == pytest.approx(B_FT * np.sqrt(D0 / huge), rel=1e-9)  # LEFM


# -- the fit ------------------------------------------------------------------------------------------


@pytest.mark.parametrize("std", [None, NOISE * EXACT])
def test_fit_recovers_exact_parameters(std):
    fit = fit_size_effect(SIZES, EXACT, std=std)
    assert fit.B_ft == pytest.approx(B_FT, rel=1e-6)
    assert fit.D0 == pytest.approx(D0, rel=1e-6)
    assert fit.residual_rms < 1e-9
    np.testing.assert_allclose(fit.predict(SIZES), EXACT, rtol=1e-9)


@pytest.mark.parametrize("seed", range(5))
@pytest.mark.parametrize("known_std", [True, False])
def test_fit_with_noise_within_three_std(seed, known_std):
    fit = fit_size_effect(SIZES, noisy(seed), std=NOISE * EXACT if known_std else None)
    assert abs(fit.B_ft - B_FT) < 3 * fit.std[0]
    assert abs(fit.D0 - D0) < 3 * fit.std[1]
    # 1 % noise determines both: a vacuous test would pass with huge standard deviations
    assert fit.std[0] < 0.05 * B_FT and fit.std[1] < 0.1 * D0


def fd_covariance(D, sigma, std, p, scaled: bool) -> np.ndarray:
    """Covariance from a central-difference Jacobian of the weighted residuals at p."""
    def residuals(q):
        return (bazant_law(D, *q) - sigma) / std

    J = np.empty((D.size, 2))
    for j in range(2):
        h = 1e-6 * p[j] * np.eye(2)[j]
        J[:, j] = (residuals(p + h) - residuals(p - h)) / (2 * h[j])
    C = np.linalg.inv(J.T @ J)
    r = residuals(p)
    return C * (r @ r) / (D.size - 2) if scaled else C


@pytest.mark.parametrize("known_std", [True, False])
def test_covariance_matches_finite_difference_jacobian(known_std):
    sigma = noisy(11)
    std = NOISE * EXACT if known_std else np.ones_like(EXACT)
    fit = fit_size_effect(SIZES, sigma, std=std if known_std else None)
    expected = fd_covariance(SIZES, sigma, std, np.array([fit.B_ft, fit.D0]), scaled=not known_std)
    np.testing.assert_allclose(fit.covariance, expected, rtol=1e-6)
    assert fit.covariance[0, 1] < 0  # a larger B_ft needs a smaller D0 to follow the large sizes
    if not known_std:  # the same convention as scipy's curve_fit(absolute_sigma=False)
        popt, pcov = curve_fit(bazant_law, SIZES, sigma, p0=[B_FT, D0])
        np.testing.assert_allclose([fit.B_ft, fit.D0], popt, rtol=1e-6)
        np.testing.assert_allclose(fit.covariance, pcov, rtol=1e-4)


def test_covariance_predicts_scatter_of_repeated_fits():
    """Monte Carlo: the scatter of 2000 fits to fresh 1 % noise is the covariance given with std."""
    rng = np.random.default_rng(2024)
    std = NOISE * EXACT
    estimates = np.array([
        [f.B_ft, f.D0]
        for f in (fit_size_effect(SIZES, EXACT + std * rng.standard_normal(SIZES.size), std=std) for _ in range(2000))
    ])
    expected = fit_size_effect(SIZES, EXACT, std=std).covariance
    # 2000 samples estimate a standard deviation to 1.6 % and this correlation (-0.92) to 0.004:
    # the tolerances are about 4 of those, while a covariance off by the residual-variance factor
    # or by a factor 2 would miss them by far
    np.testing.assert_allclose(estimates.std(axis=0), np.sqrt(np.diag(expected)), rtol=0.06)
    corr = np.corrcoef(estimates.T)[0, 1]
    assert corr == pytest.approx(expected[0, 1] / np.sqrt(expected[0, 0] * expected[1, 1]), abs=0.015)
    np.testing.assert_allclose(estimates.mean(axis=0), [B_FT, D0], rtol=0.005)  # no visible bias


@pytest.mark.parametrize("law", ["strength criterion", "LEFM"])
def test_fit_of_one_asymptote_reports_infinite_uncertainty(law):
    """Data on one asymptote do not determine D0: the fit says so instead of inventing a value."""
    sigma = np.full(SIZES.size, 2.0) if law == "strength criterion" else 2.0 * np.sqrt(10.0 / SIZES)
    fit = fit_size_effect(SIZES, sigma)
    assert fit.D0 > 1e6 * SIZES.max() if law == "strength criterion" else fit.D0 < 1e-6 * SIZES.min()
    assert np.isinf(fit.covariance).all() and np.isinf(fit.std).all()
    np.testing.assert_allclose(fit.predict(SIZES), sigma, rtol=1e-6)


def test_fit_as_dict_and_frozen():
    fit = fit_size_effect(SIZES, noisy(3), std=NOISE * EXACT)
    d = fit.as_dict()
    assert d["B_ft"] == fit.B_ft and d["D0"] == fit.D0
    assert d["std_D0"] == pytest.approx(np.sqrt(d["covariance"][1][1]))
    assert isinstance(SizeEffectFit(**{k: d[k] for k in ("B_ft", "D0", "covariance", "residual_rms")}), SizeEffectFit)
    with pytest.raises(ValueError):
        fit.covariance[0, 0] = 0.0  # read-only, as the dataclass is frozen


@pytest.mark.parametrize(
    "D, sigma, std, words",
    [
        ([50.0, 100.0], [2.0, 1.8], None, ["2 distinct", "at least 3"]),
        ([50.0, 50.0, 100.0, 100.0], [2.0, 2.1, 1.8, 1.7], None, ["2 distinct"]),
        ([50.0, -100.0, 200.0], [2.0, 1.8, 1.5], None, ["D[1]", "-100.0"]),
        ([50.0, 100.0, 200.0], [2.0, 0.0, 1.5], None, ["sigma_N[1]", "0.0"]),
        ([50.0, 100.0, 200.0], [2.0, float("nan"), 1.5], None, ["sigma_N[1]", "nan"]),
        ([50.0, 100.0, float("inf")], [2.0, 1.8, 1.5], None, ["D[2]", "inf"]),
        ([50.0, 100.0, 200.0], [2.0, 1.8], None, ["sigma_N has 2", "D has 3"]),
        ([50.0, 100.0, 200.0], [2.0, 1.8, 1.5], [0.1, 0.1], ["std has 2"]),
        ([50.0, 100.0, 200.0], [2.0, 1.8, 1.5], [0.1, -0.2, 0.1], ["std[1]", "-0.2"]),
        ([50.0, 100.0, 200.0], [2.0, 1.8, 1.5], 0.0, ["std[0]", "0.0"]),
    ],
)
def test_fit_rejects_bad_input(D, sigma, std, words):
    with pytest.raises(ValueError) as info:
        fit_size_effect(D, sigma, std=std)
    for word in words:
        assert word in str(info.value)


def test_fit_accepts_scalar_std_and_replicates():
    D = np.repeat(SIZES[:3], 2)
    fit = fit_size_effect(D, bazant_law(D, B_FT, D0), std=0.05)
    assert fit.D0 == pytest.approx(D0, rel=1e-6)


# -- nominal strength ---------------------------------------------------------------------------------


def test_nominal_strength_by_hand():
    dogbone = DogBone(size=200.0, thickness=100.0)
    assert nominal_strength(dogbone, 120_000.0) == pytest.approx(120_000.0 / (0.6 * 200.0 * 100.0))  # 10 MPa
    beam = NotchedBeam()  # D = 50, b = 50, S = 125 mm
    assert nominal_strength(beam, 1000.0) == pytest.approx(3 * 1000.0 * 125.0 / (2 * 50.0 * 50.0**2))  # 1.5 MPa
    bar = fracid.BarWithWeakZone(length=80.0, area=2.0, n_elements=20)
    np.testing.assert_allclose(nominal_strength(bar, [3.0, 5.0]), [1.5, 2.5])
    assert [specimen_size(s) for s in (dogbone, beam, bar)] == [200.0, 50.0, 80.0]


def test_nominal_strength_rejects_other_specimens():
    with pytest.raises(TypeError, match="Cylinder"):
        nominal_strength(Cylinder(), 1.0)
    with pytest.raises(TypeError, match="Cylinder"):
        size_effect_series(fracid.DamageParameters(), [small_bar(50.0), Cylinder()], progress=False)


# -- a series of forward runs ---------------------------------------------------------------------------


@dataclass(frozen=True)
class Cylinder:
    """A specimen this module does not know."""

    size: float = 100.0


class RejectingBar(fracid.BarWithWeakZone):
    """A bar whose problem cannot be built (as for parameters the model rejects)."""

    def describe(self):
        raise ValueError("this bar rejects every parameter set")


class DivergingBar(fracid.BarWithWeakZone):
    """A bar whose analysis stops after one converged step."""

    def describe(self):
        partial = PathResult("end_displacement", np.array([0.0, 1e-3]), np.array([0.0, 0.5]), {})
        raise ConvergenceError("no convergence even with the smallest step", partial)


def small_bar(length: float, cls=fracid.BarWithWeakZone):
    return cls(length=length, weak_zone_width=length / 10, n_elements=60)


def check_ok_runs(series, lengths):
    np.testing.assert_array_equal(series.sizes[: len(lengths)], lengths)
    for i in range(len(lengths)):
        control, force = series.curves[i]
        assert series.status[i] == "ok" and series.errors[i] == ""
        assert np.isfinite(series.peak_force[i]) and series.peak_force[i] > 0
        assert series.peak_force[i] == np.max(np.abs(force)) and control.size == force.size > 10
        assert series.sigma_N[i] == pytest.approx(series.peak_force[i] / 1.0)  # area 1 mm^2


def test_series_of_bars_with_failed_runs_recorded():
    params = fracid.DamageParameters()
    lengths = [50.0, 100.0]
    specimens = [small_bar(L) for L in lengths] + [small_bar(70.0, RejectingBar), small_bar(90.0, DivergingBar)]
    series = size_effect_series(params, specimens, progress=False)
    check_ok_runs(series, lengths)
    assert series.peak_force[0] == fracid.simulate(specimens[0], params).peak_force
    np.testing.assert_array_equal(series.ok, [True, True, False, False])
    assert series.status[2:] == ["failed", "failed"]
    assert "ValueError" in series.errors[2] and "rejects every parameter set" in series.errors[2]
    assert "ConvergenceError" in series.errors[3]
    assert np.isnan(series.peak_force[2:]).all() and np.isnan(series.sigma_N[2:]).all()
    assert series.curves[2][0].size == 0
    np.testing.assert_array_equal(series.curves[3][1], [0.0, 0.5])  # the converged part is kept
    np.testing.assert_array_equal(series.sizes, [50.0, 100.0, 70.0, 90.0])


def test_series_in_a_process_pool_matches_serial():
    params = fracid.DamageParameters()
    specimens = [small_bar(50.0), small_bar(100.0)]
    serial = size_effect_series(params, specimens, progress=False)
    calls = []
    with make_executor(2) as pool:
        pooled = size_effect_series(params, specimens, executor=pool, progress=lambda done, total: calls.append(done))
    check_ok_runs(pooled, [50.0, 100.0])
    np.testing.assert_allclose(pooled.peak_force, serial.peak_force, rtol=1e-12)
    assert calls[-1] == 2


# -- figure ---------------------------------------------------------------------------------------------


def test_size_effect_figure_renders():
    sigma = noisy(5)
    used = SIZES < 500
    fit = fit_size_effect(SIZES[used], sigma[used])
    computed = EXACT.copy()
    computed[-1] = np.nan  # a failed run is left out
    measured = sigma.copy()
    measured[0] = np.nan  # a size not tested
    fig = size_effect_figure(SIZES, computed, fit=fit, sigma_measured=measured, measured_std=NOISE * EXACT,
                             calibrated=used)
    ax = fig.axes[0]
    assert ax.get_xscale() == ax.get_yscale() == "log"
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    assert any("calibration" in t for t in labels) and any("predicted" in t for t in labels)
    assert any("LEFM" in t for t in labels) and any("strength criterion" in t for t in labels)
    assert to_png(fig)[:8] == b"\x89PNG\r\n\x1a\n"
    assert to_png(size_effect_figure(SIZES, EXACT))[:8] == b"\x89PNG\r\n\x1a\n"


def test_size_effect_figure_checks_lengths():
    with pytest.raises(ValueError, match="calibrated has 2"):
        size_effect_figure(SIZES, EXACT, calibrated=[True, False])
