"""Traction-separation laws as objects (fracid.fem.material.tsl, fracid.fem.material.laws): Hordijk's, linear and bilinear
softening; the secant unloading and the scaled law built on any law; composed parameter classes; the
cohesive crack and the crack band running the new laws, with their exact sensitivities."""

import pickle

import numpy as np
import pytest
from scipy.integrate import quad

from fracid.fem.material.cohesive import CohesiveParameters, hordijk_stress, hordijk_tangent
from fracid.fem.material.laws import (TRACTION_SEPARATION_LAWS, BilinearSoftening, BilinearSofteningParameters, HordijkLaw,
                             LinearSoftening, LinearSofteningParameters)
from fracid.fem.material.ranges import ELASTIC, Field, ParameterRange, compose
from fracid.fem.material.tsl import ScaledLaw, secant_unloading, secant_unloading_parameter_derivatives
from fracid.models import CohesiveCrackModel, CrackBandModel
from fracid.specimens.strip import TensionStrip

from test_ddm_crack_models import _beam, _curve, _options

LAWS = {
    "hordijk": (HordijkLaw(), CohesiveParameters(E=36000.0, ft=3.2, Gf=0.09, c1=2.5, c2=6.0)),
    "linear": (LinearSoftening(), LinearSofteningParameters(E=36000.0, ft=3.2, Gf=0.09)),
    "bilinear": (BilinearSoftening(), BilinearSofteningParameters(E=36000.0, ft=3.2, Gf=0.09, psi=0.3, chi=0.15)),
}
REL_STEP = 1e-6


def _kinks(law, params):
    """Openings where the law has a kink [mm]: 0, wc and the bilinear law's w1."""
    wc = law.critical_opening(params)
    return [0.0, wc] + ([params.chi * wc] if law.name == "bilinear" else [])


def _smooth_openings(law, params, n=37):
    """Openings in (-0.1 wc, 1.2 wc) at least 1e-4 wc away from every kink."""
    wc = law.critical_opening(params)
    w = np.linspace(-0.1, 1.2, n) * wc + 1e-3 * wc
    return w[np.min(np.abs(w[:, None] - np.array(_kinks(law, params))[None, :]), axis=1) > 1e-4 * wc]


def test_linear_and_bilinear_tractions_against_hand_values():
    linear = LinearSofteningParameters(ft=3.0, Gf=0.12)  # wc = 2 Gf / ft = 0.08 mm
    law = LinearSoftening()
    assert law.critical_opening(linear) == pytest.approx(0.08, rel=1e-15)
    sigma, slope = law.traction(np.array([-0.01, 0.0, 0.02, 0.04, 0.08, 0.2]), linear)
    np.testing.assert_allclose(sigma, [0.0, 3.0, 2.25, 1.5, 0.0, 0.0], rtol=1e-14, atol=0.0)
    np.testing.assert_allclose(slope, [0.0, -37.5, -37.5, -37.5, 0.0, 0.0], rtol=1e-14)
    # Petersson's bilinear law (the defaults): sigma1 = ft / 3 at w1 = 0.8 Gf / ft, wc = 3.6 Gf / ft
    petersson = BilinearSofteningParameters(ft=3.0, Gf=0.12)
    law = BilinearSoftening()
    wc, w1 = law.critical_opening(petersson), 0.8 * 0.12 / 3.0
    assert wc == pytest.approx(3.6 * 0.12 / 3.0, rel=1e-14)
    sigma, slope = law.traction(np.array([0.0, 0.5 * w1, w1, 0.5 * (w1 + wc), wc]), petersson)
    np.testing.assert_allclose(sigma, [3.0, 2.0, 1.0, 0.5, 0.0], rtol=1e-13, atol=1e-15)
    np.testing.assert_allclose(slope[:2], -2.0 / w1, rtol=1e-13)
    np.testing.assert_allclose(slope[2:4], -1.0 / (wc - w1), rtol=1e-13)  # w1 on the second branch
    assert law.steepest_slope(petersson) == pytest.approx(2.0 / w1, rel=1e-13)
    assert law.strength(petersson) == 3.0 and law.scales(petersson) == {"strain": 3.0 / 30000.0, "opening": wc}


def test_hordijk_law_object_is_the_hordijk_functions_bit_for_bit():
    p = CohesiveParameters()
    law = HordijkLaw()
    w = np.linspace(-0.01, 1.2, 301) * p.wc
    sigma, slope = law.traction(w, p)
    np.testing.assert_array_equal(sigma, hordijk_stress(w, *p.law()))
    np.testing.assert_array_equal(slope, hordijk_tangent(w, *p.law()))
    assert law.critical_opening(p) == p.wc and law.critical_opening(p) * p.ft / p.Gf == pytest.approx(5.136, abs=1e-3)
    assert law.scales(p) == {"strain": p.ft / p.E, "opening": p.wc}


