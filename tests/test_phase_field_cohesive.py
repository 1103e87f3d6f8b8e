"""The exact 1D traction-opening law of the PF-CZM (fracid.fem.material.phase_field_cohesive).

Measured with E = 20000 MPa, ft = 2.4 MPa, Gf = 0.113 N/mm (Wu's concrete), scipy 1.17:

shape        | |area / Gf - 1| | max |sigma - target| / ft    | l = 0.5, 2, 10 mm: max rel. difference
linear       | 2e-14           | 2e-15 (exactly linear)       | 2e-16
exponential  | 2e-14           | 2.578e-3 at w = 1.74 Gf / ft | 8e-15
cornelissen  | 2e-14           | 4.934e-2 at w = 0.80 Gf / ft | 3e-15
"""

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from fracid.fem.material import phase_field_cohesive as pfc
from fracid.fem.material.phase_field import SHAPES
from fracid.fem.material.phase_field_band import ultimate_opening
from fracid.fem.material.phase_field_cohesive import (
    crack_opening,
    centre_stress,
    dissipated_energy,
    localized_cohesive_law,
    target_law,
    traction_at_opening,
)

E, FT, GF = 20000.0, 2.4, 0.113
NAMES = list(SHAPES)


# ------------------------------------------------------------------------------------------------ 1. l-independence
@pytest.mark.parametrize("shape", NAMES)
def test_law_does_not_depend_on_the_length_scale(shape):
    sh = SHAPES[shape]
    w_end = localized_cohesive_law(E, FT, GF, 2.0, *sh)[0][-1]
    openings = np.linspace(0.0, 1.0, 9)[1:] * w_end  # down to sigma ~ 1e-3 ft
    sigma = {l: traction_at_opening(openings, E, FT, GF, l, *sh) for l in (0.5, 2.0, 10.0)}
    assert np.all(sigma[2.0] > 0.9e-3 * FT)
    for l in (0.5, 10.0):
        np.testing.assert_allclose(sigma[l], sigma[2.0], rtol=1e-6, atol=0.0)
    # the same at common band-centre values, w and sigma separately
    d = np.array([0.01, 0.3, 0.7, 0.95, 0.999])
    w_ref, s_ref = localized_cohesive_law(E, FT, GF, 2.0, *sh, centre_values=d)
    for l in (0.5, 10.0):
        w, s = localized_cohesive_law(E, FT, GF, l, *sh, centre_values=d)
        np.testing.assert_allclose(w, w_ref, rtol=1e-6)
        np.testing.assert_allclose(s, s_ref, rtol=1e-6)


def test_the_phase_field_itself_does_depend_on_the_length_scale():
    """Not a vacuous check: the degradation g(d) at fixed d changes with l (a1 ~ 1 / l)."""
    g = [pfc.degradation(0.3, E, FT, GF, l, *SHAPES["linear"]) for l in (0.5, 10.0)]
    assert g[1] > 10.0 * g[0]


# ------------------------------------------------------------------------------------------- 2. initial strength
@pytest.mark.parametrize("shape", NAMES)
def test_stress_tends_to_the_strength_with_wu_initial_slope(shape):
    p, a2, a3 = SHAPES[shape]
    w, sigma = localized_cohesive_law(E, FT, GF, 2.0, p, a2, a3)
    assert w[0] == 0.0 and sigma[0] == FT
    assert np.all(np.diff(w) > 0.0) and np.all(np.diff(sigma) < 0.0)
    assert traction_at_opening(0.0, E, FT, GF, 2.0, p, a2, a3) == FT
    # sigma -> ft linearly, with the initial slope k0 that Wu's a2 = 2 (-2 k0 Gf / ft^2)^(2/3) - (p + 1/2) encodes
    k0 = -(FT**2 / (2.0 * GF)) * ((a2 + p + 0.5) / 2.0) ** 1.5
    small = np.array([1e-3, 1e-5, 1e-7]) * GF / FT
    s = traction_at_opening(small, E, FT, GF, 2.0, p, a2, a3)
    assert np.all(s < FT)
    error = np.abs((s - FT) / small / k0 - 1.0)
    # measured relative slope errors: linear ~1e-11 at all three; exponential 5e-4, 5e-6, 5e-8; cornelissen 1e-3,
    # 1e-5, 1e-7: first order in w, as from a smooth law with this initial slope
    assert error[0] < 2e-3 and error[1] < 2e-5 and error[2] < 2e-7
    assert k0 * GF / FT**2 == pytest.approx({"linear": -0.5, "exponential": -1.0, "cornelissen": -1.3546}[shape],
                                            abs=1e-4)


