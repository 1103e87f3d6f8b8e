"""The exact 1D traction-opening law of the phase-field regularised cohesive zone model (PF-CZM; J.-Y. Wu 2017,
J. Mech. Phys. Solids 103:72-99; Wu & Nguyen 2018, J. Mech. Phys. Solids 119:20-42), by quadrature, and the
nominal softening laws its shapes stand for.

The band itself (the first integral of the phase-field equation, the stress and the opening of a band of
centre d* by quadrature, the ultimate opening): :mod:`fracid.fem.material.phase_field_band`.

**What comes out.** Since a1 l = 4 E Gf / (pi ft^2), both sigma and w are free of l: the law is exact in l,
not an approximation (the 1 / l of a1 cancels in R / a1 and in l sqrt(omega / R)). In units ft and Gf / ft,

    sigma / ft = sqrt(R a1 / 2),   w ft / Gf = (8 / pi) (sigma / ft) int_0^{d*} sqrt(phi / (rho - rho*)) dd

with phi = omega / a1, rho = R a1. For p = 2 the opening tends to the finite ultimate opening
w_u = 2 sqrt(2 (1 + a2 + a2 a3)) Gf / ft as d* -> 1 (linear shape: 2 Gf / ft, the linear law's; Cornelissen
shape: 5.1362 Gf / ft, Hordijk's 5.1361 Gf / ft); for p > 2 it grows without bound like (1 - d*)^(1 - p / 2)
while sigma ~ (1 - d*)^(p / 2): the law has an infinite tail, algebraic, sigma ~ w^(-p / (p - 2)) (w^-5 for the
exponential shape), not exponential. The area under the whole law is Gf (the fully broken band carries the
optimal profile of the crack functional; :func:`dissipated_energy` gives it to ~1e-14), and the initial slope
is k0 = -(ft^2 / (2 Gf)) ((a2 + p + 1/2) / 2)^(3/2), from which Wu's a2 are set.

Against the nominal laws (:func:`target_law`), max ``|sigma - sigma_target|`` / ft over the law:

- linear (2, -1/2, 0): exactly the linear law, sigma = ft (1 - d*) and w = 2 Gf d* / ft in closed form;
- exponential (5/2, 2^(5/3) - 3, 0): 2.6e-3, at w = 1.74 Gf / ft;
- cornelissen (2, 1.3868, 0.6567): 4.9e-2, at w = 0.80 Gf / ft (same initial slope, ultimate opening and area
  as Hordijk's law, a fuller curve in between: +0.049 ft near w = 0.8 Gf / ft, -0.026 ft further on).

Units: stresses [MPa], lengths [mm], Gf [N/mm].
"""

from __future__ import annotations

import numpy as np
from scipy.integrate import quad
from scipy.optimize import brentq

from fracid.fem.material.cohesive import hordijk_stress
from fracid.fem.material.phase_field import C_ALPHA, SHAPES, a1 as a1_coefficient
from fracid.fem.material.phase_field import degradation as _degradation
from fracid.fem.material.phase_field_band import (
    QUAD_LIMIT,
    band_opening,
    band_stress,
    check_law_parameters,
    dlog_r,
    rho,
)

#: Cornelissen / Hordijk's constants of the nominal law: c1, c2 and wc ft / Gf
HORDIJK_C1 = 3.0
HORDIJK_C2 = 6.93
HORDIJK_WC = 5.1361


# ------------------------------------------------------------------------------------------ the model's functions
def shape_parameters(shape):
    """(p, a2, a3) of a softening shape by name.

    Parameters
    ----------
    shape : str
        ``"linear"``, ``"exponential"`` or ``"cornelissen"``.

    Returns
    -------
    tuple of float
        (p, a2, a3) [-].

    Raises
    ------
    ValueError
        For an unknown name (the message lists the allowed ones).
    """
    try:
        return SHAPES[shape]
    except (KeyError, TypeError):
        raise ValueError(f"unknown phase-field softening shape {shape!r}; allowed: {', '.join(SHAPES)}") from None