@pytest.mark.parametrize("name", sorted(LAWS))
def test_area_under_the_law_is_gf(name):
    law, params = LAWS[name]
    wc = law.critical_opening(params)
    area, _ = quad(lambda w: float(law.traction(w, params)[0]), 0.0, 1.5 * wc, points=_kinks(law, params),
                   epsabs=0.0, epsrel=1e-12, limit=200)
    assert area == pytest.approx(params.Gf, rel=1e-10)


@pytest.mark.parametrize("name", sorted(LAWS))
def test_slope_matches_central_differences(name):
    law, params = LAWS[name]
    w = _smooth_openings(law, params)
    h = 1e-7 * law.critical_opening(params)
    sigma, slope = law.traction(w, params)
    fd = (law.traction(w + h, params)[0] - law.traction(w - h, params)[0]) / (2 * h)
    np.testing.assert_allclose(slope, fd, rtol=1e-6, atol=1e-8 * params.ft / law.critical_opening(params))
    assert np.all(sigma[w < 0] == 0.0) and np.all(slope[w >= law.critical_opening(params)] == 0.0)
    assert law.steepest_slope(params) >= np.max(np.abs(slope)) * (1 - 1e-3)


@pytest.mark.parametrize("name", sorted(LAWS))
def test_every_parameter_derivative_matches_central_differences(name):
    law, params = LAWS[name]
    w = _smooth_openings(law, params)
    rates = law.parameter_derivatives(w, params)
    own = set(params.names()) - {"E", "nu"}
    assert set(rates) == own  # the law's parameters, all of them
    for parameter, exact in rates.items():
        value = getattr(params, parameter)
        step = REL_STEP * value
        plus, minus = (law.traction(w, params.replace(**{parameter: value + s * step}))[0] for s in (1, -1))
        fd = (plus - minus) / (2 * step)
        np.testing.assert_allclose(exact, fd, rtol=1e-6, atol=1e-6 * np.max(np.abs(fd)), err_msg=parameter)
        assert np.max(np.abs(exact)) > 0.0, parameter
    # the strength's derivatives are the traction's at w = 0: d ft / d x = (1 for ft, 0 else)
    at_zero = law.parameter_derivatives(np.zeros(1), params)
    assert {k: float(v[0]) for k, v in at_zero.items()} == {k: (1.0 if k == "ft" else 0.0) for k in own}


def test_the_registry_names_every_law_with_its_parameter_class():
    assert set(TRACTION_SEPARATION_LAWS) == {"hordijk", "linear", "bilinear"}
    for name, cls in TRACTION_SEPARATION_LAWS.items():
        assert cls.name == name and cls.parameters().names()[:2] == ("E", "nu")


def test_scaled_law_is_the_strength_imperfection_at_equal_energy():
    law, params = LAWS["bilinear"]
    a = np.array([0.8, 1.0, 1.25])
    scaled = ScaledLaw(law, params, stress=a, opening=a)
    wc = law.critical_opening(params)
    np.testing.assert_allclose(scaled.strength(), a * params.ft)
    np.testing.assert_allclose(scaled.opening_scale(), wc / a)
    for k in range(3):  # each point's law has the area Gf
        one = ScaledLaw(law, params, a[k], a[k])
        area, _ = quad(lambda w: float(one.traction(w)[0]), 0.0, wc / a[k], points=[params.chi * wc / a[k]],
                       epsrel=1e-12)
        assert area == pytest.approx(params.Gf, rel=1e-10)
    w = np.array([0.1, 0.5, 0.9]) * wc / a
    sigma, slope = scaled.traction(w)
    h = 1e-7 * wc
    np.testing.assert_allclose(slope, (scaled.traction(w + h)[0] - scaled.traction(w - h)[0]) / (2 * h), rtol=1e-6)
    plus = ScaledLaw(law, params.replace(Gf=params.Gf * (1 + REL_STEP)), a, a).traction(w)[0]
    minus = ScaledLaw(law, params.replace(Gf=params.Gf * (1 - REL_STEP)), a, a).traction(w)[0]
    np.testing.assert_allclose(scaled.parameter_derivatives(w)["Gf"], (plus - minus) / (2 * REL_STEP * params.Gf),
                               rtol=1e-6)
    with pytest.raises(ValueError, match="positive"):
        ScaledLaw(law, params, stress=0.0)