# ---------------------------------------------------------------------------------------------------- 3. energy
@pytest.mark.parametrize("shape", NAMES)
def test_area_under_the_law_is_the_fracture_energy(shape):
    p, a2, a3 = SHAPES[shape]
    # the whole law, tail included (measured: 2e-14 relative for all three shapes)
    assert dissipated_energy(E, FT, GF, 2.0, p, a2, a3) == pytest.approx(GF, rel=1e-9)
    # the drawn curve, down to sigma = 1e-3 ft, by the trapezoidal rule; measured area / Gf - 1:
    # linear -1.0e-6, exponential -1.94e-3 (its tail sigma ~ w^(-p / (p - 2)) = w^-5 holds sigma w / 4 ~ 2e-3 Gf),
    # cornelissen +1.2e-5
    w, sigma = localized_cohesive_law(E, FT, GF, 2.0, p, a2, a3)
    area = float(np.sum(0.5 * (sigma[1:] + sigma[:-1]) * np.diff(w)))  # trapezoidal rule
    if p > 2.0:
        assert area / GF - 1.0 == pytest.approx(-1.943e-3, abs=5e-5)
        tail = sigma[-1] * w[-1] / (p / (p - 2.0) - 1.0)  # power-law tail beyond the last point
        assert (area + tail) / GF == pytest.approx(1.0, abs=3e-5)
    else:
        assert area / GF == pytest.approx(1.0, abs=3e-5)
        assert area < GF + 1e-3 * GF and w[-1] < ultimate_opening(FT, GF, p, a2, a3)


# --------------------------------------------------------------------------------------- 4. against the nominal law
MAX_DEVIATION = {"linear": 0.0, "exponential": 2.578e-3, "cornelissen": 4.934e-2}  # max |sigma - target| / ft


@pytest.mark.parametrize("shape", NAMES)
def test_deviation_from_the_nominal_law(shape):
    sh = SHAPES[shape]
    d = np.linspace(0.0, 1.0, 401)[:-1]
    w, sigma = localized_cohesive_law(E, FT, GF, 2.0, *sh, centre_values=d)
    deviation = np.abs(sigma - target_law(shape, w, FT, GF)) / FT
    assert np.max(deviation) == pytest.approx(MAX_DEVIATION[shape], abs=2e-5 if shape != "linear" else 1e-12)


def test_linear_shape_gives_exactly_the_linear_law():
    """p = 2, a2 = -1/2, a3 = 0: sigma = ft (1 - d*) and w = 2 Gf d* / ft in closed form (the opening integral is
    (1/4) int_{delta^2}^1 sqrt((1 - v) / (v - delta^2)) dv / v = pi (1 - delta) / (4 delta), delta = 1 - d*)."""
    d = np.array([1e-6, 0.05, 0.3, 0.5, 0.8, 0.99, 0.9999])
    w, sigma = localized_cohesive_law(E, FT, GF, 3.0, *SHAPES["linear"], centre_values=d)
    np.testing.assert_allclose(sigma, FT * (1.0 - d), rtol=1e-13)
    np.testing.assert_allclose(w, 2.0 * GF * d / FT, rtol=1e-11)


def test_ultimate_openings_and_target_laws():
    assert ultimate_opening(FT, GF, *SHAPES["linear"]) == pytest.approx(2.0 * GF / FT, rel=1e-15)
    assert ultimate_opening(FT, GF, *SHAPES["cornelissen"]) == pytest.approx(5.1361 * GF / FT, rel=5e-5)
    assert ultimate_opening(FT, GF, *SHAPES["exponential"]) == math.inf
    # the law reaches its ultimate opening: no traction from there on
    for shape in ("linear", "cornelissen"):
        wu = ultimate_opening(FT, GF, *SHAPES[shape])
        s = traction_at_opening([0.999 * wu, wu, 2.0 * wu], E, FT, GF, 2.0, *SHAPES[shape])
        assert 0.0 < s[0] < 0.01 * FT and s[1] == 0.0 and s[2] == 0.0
    assert traction_at_opening(1e3, E, FT, GF, 2.0, *SHAPES["exponential"]) == 0.0
    # target laws: their values at a few points
    w = np.array([0.0, 0.5, 1.0]) * GF / FT
    np.testing.assert_allclose(target_law("linear", w, FT, GF), FT * np.array([1.0, 0.75, 0.5]))
    np.testing.assert_allclose(target_law("exponential", w, FT, GF), FT * np.exp([0.0, -0.5, -1.0]))
    x = w / (5.1361 * GF / FT)
    hordijk = (1.0 + (3.0 * x) ** 3) * np.exp(-6.93 * x) - x * 28.0 * np.exp(-6.93)
    np.testing.assert_allclose(target_law("cornelissen", w, FT, GF), FT * hordijk, rtol=1e-14)