def degradation(d, E, ft, Gf, l, p, a2, a3):
    """g(d) [-] of :func:`fracid.fem.material.phase_field.degradation` with a1 from (E, ft, Gf, l), validated."""
    check_law_parameters(E, ft, Gf, l, p, a2, a3)
    return _degradation(d, a1_coefficient(E, ft, Gf, l), p, a2, a3)[0]



# ------------------------------------------------------------------------------------------------- the law itself
def _centre_values(centre_values):
    d = np.asarray(centre_values, dtype=float)
    if not np.all(np.isfinite(d)) or np.any(d < 0.0) or np.any(d > 1.0):
        raise ValueError("the centre values d* must lie in [0, 1]")
    return d


def centre_stress(centre_values, E, ft, Gf, l, p, a2, a3):
    """Stress sigma [MPa] of the localized band whose centre has the phase field d*.

    sigma^2 = 2 E Gf alpha(d*) / (c_alpha l omega(d*)) = ft^2 (2 - d*) (1 - d*)^p / (2 P(d*)),
    P = 1 + a2 d + a2 a3 d^2: ft at d* = 0, 0 at d* = 1, decreasing in between.

    Parameters
    ----------
    centre_values : array_like
        Phase field at the band centre d* [-], in [0, 1].
    E, ft, Gf, l : float
        Young's modulus [MPa], tensile strength [MPa], fracture energy [N/mm], length scale [mm].
    p, a2, a3 : float
        Softening shape [-] (:data:`SHAPES`).

    Returns
    -------
    ndarray
        sigma [MPa], like ``centre_values``.
    """
    check_law_parameters(E, ft, Gf, l, p, a2, a3)
    d = _centre_values(centre_values)
    R = rho(d, p, a2, a3) / a1_coefficient(E, ft, Gf, l)
    return np.sqrt(2.0 * E * Gf * R / (C_ALPHA * l))


def crack_opening(centre_values, E, ft, Gf, l, p, a2, a3):
    """Crack opening w [mm] of the localized band with centre phase field d*.

    w = 2 (sigma / E) int_0^{d*} omega(d) / ``|d'(d)|`` dd, ``|d'|`` = (1 / l) sqrt(alpha - (alpha* / omega*) omega),
    by adaptive quadrature with the end singularities as algebraic weights (relative accuracy ~1e-12; for
    d* near 1 limited by the representation of 1 - d*, about 1e-16 / (1 - d*) relative).

    Parameters
    ----------
    centre_values : array_like
        Phase field at the band centre d* [-], in [0, 1].
    E, ft, Gf, l : float
        Young's modulus [MPa], tensile strength [MPa], fracture energy [N/mm], length scale [mm].
    p, a2, a3 : float
        Softening shape [-] (:data:`SHAPES`).

    Returns
    -------
    ndarray
        w [mm], like ``centre_values``: 0 at d* = 0,
        :func:`~fracid.fem.material.phase_field_band.ultimate_opening` at d* = 1.
    """
    check_law_parameters(E, ft, Gf, l, p, a2, a3)
    d = _centre_values(centre_values)
    w = np.zeros_like(d)
    for index, d_star in np.ndenumerate(d):
        w[index] = band_opening(float(d_star), 1.0 - float(d_star), E, ft, Gf, l, p, a2, a3)
    return w


