"""Hordijk's cohesive (stress-opening) law of concrete, with secant unloading.

The law (Hordijk 1991) relates the normal traction sigma [MPa] across a crack to its opening w [mm]:

    sigma(w) = ft [(1 + (c1 x)^3) exp(-c2 x) - x (1 + c1^3) exp(-c2)],   x = w / wc,   0 <= w < wc,

and sigma = 0 from the critical opening wc on. The second term makes sigma(wc) = 0 exactly, so
wc is chosen here from the fracture energy Gf by the exact area, wc = Gf / (ft I(c1, c2)) with
I(c1, c2) the area under the normalised law, instead of the rounded wc = 5.136 Gf / ft that holds
for Hordijk's constants c1 = 3, c2 = 6.93 only.

With Hordijk's constants the law is positive and decreasing on [0, wc): it does not dip below zero
before wc (its slope at wc is -141 exp(-6.93) ft / wc, about -0.139 ft / wc, so it reaches zero
from above with a kink). Other (c1, c2) may give laws that rise or change sign; only those with a
positive area are accepted by :class:`CohesiveParameters`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np
from scipy.special import gammainc

from fracid.fem.material.ranges import ELASTIC_USUAL, ParameterRange, ParameterSet
from fracid.fem.material.tsl import secant_unloading


_R = ParameterRange
_RANGES = {
    "E": _R(0.0, False, None, False, "MPa"),
    "nu": _R(-1.0, False, 0.5, False, "-"),
    "ft": _R(0.0, False, None, False, "MPa"),
    "Gf": _R(0.0, False, None, False, "N/mm"),
    "c1": _R(0.0, True, None, False, "-"),
    "c2": _R(0.0, False, None, False, "-"),
}
#: concrete: ft of 2 to 5 MPa, Gf ~ 0.1 N/mm, Hordijk's c1 = 3, c2 = 6.93
_USUAL = {**ELASTIC_USUAL, "ft": (0.5, 20.0), "Gf": (0.005, 1.0), "c1": (0.0, 10.0), "c2": (1.0, 20.0)}


def _incomplete_moment(n, c, x):
    """int_0^x t^n exp(-c t) dt for c > 0, through the regularised lower incomplete gamma function,
    which stays accurate for small c x where the textbook sum 1 - exp(-c x) sum (c x)^k / k! cancels."""
    return math.factorial(n) / c ** (n + 1) * gammainc(n + 1, c * x)


def normalised_area(x, c1, c2):
    """Area under the normalised Hordijk law f(t) = sigma(t wc) / ft from t = 0 to t = x.

    Parameters
    ----------
    x : array_like
        Normalised opening w / wc [-]; values above 1 count as 1 (the law is zero there), values
        below 0 as 0.
    c1, c2 : array_like
        Hordijk's shape constants [-], c1 >= 0, c2 > 0.

    Returns
    -------
    ndarray
        F(x) = int_0^x f(t) dt [-]; F(1) = I(c1, c2), about 0.19470 for c1 = 3, c2 = 6.93.
    """
    x = np.clip(np.asarray(x, dtype=float), 0.0, 1.0)
    c1 = np.asarray(c1, dtype=float)
    c2 = np.asarray(c2, dtype=float)
    tail = (1.0 + c1**3) * np.exp(-c2)
    return _incomplete_moment(0, c2, x) + c1**3 * _incomplete_moment(3, c2, x) - tail * x**2 / 2.0


def hordijk_shape(x, c1, c2):
    """f(x) = sigma / ft and df/dx of the Hordijk law at normalised openings x = w / wc [-], without
    the cut-offs outside [0, 1)."""
    decay = np.exp(-c2 * x)
    tail = (1.0 + c1**3) * np.exp(-c2)
    cubic = 1.0 + (c1 * x) ** 3
    f = cubic * decay - x * tail
    df = (3.0 * c1**3 * x**2 - c2 * cubic) * decay - tail
    return f, df


def hordijk_shape_derivatives(x, c1, c2) -> dict:
    """d f / d c1 and d f / d c2 of :func:`hordijk_shape` at fixed x [-]:
    3 c1^2 (x^3 exp(-c2 x) - x exp(-c2)) and x ((1 + c1^3) exp(-c2) - (1 + (c1 x)^3) exp(-c2 x))."""
    decay, tail = np.exp(-c2 * x), np.exp(-c2)
    return {"c1": 3.0 * c1**2 * (x**3 * decay - x * tail),
            "c2": -x * (1.0 + (c1 * x) ** 3) * decay + x * (1.0 + c1**3) * tail}


def hordijk_envelope(w, ft, wc, c1, c2):
    """Stress [MPa] and tangent [MPa/mm] of the Hordijk law, both zero outside the softening range
    0 <= w < wc (see :func:`hordijk_stress` and :func:`hordijk_tangent`)."""
    w = np.asarray(w, dtype=float)
    active = (w >= 0.0) & (w < wc)
    # evaluate at a harmless x where inactive so that no overflow or nan leaks through np.where
    x = np.where(active, w / wc, 0.0)
    f, df = hordijk_shape(x, c1, c2)
    return np.where(active, ft * f, 0.0), np.where(active, ft / wc * df, 0.0)


def hordijk_stress(w, ft, wc, c1, c2):
    """Hordijk's cohesive traction sigma(w) on the monotonic (envelope) curve.

    sigma = ft [(1 + (c1 w/wc)^3) exp(-c2 w/wc) - (w/wc)(1 + c1^3) exp(-c2)] for 0 <= w < wc and
    sigma = 0 for w >= wc (fully open crack). For w < 0 (crack faces in contact) it also returns 0:
    the law carries tension only, and the compressive contact (penalty) stiffness of the interface
    is left to the caller.

    Parameters
    ----------
    w : array_like
        Crack opening [mm].
    ft : array_like
        Tensile strength [MPa], the traction at w = 0.
    wc : array_like
        Critical opening [mm], where the traction vanishes (see :attr:`CohesiveParameters.wc`).
    c1, c2 : array_like
        Shape constants [-] (Hordijk: c1 = 3, c2 = 6.93).

    Returns
    -------
    ndarray
        Traction sigma [MPa], broadcast over the arguments.
    """
    return hordijk_envelope(w, ft, wc, c1, c2)[0]


def hordijk_tangent(w, ft, wc, c1, c2):
    """Derivative d sigma / d w of :func:`hordijk_stress` [MPa/mm].

    Analytic: (ft / wc) [(3 c1^3 x^2 - c2 (1 + (c1 x)^3)) exp(-c2 x) - (1 + c1^3) exp(-c2)] with
    x = w / wc on 0 <= w < wc, and 0 where the stress is cut to 0 (w < 0, w >= wc). The law has kinks
    at w = 0 and w = wc; at those points the one-sided value on the side of the formula's definition
    (0 at wc, the softening slope at 0) is returned.

    Parameters
    ----------
    w, ft, wc, c1, c2 : array_like
        As in :func:`hordijk_stress`.

    Returns
    -------
    ndarray
        Tangent stiffness [MPa/mm].
    """
    return hordijk_envelope(w, ft, wc, c1, c2)[1]


def cohesive_traction(w, w_max, ft, wc, c1, c2):
    """Traction, consistent tangent and history update of the Hordijk law with secant unloading
    (:func:`~fracid.fem.material.tsl.secant_unloading` on :func:`hordijk_envelope`).

    Loading (w >= w_max, neutral loading included, as in
    :func:`fracid.fem.material.damage.update_history`): the point follows the envelope,
    sigma = hordijk_stress(w). Unloading (0 <= w < w_max): it goes back linearly to the origin,
    sigma = hordijk_stress(w_max) w / w_max, so that reloading retraces the same secant until the
    envelope is met again. Closure (w < 0): sigma = 0 with zero tangent, as in
    :func:`hordijk_stress`; contact is the caller's business.

    Parameters
    ----------
    w : array_like
        Current crack opening [mm].
    w_max : array_like
        Largest opening reached before this step [mm], w_max >= 0 (0 for an intact point).
    ft, wc, c1, c2 : array_like
        As in :func:`hordijk_stress`.

    Returns
    -------
    sigma : ndarray
        Traction [MPa].
    dsigma_dw : ndarray
        Consistent tangent [MPa/mm]: the envelope's slope when loading, the secant slope
        hordijk_stress(w_max) / w_max when unloading.
    w_max_new : ndarray
        Updated history max(w_max, w) [mm].
    """
    return secant_unloading(w, w_max, lambda v: hordijk_envelope(v, ft, wc, c1, c2))


def dissipated_energy_density(w_max, ft, wc, c1, c2):
    """Energy dissipated per unit crack area after opening to w_max and unloading to w = 0 [N/mm].

    The area under the envelope up to w_max minus the elastic triangle recovered on secant
    unloading, ft wc F(w_max / wc) - hordijk_stress(w_max) w_max / 2, with F from
    :func:`normalised_area`. It is 0 at w_max = 0 and equals Gf = ft wc I(c1, c2) from w_max = wc
    on (nothing is recovered from a fully open crack).

    Parameters
    ----------
    w_max : array_like
        Largest opening reached [mm], w_max >= 0.
    ft, wc, c1, c2 : array_like
        As in :func:`hordijk_stress`.

    Returns
    -------
    ndarray
        Dissipated energy density [N/mm] = [MPa mm].
    """
    w_max = np.asarray(w_max, dtype=float)
    area = ft * wc * normalised_area(w_max / wc, c1, c2)
    return area - 0.5 * hordijk_stress(w_max, ft, wc, c1, c2) * np.maximum(w_max, 0.0)


@dataclass(frozen=True)
class CohesiveParameters(ParameterSet):
    """Parameters x = (E, nu, ft, Gf, c1, c2) of a bulk with Hordijk cohesive cracks.

    Parameters
    ----------
    E : float
        Young's modulus of the bulk [MPa], E > 0.
    nu : float
        Poisson's ratio of the bulk [-], -1 < nu < 0.5.
    ft : float
        Tensile strength, traction at zero opening [MPa], ft > 0.
    Gf : float
        Fracture energy, area under the traction-opening law [N/mm], Gf > 0.
    c1 : float
        Shape constant of the law [-], c1 >= 0 (Hordijk: 3).
    c2 : float
        Shape constant of the law [-], c2 > 0 (Hordijk: 6.93).

    Besides the ranges, (c1, c2) must give a law of positive area, else no wc reproduces Gf
    (e.g. c1 = 10, c2 = 2 is rejected).

    Examples
    --------
    >>> p = CohesiveParameters()
    >>> round(p.wc * p.ft / p.Gf, 3)
    5.136
    >>> p.replace(Gf=0.12).Gf
    0.12
    """

    E: float = 30000.0
    nu: float = 0.2
    ft: float = 3.0
    Gf: float = 0.1
    c1: float = 3.0
    c2: float = 6.93

    ranges: ClassVar[dict] = _RANGES
    usual_ranges: ClassVar[dict] = _USUAL

    def __post_init__(self):
        super().__post_init__()
        if not self.area_factor > 0.0:
            raise ValueError(
                f"parameters 'c1' = {self.c1!r}, 'c2' = {self.c2!r} give a cohesive law of area "
                f"{self.area_factor:g} ft wc <= 0; no critical opening reproduces Gf"
            )

    @property
    def area_factor(self) -> float:
        """I(c1, c2) = int_0^1 sigma(x wc) / ft dx [-], the normalised area under the law.

        Closed form (incomplete gamma functions), about 10 microseconds, so it is not cached.
        """
        return float(normalised_area(1.0, self.c1, self.c2))

    @property
    def wc(self) -> float:
        """Critical opening [mm] at which the traction vanishes, wc = Gf / (ft I(c1, c2)), so that
        the area under the law is exactly Gf (about 5.136 Gf / ft for Hordijk's constants)."""
        return self.Gf / (self.ft * self.area_factor)

    def area_factor_derivatives(self) -> tuple[float, float]:
        """(d I / d c1, d I / d c2) of :attr:`area_factor` [-], in closed form:
        3 c1^2 (M3 - exp(-c2) / 2) and (1 + c1^3) exp(-c2) / 2 - M1 - c1^3 M4, with
        Mn = int_0^1 t^n exp(-c2 t) dt."""
        c1, c2 = self.c1, self.c2
        moment = lambda n: float(_incomplete_moment(n, c2, 1.0))  # noqa: E731
        tail = math.exp(-c2)
        return (3.0 * c1**2 * (moment(3) - 0.5 * tail),
                0.5 * (1.0 + c1**3) * tail - moment(1) - c1**3 * moment(4))

    def law(self) -> tuple[float, float, float, float]:
        """(ft, wc, c1, c2), the trailing arguments of the Hordijk functions of this module (the crack
        formulations do not use it: they ask their law object, :class:`~fracid.fem.material.laws.HordijkLaw`)."""
        return self.ft, self.wc, self.c1, self.c2