def test_secant_unloading_on_any_law_and_its_parameter_derivatives():
    law, params = LAWS["linear"]
    wc = law.critical_opening(params)
    envelope = lambda v, p=params: law.traction(v, p)  # noqa: E731
    w = np.array([-0.1, 0.2, 0.3, 0.1, 0.45, 1.3]) * wc
    w_max = np.array([0.5, 0.1, 0.3, 0.4, 0.6, 0.0]) * wc  # closed, loading, neutral, unloading x2, open
    sigma, tangent, history = secant_unloading(w, w_max, envelope)
    np.testing.assert_array_equal(history, np.maximum(w, w_max))
    secant = law.traction(w_max[3:5], params)[0] / w_max[3:5]
    np.testing.assert_allclose(sigma, [0.0, *law.traction(w[1:3], params)[0], *(secant * w[3:5]), 0.0], rtol=1e-14)
    np.testing.assert_allclose(tangent[3:5], secant, rtol=1e-14)
    rates, d_w_max = secant_unloading_parameter_derivatives(w, w_max, envelope,
                                                            lambda v: law.parameter_derivatives(v, params))
    for name in ("ft", "Gf"):
        value = getattr(params, name)
        step = REL_STEP * value
        plus, minus = (secant_unloading(w, w_max, lambda v, p=params.replace(**{name: value + s * step}):
                                        law.traction(v, p))[0] for s in (1, -1))
        np.testing.assert_allclose(rates[name], (plus - minus) / (2 * step), rtol=1e-6, atol=1e-9)
    h = 1e-7 * wc
    fd = (secant_unloading(w, w_max + h, envelope)[0] - secant_unloading(w, w_max - h, envelope)[0]) / (2 * h)
    np.testing.assert_allclose(d_w_max[[0, 3, 4, 5]], fd[[0, 3, 4, 5]], rtol=1e-6, atol=1e-9)
    assert np.all(d_w_max[[0, 1, 2, 5]] == 0.0)


# ------------------------------------------------------------------------------------------------
# composed parameter classes


def test_composed_parameter_classes_have_fields_ranges_units_and_docstrings_in_order():
    for cls, names in ((LinearSofteningParameters, ("E", "nu", "ft", "Gf")),
                       (BilinearSofteningParameters, ("E", "nu", "ft", "Gf", "psi", "chi"))):
        assert cls.names() == names and cls.units()["Gf"] == "N/mm" and cls.units()["E"] == "MPa"
        p = cls()
        assert pickle.loads(pickle.dumps(p)) == p  # found again by module and name (process pools, the run store)
        assert cls.__module__ == "fracid.fem.material.laws" and cls.__qualname__ == cls.__name__
        assert "Parameters\n----------\nE : float\n    Young's modulus of the bulk [MPa], 0 < E." in cls.__doc__
        with pytest.raises(ValueError, match=r"parameter 'ft' = -1.0 is out of range; valid range: 0 < ft"):
            p.replace(ft=-1.0)
        with pytest.raises(AttributeError):
            p.ft = 2.0  # frozen
    assert BilinearSofteningParameters().psi == pytest.approx(1 / 3) and "0 < chi < 1" in BilinearSofteningParameters.__doc__


def test_compose_defaults_checks_and_refusals():
    rate = (Field("c", 1.0, ParameterRange(0.0, False, None, False, "mm^2"), "Gradient parameter"),)

    def positive_sum(p):
        if p.E * p.c > 1e6:
            raise ValueError(f"E c = {p.E * p.c:g} too large")

    Composed = compose("Composed", ELASTIC, rate, defaults={"E": 20000.0}, check=positive_sum, summary="A test set.")
    assert Composed().E == 20000.0 and Composed.names() == ("E", "nu", "c") and Composed.__doc__.startswith("A test set.")
    assert Composed.valid_bounds(["c"])[0][0] > 0.0
    with pytest.raises(ValueError, match="E c = 2e\\+06 too large"):
        Composed(c=100.0)
    with pytest.raises(ValueError, match=r"parameter\(s\) \['E', 'nu'\] defined by more than one part"):
        compose("Twice", ELASTIC, ELASTIC)
    with pytest.raises(ValueError, match=r"defaults for unknown parameter\(s\) \['kappa'\]"):
        compose("Unknown", ELASTIC, defaults={"kappa": 1.0})
    with pytest.raises(TypeError, match="Field"):
        compose("Bad", [("E", 1.0)])


# ------------------------------------------------------------------------------------------------
# the formulations with the new laws


