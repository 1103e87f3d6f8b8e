import numpy as np
import pytest
from scipy.integrate import quad

from fracid.fem.material.cohesive import (
    CohesiveParameters,
    cohesive_traction,
    dissipated_energy_density,
    hordijk_stress,
    hordijk_tangent,
    normalised_area,
)

HORDIJK = (3.0, 6.93)
SHAPES = [HORDIJK, (1.0, 3.0), (5.0, 10.0)]


@pytest.mark.parametrize("c1, c2", SHAPES)
def test_area_under_the_law_is_the_fracture_energy(c1, c2):
    p = CohesiveParameters(ft=2.5, Gf=0.08, c1=c1, c2=c2)
    ft, wc, _, _ = p.law()
    # independent of the closed form used for wc: adaptive quadrature of the stress itself
    area, _ = quad(lambda w: float(hordijk_stress(w, ft, wc, c1, c2)), 0.0, wc, epsabs=0.0, epsrel=1e-10, limit=200)
    assert area == pytest.approx(p.Gf, rel=1e-3)
    # the closed-form partial area agrees with quadrature along the curve, not just at the end
    for x in (0.05, 0.3, 0.8):
        partial, _ = quad(lambda w: float(hordijk_stress(w, ft, wc, c1, c2)), 0.0, x * wc, epsrel=1e-12)
        assert ft * wc * normalised_area(x, c1, c2) == pytest.approx(partial, rel=1e-9)


def test_critical_opening_of_hordijk_constants():
    p = CohesiveParameters()
    assert p.wc == pytest.approx(5.136 * p.Gf / p.ft, rel=1e-3)
    # wc scales as Gf / ft
    q = p.replace(ft=2 * p.ft, Gf=3 * p.Gf)
    assert q.wc == pytest.approx(1.5 * p.wc, rel=1e-14)


def test_end_values_and_sign_of_the_law():
    p = CohesiveParameters()
    ft, wc, c1, c2 = p.law()
    assert hordijk_stress(0.0, *p.law()) == pytest.approx(ft, rel=1e-15)
    # continuous at wc: the formula tends to 0 from the left and the cut-off gives 0 from wc on
    below_wc = np.nextafter(wc, 0.0)
    assert abs(hordijk_stress(below_wc, *p.law())) <= 1e-12 * ft
    assert hordijk_stress(wc, *p.law()) == 0.0
    np.testing.assert_array_equal(hordijk_stress([wc, 2 * wc, 1e3], *p.law()), 0.0)
    # closure carries no cohesive traction (contact is the caller's business)
    np.testing.assert_array_equal(hordijk_stress([-1e-3, -1.0], *p.law()), 0.0)
    # with Hordijk's constants the law does not dip below zero before wc, and decreases throughout
    w = np.linspace(0.0, wc, 100_001)
    sigma = hordijk_stress(w, *p.law())
    assert np.all(sigma >= 0.0)
    assert np.all(np.diff(sigma) < 0.0)
    # it reaches zero with the finite slope -141 exp(-6.93) ft / wc (a kink, not a smooth tail)
    assert hordijk_tangent(below_wc, *p.law()) == pytest.approx((81 - 6.93 * 28 - 28) * np.exp(-6.93) * ft / wc)


@pytest.mark.parametrize("c1, c2", SHAPES)
def test_tangent_matches_central_differences(c1, c2):
    ft, wc = 3.0, 0.2
    w = np.linspace(0.0, wc, 401)[1:-1]
    h = 1e-7 * wc
    numeric = (hordijk_stress(w + h, ft, wc, c1, c2) - hordijk_stress(w - h, ft, wc, c1, c2)) / (2 * h)
    np.testing.assert_allclose(hordijk_tangent(w, ft, wc, c1, c2), numeric, rtol=1e-6, atol=1e-9 * ft / wc)
    assert np.all(hordijk_tangent([-0.1, wc, 2 * wc], ft, wc, c1, c2) == 0.0)


def test_traction_tangent_matches_differences_when_loading_and_unloading():
    p = CohesiveParameters()
    law = p.law()
    wc = p.wc
    h = 1e-7 * wc

    def traction(w, w_max):
        return cohesive_traction(w, w_max, *law)

    # loading: w beyond the history, which moves along
    w_max = np.linspace(0.0, 0.9 * wc, 50)
    w = w_max + np.linspace(0.01, 0.09, 50) * wc
    sigma, tangent, w_max_new = traction(w, w_max)
    np.testing.assert_array_equal(w_max_new, w)
    np.testing.assert_allclose(sigma, hordijk_stress(w, *law), rtol=1e-15)
    numeric = (traction(w + h, w_max)[0] - traction(w - h, w_max)[0]) / (2 * h)
    np.testing.assert_allclose(tangent, numeric, rtol=1e-6)
    # unloading: w below the history, which stays; secant to the origin
    w_max = np.linspace(0.05, 1.2, 50) * wc
    w = w_max * np.linspace(0.1, 0.9, 50)
    sigma, tangent, w_max_new = traction(w, w_max)
    np.testing.assert_array_equal(w_max_new, w_max)
    np.testing.assert_allclose(sigma, hordijk_stress(w_max, *law) * w / w_max, rtol=1e-14)
    numeric = (traction(w + h, w_max)[0] - traction(w - h, w_max)[0]) / (2 * h)
    np.testing.assert_allclose(tangent, numeric, rtol=1e-6, atol=1e-12)
    assert np.all(sigma[w_max >= wc] == 0.0)
    # closure after cracking: no traction, no stiffness, history kept
    sigma, tangent, w_max_new = traction(np.array([-1e-3]), np.array([0.3 * wc]))
    assert sigma[0] == 0.0 and tangent[0] == 0.0 and w_max_new[0] == 0.3 * wc