def default_centre_values(p, a2, a3, stress_fraction=1e-3, n_linear=121, n_tail=80):
    """The default grid of band-centre values d* of :func:`localized_cohesive_law`.

    d* = 0, ..., 0.9 evenly (``n_linear`` points), then 1 - d* geometrically from 0.1 down to the value where
    sigma = ``stress_fraction`` * ft (``n_tail`` more points): the whole curve from (0, ft) into its tail.

    Parameters
    ----------
    p, a2, a3 : float
        Softening shape [-].
    stress_fraction : float, optional
        sigma / ft at the last point [-], in (0, 1).
    n_linear, n_tail : int, optional
        Numbers of points of the two parts.

    Returns
    -------
    ndarray
        Increasing d* [-], starting with 0.
    """
    check_law_parameters(1.0, 1.0, 1.0, 1.0, p, a2, a3)
    if not 0.0 < stress_fraction < 1.0:
        raise ValueError(f"stress_fraction = {stress_fraction!r}: must lie in (0, 1)")
    # sigma^2 / ft^2 = rho / 2 falls monotonically from 1 (d* = 0) to 0 (d* = 1)
    d_end = brentq(lambda d: float(rho(d, p, a2, a3)) - 2.0 * stress_fraction**2, 0.0, 1.0, xtol=1e-15)
    if d_end <= 0.9:
        return np.linspace(0.0, d_end, n_linear)
    head = np.linspace(0.0, 0.9, n_linear)
    tail = 1.0 - np.geomspace(0.1, 1.0 - d_end, n_tail + 1)[1:]
    return np.concatenate([head, tail])


def localized_cohesive_law(E, ft, Gf, l, p, a2, a3, centre_values=None):
    """The traction-opening law sigma(w) of the PF-CZM's localized band, along increasing d*.

    Parameters
    ----------
    E : float
        Young's modulus [MPa].
    ft : float
        Tensile strength [MPa].
    Gf : float
        Fracture energy [N/mm].
    l : float
        Phase-field length scale [mm] (Wu's b); the law does not depend on it.
    p, a2, a3 : float
        Softening shape [-] (:data:`SHAPES`).
    centre_values : array_like, optional
        Phase field at the band centre d* [-] in [0, 1] where the law is evaluated; default
        :func:`default_centre_values` (201 points from w = 0, sigma = ft down to sigma = 1e-3 ft).

    Returns
    -------
    w : ndarray
        Crack opening [mm].
    sigma : ndarray
        Traction [MPa].
    """
    check_law_parameters(E, ft, Gf, l, p, a2, a3)
    d = default_centre_values(p, a2, a3) if centre_values is None else _centre_values(centre_values)
    return crack_opening(d, E, ft, Gf, l, p, a2, a3), centre_stress(d, E, ft, Gf, l, p, a2, a3)


def traction_at_opening(w, E, ft, Gf, l, p, a2, a3):
    """Traction sigma [MPa] of the PF-CZM's localized law at given crack openings.

    The monotone relation w(d*) is inverted by Brent's method, in d* where d* < 0.5 and in 1 - d* beyond
    (both keep their relative accuracy), bracketed on a coarse grid of d* shared by all openings.

    Parameters
    ----------
    w : array_like
        Crack opening [mm], >= 0.
    E, ft, Gf, l : float
        Young's modulus [MPa], tensile strength [MPa], fracture energy [N/mm], length scale [mm].
    p, a2, a3 : float
        Softening shape [-] (:data:`SHAPES`).

    Returns
    -------
    ndarray
        sigma [MPa], like w: ft at w = 0; 0 from the law's last opening on
        (:func:`~fracid.fem.material.phase_field_band.ultimate_opening` for p = 2; for p > 2 the opening at
        d* = 1 - 1e-14, where sigma is below 1e-17 ft).
    """
    check_law_parameters(E, ft, Gf, l, p, a2, a3)
    w = np.asarray(w, dtype=float)
    if not np.all(np.isfinite(w)) or np.any(w < 0.0):
        raise ValueError("the openings w must be finite and >= 0")
    args = (E, ft, Gf, l, p, a2, a3)
    # the grid in delta = 1 - d*, decreasing: d* = 0, 0.1, ..., 0.5, then 1 - d* = 0.4, ..., 0.1, 1e-2, ..., 1e-14
    delta_grid = np.concatenate([np.linspace(1.0, 0.1, 10), 10.0 ** -np.arange(2.0, 15.0)])
    if p == 2.0:
        delta_grid = np.append(delta_grid, 0.0)  # w(d* = 1) = w_u, finite
    w_grid = np.array([band_opening(1.0 - float(x), float(x), *args) for x in delta_grid])
    sigma = np.zeros_like(w)
    for index, wi in np.ndenumerate(w):
        if wi == 0.0:
            sigma[index] = ft
            continue
        if wi >= w_grid[-1]:
            continue  # beyond the law: no traction
        k = int(np.searchsorted(w_grid, wi, side="right"))
        lo, hi = float(delta_grid[k]), float(delta_grid[k - 1])  # delta bracket, lo < hi
        if lo >= 0.5:  # small d*: solve for d* itself
            d_star = brentq(lambda d: band_opening(d, 1.0 - d, *args) - wi, 1.0 - hi, 1.0 - lo, xtol=1e-300, rtol=1e-14)
            delta = 1.0 - d_star
        else:
            delta = brentq(lambda x: band_opening(1.0 - x, x, *args) - wi, lo, hi, xtol=1e-300, rtol=1e-14)
            d_star = 1.0 - delta
        sigma[index] = band_stress(d_star, delta, *args)
    return sigma