@pytest.mark.parametrize("shape", NAMES)
def test_traction_at_opening_inverts_the_law(shape):
    sh = SHAPES[shape]
    d = np.array([1e-3, 0.2, 0.5, 0.8, 0.99, 0.9999])
    w, sigma = localized_cohesive_law(E, FT, GF, 1.0, *sh, centre_values=d)
    np.testing.assert_allclose(traction_at_opening(w, E, FT, GF, 1.0, *sh), sigma, rtol=1e-10)


# ------------------------------------------------------------------------------------------- 5. the quadrature
def _opening_by_ode(d_star, l, p, a2, a3):
    """Brute force: integrate the phase-field equation itself (not its first integral) across the band,
    Gf / (pi l) (alpha' - 2 l^2 d'') = (sigma^2 / (2 E)) omega'(d) (= -g' Y), from the centre (d = d*, d' = 0)
    to the edge (d' = 0 again, d = 0), accumulating w = 2 int_0^{edge} (sigma / E) omega(d(x)) dx."""
    a1 = 4.0 * E * GF / (math.pi * l * FT**2)

    def omega(d):  # 1 / g - 1
        return a1 * d * (1.0 + a2 * d + a2 * a3 * d * d) / (1.0 - d) ** p

    sigma2 = 2.0 * E * GF * (2.0 * d_star - d_star**2) / (math.pi * l * omega(d_star))
    sigma = math.sqrt(sigma2)

    def rhs(x, y):
        d, dp, _ = y
        q = a1 * d * (1.0 + a2 * d + a2 * a3 * d * d)
        dq = a1 * (1.0 + 2.0 * a2 * d + 3.0 * a2 * a3 * d * d)
        domega = dq / (1.0 - d) ** p + p * q / (1.0 - d) ** (p + 1.0)
        d2 = ((2.0 - 2.0 * d) - math.pi * l * sigma2 / (2.0 * E * GF) * domega) / (2.0 * l * l)
        return [dp, d2, sigma / E * omega(d)]

    def edge(x, y):  # d' back to 0, in the lower half of the band
        return y[1] if y[0] < 0.5 * d_star else -1.0

    edge.terminal, edge.direction = True, 1
    sol = solve_ivp(rhs, [0.0, 100.0 * l], [d_star, 0.0, 0.0], method="DOP853", rtol=1e-13, atol=1e-16, events=edge)
    assert sol.status == 1 and abs(sol.y_events[0][0][0]) < 1e-6 * d_star  # the band's edge, d = 0
    return 2.0 * sol.y_events[0][0][2], sigma


@pytest.mark.parametrize("shape", NAMES)
@pytest.mark.parametrize("d_star", [0.05, 0.7, 0.97])
def test_opening_agrees_with_integrating_the_phase_field_equation(shape, d_star):
    sh = SHAPES[shape]
    w_ode, sigma_ode = _opening_by_ode(d_star, 2.0, *sh)
    assert float(centre_stress(d_star, E, FT, GF, 2.0, *sh)) == pytest.approx(sigma_ode, rel=1e-13)
    # measured: ~2e-14 relative
    assert float(crack_opening(d_star, E, FT, GF, 2.0, *sh)) == pytest.approx(w_ode, rel=1e-9)


# ------------------------------------------------------------------------------------------------- 6. bad input
@pytest.mark.parametrize("bad", [dict(E=0.0), dict(ft=-2.4), dict(Gf=0.0), dict(l=-1.0), dict(l=math.nan),
                                 dict(E=math.inf), dict(p=1.5), dict(a2=-1.5)])
def test_bad_parameters_raise(bad):
    args = dict(E=E, ft=FT, Gf=GF, l=2.0, p=2.0, a2=-0.5, a3=0.0) | bad
    with pytest.raises(ValueError):
        localized_cohesive_law(**args)
    with pytest.raises(ValueError):
        traction_at_opening(0.01, **args)


def test_bad_shape_opening_and_centre_values_raise():
    with pytest.raises(ValueError, match="linear, exponential, cornelissen"):
        target_law("bilinear", 0.01, FT, GF)
    with pytest.raises(ValueError):
        target_law("linear", 0.01, 0.0, GF)
    with pytest.raises(ValueError):
        target_law("linear", -0.01, FT, GF)
    with pytest.raises(ValueError):
        traction_at_opening([0.01, -0.01], E, FT, GF, 2.0, *SHAPES["linear"])
    with pytest.raises(ValueError):
        localized_cohesive_law(E, FT, GF, 2.0, *SHAPES["linear"], centre_values=[0.5, 1.2])
