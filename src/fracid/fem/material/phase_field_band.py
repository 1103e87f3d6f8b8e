"""The localized band of the phase-field regularised cohesive zone model (PF-CZM) in a bar under uniform
stress: its stress and crack opening as functions of the phase field d* at its centre, by quadrature.

The traction-opening law built from them, and its comparison with the nominal laws:
:mod:`fracid.fem.material.phase_field_cohesive`.

**Model.** Phase field d in [0, 1] of length scale l [mm], geometric function alpha(d) = 2 d - d^2 (c_alpha = pi),
degradation

    g(d) = (1 - d)^p / ((1 - d)^p + Q(d)),   Q(d) = a1 d (1 + a2 d + a2 a3 d^2),   a1 = 4 E Gf / (pi l ft^2),

and omega(d) = 1 / g(d) - 1 = Q(d) / (1 - d)^p. In a bar under the uniform stress sigma the band, loading
everywhere during softening, solves Gf / (c_alpha l) (alpha'(d) - 2 l^2 d'') = -g'(d) Y with
Y = sigma^2 / (2 E g^2), whose first integral from the band's edge (d = d' = 0) is

    Gf / (c_alpha l) (alpha(d) - l^2 d'^2) = sigma^2 / (2 E) omega(d).

At the band centre (d = d*, d' = 0) this fixes the stress,

    sigma(d*)^2 = 2 E Gf R(d*) / (c_alpha l),   R(d) = alpha(d) / omega(d) = (2 - d) (1 - d)^p / (a1 P(d)),

with P(d) = 1 + a2 d + a2 a3 d^2 (R(0) = 2 / a1, so sigma(0) = ft), and the crack opening, the inelastic
elongation of the whole band, is

    w = int (sigma / E) omega dx = 2 (sigma / E) l int_0^{d*} sqrt(omega(d) / (R(d) - R(d*))) dd,

using ``|d'|`` = (1 / l) sqrt(omega (R(d) - R(d*))). The integrand behaves as sqrt(d) at d = 0 and as
(d* - d)^(-1/2) at d*: it is integrated as sqrt(omega(d) / d / D(d)) against the algebraic weight
d^(1/2) (d* - d)^(-1/2) (QUADPACK's QAWS, ``scipy.integrate.quad(weight="alg")``), with the divided
difference D(d) = (R(d) - R(d*)) / (d* - d) > 0 evaluated without cancellation (it tends to -R'(d*)). For d*
near 1, beyond d = 0.9 the integral runs over u = 1 - d in decades (the integrand grows like u^-p), so that
1 - d and d* - d keep their relative accuracy. Checked against integrating the phase-field equation itself
across the band (tests): ~1e-14 relative.

Units: stresses [MPa], lengths [mm], Gf [N/mm].
"""

from __future__ import annotations

import math

import numpy as np
from scipy.integrate import quad

from fracid.fem.material.phase_field import C_ALPHA, a1 as a1_coefficient, shape_polynomial

__all__ = ["QUAD_EPSREL", "QUAD_LIMIT", "band_opening", "band_stress", "check_law_parameters", "dlog_r",
           "opening_integral", "rho", "ultimate_opening"]

# quadrature tolerances of one opening
QUAD_EPSREL = 1e-12
QUAD_LIMIT = 200