def test_reloading_retraces_the_secant_and_rejoins_the_envelope():
    p = CohesiveParameters()
    law = p.law()
    w_max = 0.2 * p.wc
    s_peak = hordijk_stress(w_max, *law)
    sigma, _, hist = cohesive_traction(0.5 * w_max, w_max, *law)
    assert sigma == pytest.approx(0.5 * s_peak) and hist == w_max
    sigma, _, hist = cohesive_traction(w_max, w_max, *law)  # back on the envelope: neutral loading
    assert sigma == pytest.approx(s_peak) and hist == w_max


def test_dissipated_energy():
    p = CohesiveParameters()
    law, wc = p.law(), p.wc
    assert dissipated_energy_density(wc, *law) == pytest.approx(p.Gf, rel=1e-3)
    assert dissipated_energy_density(3 * wc, *law) == pytest.approx(p.Gf, rel=1e-12)
    assert dissipated_energy_density(0.0, *law) == 0.0
    w_max = np.linspace(0.0, wc, 2001)
    d = dissipated_energy_density(w_max, *law)
    assert np.all(np.diff(d) > 0.0)
    # against its definition: area under the envelope minus the recovered triangle
    x = 0.4 * wc
    area, _ = quad(lambda w: float(hordijk_stress(w, *law)), 0.0, x, epsrel=1e-12)
    assert dissipated_energy_density(x, *law) == pytest.approx(area - 0.5 * x * hordijk_stress(x, *law), rel=1e-9)


@pytest.mark.parametrize(
    "name, value, range_text",
    [("E", 0.0, "0 < E"), ("nu", 0.5, "-1 < nu < 0.5"), ("ft", -1.0, "0 < ft"), ("Gf", 0.0, "0 < Gf"),
     ("c1", -0.1, "0 <= c1"), ("c2", 0.0, "0 < c2"), ("Gf", float("nan"), "0 < Gf")],
)
def test_validation_names_field_value_and_range(name, value, range_text):
    with pytest.raises(ValueError) as err:
        CohesiveParameters(**{name: value})
    message = str(err.value)
    assert repr(name) in message and repr(value) in message and range_text in message


def test_validation_of_the_shape_and_of_unknown_or_non_numeric_input():
    with pytest.raises(ValueError, match="'c1' = 10.0, 'c2' = 2.0"):
        CohesiveParameters(c1=10.0, c2=2.0)  # the law's area is negative
    with pytest.raises(ValueError, match="'ft' = 'x' is not a number; valid range: 0 < ft"):
        CohesiveParameters(ft="x")
    with pytest.raises(ValueError, match="unknown parameter"):
        CohesiveParameters().replace(fc=30.0)
    assert CohesiveParameters(c1=0.0).c1 == 0.0  # the closed end of c1's range is valid


def test_replace_array_round_trip_names_units_and_bounds():
    p = CohesiveParameters()
    q = p.replace(Gf=0.15)
    assert q.Gf == 0.15 and p.Gf == 0.1 and q.ft == p.ft
    assert q.wc == pytest.approx(1.5 * p.wc)
    assert CohesiveParameters.from_array(q.as_array()) == q
    with pytest.raises(ValueError, match="expected a vector of 6"):
        CohesiveParameters.from_array([1.0, 2.0])
    assert CohesiveParameters.names() == ("E", "nu", "ft", "Gf", "c1", "c2")
    assert CohesiveParameters.units()["Gf"] == "N/mm" and CohesiveParameters.units()["ft"] == "MPa"
    names = ["nu", "c1", "c2", "Gf"]
    lower, upper = CohesiveParameters.valid_bounds(names)
    assert lower.shape == upper.shape == (4,)
    assert lower[1] == 0.0 and lower[2] > 0.0 and np.isinf(upper[3])
    assert -1.0 < lower[0] < -1.0 + 1e-6 and 0.5 - 1e-6 < upper[0] < 0.5
    # clipped values pass validation (the ends of each range that are finite)
    CohesiveParameters(nu=lower[0], c1=0.0, c2=lower[2], Gf=lower[3])  # c1 = 3 with c2 -> 0 has a negative area
    CohesiveParameters(nu=upper[0])
    empty = CohesiveParameters.valid_bounds([])
    assert empty[0].shape == empty[1].shape == (0,)