@pytest.mark.parametrize("model_class", [CohesiveCrackModel, CrackBandModel], ids=["cohesive", "crack-band"])
def test_the_formulations_use_their_law_object(model_class):
    law, params = LAWS["bilinear"]
    model = model_class(law=law)
    assert model.parameters is BilinearSofteningParameters
    problem = model.build(_beam(), params)
    assert problem.law is law and problem.differentiable == params.names()
    assert model.scales(params)["opening"] == law.critical_opening(params)


def test_runs_of_different_laws_never_share_a_model_key():
    keys = {model(law=law).key for model in (CohesiveCrackModel, CrackBandModel) for law, _ in LAWS.values()}
    assert len(keys) == 2 * len(LAWS)


@pytest.mark.parametrize("name", sorted(LAWS))
def test_crack_band_dissipates_the_energy_of_its_law(name):
    """The tension strip opened to 0.99 wc of its weak column (strength and openings scaled by 0.98):
    the dissipated energy is the area under the law up to that opening less the triangle the crack
    would give back on secant unloading, 1 % of Gf for the linear law, whatever the element size."""
    from fracid.fem.path.path_following import follow_path

    law, params = LAWS[name]
    model = CrackBandModel(law=law)
    weak = ScaledLaw(law, params, TensionStrip().weak_factor, TensionStrip().weak_factor)
    energies = []
    for n in (11, 41):
        strip = TensionStrip(n_elements=n)
        target = model.default_target(strip, params)
        result = follow_path(model.build(strip, params), "band_opening", target, steps=strip.default_steps(target),
                             stop_force_fraction=None)
        assert result.status == "target reached"
        energies.append(result.observables["dissipated_energy"][-1] / (strip.height * strip.thickness))
    w = target  # the band's opening, all crack at 1 % of the peak stress or less
    area, _ = quad(lambda v: float(weak.traction(v)[0]), 0.0, w, points=[k / 0.98 for k in _kinks(law, params) if 0 < k / 0.98 < w],
                   epsrel=1e-12)
    expected = area - 0.5 * float(weak.traction(w)[0]) * w
    np.testing.assert_allclose(energies, expected, rtol=2e-3)
    assert expected < (0.995 if name == "linear" else 1.0) * params.Gf


def _ddm_case(law, params, n=20, fraction=0.5, rel_step=1e-5):
    """A cohesive-crack run on the coarse notched beam with its DDM derivatives, and the relative
    differences to the central differences of runs at the checkpoints (as in test_ddm_crack_models;
    the relative step 1e-5, not 1e-6: the force hardly depends on nu, whose differences then carry
    round-off of 1e-4 of their largest value, measured with the linear law: 1.5e-4 at 1e-6, 2e-5
    at 1e-5, 3e-6 at 1e-4)."""
    model, specimen = CohesiveCrackModel(law=law), _beam()
    target = fraction * model.default_target(specimen, params)
    checkpoints, options = _options(target, n)
    run = model.simulate(specimen, params, sensitivities=params.names(), **options)
    rows = np.array([int(np.argmin(np.abs(run.control - c))) for c in checkpoints])
    errors = {}
    for k, name in enumerate(params.names()):
        value = getattr(params, name)
        step = rel_step * value
        plus, minus = (model.simulate(specimen, params.replace(**{name: value + s * step}), **options) for s in (1, -1))
        for other in (plus, minus):
            assert np.array_equal(other.control, run.control), name  # the same steps in every run
        fd = (_curve(plus, "force")[rows] - _curve(minus, "force")[rows]) / (2 * step)
        errors[name] = float(np.max(np.abs(run.derivatives["force"][rows, k] - fd)) / np.max(np.abs(fd)))
    return run.force[rows], errors


@pytest.mark.slow
@pytest.mark.parametrize("name", ["linear", "bilinear"])
def test_cohesive_crack_with_the_new_laws_passes_the_peak_with_exact_sensitivities(name):
    law, params = LAWS[name]
    force, errors = _ddm_case(law, params)
    peak = int(np.argmax(force))
    assert 2 <= peak < len(force) - 5 and force[-1] < 0.75 * force[peak]  # rise, peak, softening
    print(f"\n{name} force: " + ", ".join(f"{n} {e:.1e}" for n, e in errors.items()))
    assert max(errors.values()) <= 1e-4, errors


def test_the_crack_models_declare_the_parameters_of_their_law():
    for model in (CohesiveCrackModel, CrackBandModel):
        for law, params in LAWS.values():
            assert model(law=law).differentiable == params.names()