def check_law_parameters(E, ft, Gf, l, p, a2, a3):
    """Raise a ValueError unless E, ft, Gf, l [MPa, MPa, N/mm, mm] are finite and positive and the shape
    (p, a2, a3) [-] gives a stress that falls monotonically with the band centre's phase field d*."""
    for name, value in (("E", E), ("ft", ft), ("Gf", Gf), ("l", l)):
        if not (np.isscalar(value) and np.isreal(value) and math.isfinite(value) and value > 0.0):
            raise ValueError(f"{name} = {value!r}: must be a finite positive number")
    for name, value in (("p", p), ("a2", a2), ("a3", a3)):
        if not (np.isscalar(value) and np.isreal(value) and math.isfinite(value)):
            raise ValueError(f"{name} = {value!r}: must be a finite number")
    if p < 2.0:
        raise ValueError(f"p = {p!r}: must be >= 2 (for p < 2 the opening closes again as d* -> 1)")
    d = np.linspace(0.0, 1.0, 401)
    if np.min(shape_polynomial(d, a2, a3)) <= 0.0:
        raise ValueError(f"a2 = {a2!r}, a3 = {a3!r}: 1 + a2 d + a2 a3 d^2 must stay positive on [0, 1]")
    # the stress must fall monotonically with d*: R = alpha / omega strictly decreasing on [0, 1)
    d = d[:-1]
    if np.max(dlog_r(d, p, a2, a3)) >= 0.0:
        raise ValueError(f"(p, a2, a3) = ({p!r}, {a2!r}, {a3!r}): the stress sigma(d*) is not decreasing")


def rho(d, p, a2, a3, u=None):
    """rho(d) = a1 R(d) = a1 alpha / omega = (2 - d) u^p / P(d) [-], u = 1 - d (pass it when it is known more
    accurately than 1 - d); sigma^2 / ft^2 = rho(d*) / 2."""
    u = np.maximum(1.0 - d, 0.0) if u is None else u
    return (2.0 - d) * u**p / shape_polynomial(d, a2, a3)


def dlog_r(d, p, a2, a3, u=None):
    """d log R / d d [-] = -1 / (2 - d) - p / u - P'(d) / P(d), u = 1 - d > 0."""
    u = 1.0 - d if u is None else u
    return -1.0 / (2.0 - d) - p / u - (a2 + 2.0 * a2 * a3 * d) / shape_polynomial(d, a2, a3)


def opening_integral(d_star, delta, p, a2, a3):
    """K(d*) = int_0^{d*} sqrt(phi(d) / (rho(d) - rho(d*))) dd [-] (delta = 1 - d*, both given accurately),
    phi = omega / a1 = d P(d) / (1 - d)^p, so that w = (8 Gf / (pi ft)) (sigma / ft) K.

    The integrand is sqrt(phi / d / D) d^(1/2) (d* - d)^(-1/2) with the divided difference
    D = (rho(d) - rho(d*)) / (d* - d) > 0, evaluated without cancellation as follows. With rho = A B / P,
    A = 2 - d, B = (1 - d)^p and [f] = (f(d*) - f(d)) / (d* - d): [A] = -1, [P] = a2 + a2 a3 (d + d*),
    [B] = -u^(p - 1) (1 - q^p) / (1 - q) with u = 1 - d, q = delta / u (1 - q = (d* - d) / u), [AB] =
    A(d*) [B] - B(d) and D = -([AB] P(d) - A(d) B(d) [P]) / (P(d) P(d*)); D -> -rho'(d*) at d = d*. The
    algebraic end factors go to QUADPACK's weight (QAWS). For d* > 0.95, beyond d = 0.9 the integral runs over
    u = 1 - d in decades of u (the integrand grows like u^-p, and u, d* - d = u - delta keep their relative accuracy).
    """
    if d_star <= 0.0:
        return 0.0
    Py = 1.0 + a2 * d_star + a2 * a3 * d_star * d_star
    Ay = 1.0 + delta
    tiny = np.finfo(float).tiny

    def smooth(d, u, gap):  # sqrt(phi / d / D) at d = 1 - u, gap = d* - d: bounded and smooth on [0, d*]
        m = min(gap / u, 1.0)
        ratio = -math.expm1(p * math.log1p(-m)) / m if 0.0 < m < 1.0 else (p if m <= 0.0 else 1.0 / m)
        Bx = u**p
        Px = 1.0 + a2 * d + a2 * a3 * d * d
        drop = -((Ay * -(Bx / u) * ratio - Bx) * Px - (2.0 - d) * Bx * (a2 + a2 * a3 * (d + d_star))) / (Px * Py)
        return math.sqrt(Px / Bx / max(drop, tiny))

    def options(wvar):
        return dict(weight="alg", wvar=wvar, epsabs=0.0, epsrel=QUAD_EPSREL, limit=QUAD_LIMIT)

    if d_star <= 0.95:  # one piece over d, both end factors in the weight
        value, _ = quad(lambda d: smooth(d, 1.0 - d, d_star - d), 0.0, d_star, **options((0.5, -0.5)))
        return value
    # d in [0, 0.9]: weight d^(1/2); the factor (d* - d)^(-1/2) is smooth there (d* - d >= 0.05)
    total, _ = quad(lambda d: smooth(d, 1.0 - d, d_star - d) / math.sqrt(d_star - d), 0.0, 0.9, **options((0.5, 0.0)))
    # u in decades [10^-(k+1), 10^-k] while 10^-(k+1) > 4 delta, then [delta, 10^-K] with weight (u - delta)^(-1/2)
    k = 1
    while 10.0 ** -(k + 1) > 4.0 * delta:
        value, _ = quad(lambda u: smooth(1.0 - u, u, u - delta) * math.sqrt((1.0 - u) / (u - delta)),
                        10.0 ** -(k + 1), 10.0**-k, epsabs=0.0, epsrel=QUAD_EPSREL, limit=QUAD_LIMIT)
        total += value
        k += 1
    value, _ = quad(lambda u: smooth(1.0 - u, u, u - delta) * math.sqrt(1.0 - u), delta, 10.0**-k,
                    **options((-0.5, 0.0)))
    return total + value