def dissipated_energy(E, ft, Gf, l, p, a2, a3):
    """Area under the whole law, int sigma dw [N/mm], tail included.

    Computed as int_0^ft w dsigma = int_0^1 w(d*) (-dsigma / dd*) dd* (sigma w -> 0 at the end, also for the
    infinite tail of p > 2), with dsigma / dd* = (sigma / 2) d log R / dd* in closed form; the integrand is
    bounded, and the part beyond d* = 1 - 1e-14 is left out.

    Parameters
    ----------
    E, ft, Gf, l : float
        Young's modulus [MPa], tensile strength [MPa], fracture energy [N/mm], length scale [mm].
    p, a2, a3 : float
        Softening shape [-] (:data:`SHAPES`).

    Returns
    -------
    float
        The dissipated energy per unit crack area [N/mm]: Gf to ~1e-10 relative (see the tests).
    """
    check_law_parameters(E, ft, Gf, l, p, a2, a3)
    args = (E, ft, Gf, l, p, a2, a3)

    def integrand(delta):  # w (-dsigma / dd*) at d* = 1 - delta
        d = 1.0 - delta
        slope = float(dlog_r(d, p, a2, a3, u=delta))
        return -band_opening(d, delta, *args) * 0.5 * band_stress(d, delta, *args) * slope

    def piece(a, b):
        return quad(integrand, a, b, epsabs=0.0, epsrel=1e-11, limit=QUAD_LIMIT)[0]

    # delta from 1 to 0.1, then by decades down to 1e-14
    edges = np.concatenate([[1.0], 10.0 ** -np.arange(1.0, 15.0)])
    return sum(piece(float(b), float(a)) for a, b in zip(edges[:-1], edges[1:]))


def target_law(shape, w, ft, Gf):
    """Traction of the nominal cohesive law a softening shape stands for [MPa].

    - ``"linear"``: sigma = ft max(1 - w / w_u, 0), w_u = 2 Gf / ft;
    - ``"exponential"``: sigma = ft exp(-ft w / Gf);
    - ``"cornelissen"``: Cornelissen / Hordijk's law (:func:`fracid.fem.material.cohesive.hordijk_stress`)
      with c1 = 3, c2 = 6.93 and wc = 5.1361 Gf / ft.

    Parameters
    ----------
    shape : str
        ``"linear"``, ``"exponential"`` or ``"cornelissen"``.
    w : array_like
        Crack opening [mm], >= 0.
    ft : float
        Tensile strength [MPa].
    Gf : float
        Fracture energy [N/mm].

    Returns
    -------
    ndarray
        sigma [MPa], like w.
    """
    shape_parameters(shape)
    check_law_parameters(1.0, ft, Gf, 1.0, *SHAPES[shape])
    w = np.asarray(w, dtype=float)
    if not np.all(np.isfinite(w)) or np.any(w < 0.0):
        raise ValueError("the openings w must be finite and >= 0")
    if shape == "linear":
        return ft * np.maximum(1.0 - w * ft / (2.0 * Gf), 0.0)
    if shape == "exponential":
        return ft * np.exp(-ft * w / Gf)
    return hordijk_stress(w, ft, HORDIJK_WC * Gf / ft, HORDIJK_C1, HORDIJK_C2)