def band_stress(d_star, delta, E, ft, Gf, l, p, a2, a3):
    """sigma(d*) [MPa] (delta = 1 - d*) in the dimensional form sqrt(2 E Gf R / (c_alpha l)), R = rho / a1."""
    R = rho(d_star, p, a2, a3, u=delta) / a1_coefficient(E, ft, Gf, l)
    return math.sqrt(2.0 * E * Gf * R / (C_ALPHA * l))


def band_opening(d_star, delta, E, ft, Gf, l, p, a2, a3):
    """w(d*) [mm] for d* in [0, 1] (delta = 1 - d*, both given accurately), inputs already validated:
    w = 2 (sigma / E) l int sqrt(omega / (R - R*)) dd = 2 (sigma / E) l a1 K (omega = a1 phi, R = rho / a1)."""
    if d_star <= 0.0:
        return 0.0
    if delta <= 0.0:
        return ultimate_opening(ft, Gf, p, a2, a3)
    sigma = band_stress(d_star, delta, E, ft, Gf, l, p, a2, a3)
    return 2.0 * sigma * l * a1_coefficient(E, ft, Gf, l) * opening_integral(d_star, delta, p, a2, a3) / E


def ultimate_opening(ft, Gf, p, a2, a3):
    """Opening w_u [mm] where the law reaches sigma = 0 (the limit d* -> 1).

    For p = 2, w_u = 2 sqrt(2 (1 + a2 + a2 a3)) Gf / ft (linear shape: 2 Gf / ft; Cornelissen shape:
    5.1362 Gf / ft); for p > 2 the law has an infinite tail and w_u = inf.

    Parameters
    ----------
    ft : float
        Tensile strength [MPa].
    Gf : float
        Fracture energy [N/mm].
    p, a2, a3 : float
        Softening shape [-].

    Returns
    -------
    float
        w_u [mm] (``inf`` for p > 2).
    """
    check_law_parameters(1.0, ft, Gf, 1.0, p, a2, a3)
    if p > 2.0:
        return math.inf
    return 2.0 * math.sqrt(2.0 * shape_polynomial(1.0, a2, a3)) * Gf / ft
