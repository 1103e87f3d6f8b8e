"""Closed-form solution of a 1D gradient-enhanced damage bar with a weak zone.

Peerlings et al. (1996)-type benchmark, "perfect damage" ``omega = 1 - kappa_i/kappa``.
Units: N, mm, MPa.  Symmetric coordinate ``s = x - L/2``, ``h = W/2``, ``l = L/2``,
``ell = sqrt(c)``, ``lam = sigma/(E_w kappa_i)``, ``q = sqrt(lam - 1)``, ``k = q/ell``.

Damaged band ``|s| < xi`` (``xi < h``, all points loading): ``eps = lam*ebar`` so
``ebar = a cos(k s)`` with ``a = kappa_i/cos(k xi)``.  The elastic parts
(``ebar = sigma/E(x) + cosh/sinh``) with ``ebar'(l) = 0``, ``ebar`` and ``ebar'``
continuous at ``h`` and ``ebar(xi) = kappa_i`` give
``ell*ebar'(xi+) = -(kappa_i - sigma/E_w) tanh(rho) - sigma*delta*sinh(m)/cosh(rho)``
with ``rho = (l - xi)/ell``, ``m = (l - h)/ell``, ``delta = 1/E_w - 1/E``.  Matching
``ell*ebar'(xi-) = -kappa_i q tan(q xi/ell)`` yields the single equation for ``q``::

    q tan(q xi/ell) + q**2 tanh(rho) - (1 + q**2) beta = 0,
    beta = (1 - phi) sinh(m)/cosh(rho),

whose left side increases from ``-beta`` to ``+inf`` on ``0 < q < pi ell/(2 xi)``:
exactly one root.  Onset (``xi = 0``): ``sigma_0 = kappa_i E_w sinh(l/ell) /
(sinh(l/ell) - (1 - phi) sinh(m))``.  Elongation
``u = 2 [lam kappa_i tan(k xi)/k + sigma (h - xi)/E_w + sigma (l - h)/E]``.

Along the path (checked numerically for E=2e4, phi in {0.5, 0.9, 0.99}, kappa_i=1e-4,
L in {20, 100, 1000}, W=10, c in {0.5, 1, 2, 4, 25}): ``xi``, ``ebar_centre``, the
elongation *and* ``sigma`` all increase monotonically (perfect damage with a nonlocal
``ebar`` gives a slightly hardening response, ``E_w kappa_i < sigma < E kappa_i``; no
snap-back), every damaged point keeps loading and the elastic parts stay below
``kappa_i``.  The path ends when the band reaches the weak-zone edge (``xi -> W/2``).
For ``sqrt(c) << W`` the response is flat to round-off (``sigma ~ E_w kappa_i``).
"""
from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import brentq


@dataclass(frozen=True)
class PerfectDamageBar:
    """Bar data: ``E`` [MPa], ``phi`` = E_w/E [-], ``kappa_i`` [-], ``c`` [mm^2],
    length ``L`` [mm], weak-zone width ``W`` [mm], cross-section ``A`` [mm^2]."""

    E: float
    phi: float
    kappa_i: float
    c: float
    L: float
    W: float
    A: float = 1.0


def _cosh_ratio(a, b):
    """cosh(a)/cosh(b) for 0 <= a, b without overflow."""
    return np.exp(a - b) * (1.0 + np.exp(-2.0 * a)) / (1.0 + np.exp(-2.0 * b))


def _sinh_ratio(a, b):
    """sinh(a)/sinh(b) for 0 <= a <= b, b > 0, without overflow."""
    return np.exp(a - b) * -np.expm1(-2.0 * a) / -np.expm1(-2.0 * b)


def _beta(bar, xi):
    """(1 - phi) sinh(m)/cosh(rho), overflow-safe."""
    ell = np.sqrt(bar.c)
    m, rho = (bar.L - bar.W) / (2 * ell), (bar.L / 2 - xi) / ell
    return (1 - bar.phi) * np.exp(m - rho) * -np.expm1(-2 * m) / (1 + np.exp(-2 * rho))


@dataclass(frozen=True)
class BarState:
    """Equilibrium state of the bar.

    Attributes
    ----------
    xi : float
        Damaged band half-width [mm]; the band width is ``2*xi`` (0 if undamaged).
    sigma : float
        Uniform stress [MPa].
    force : float
        Axial force ``sigma*A`` [N].
    ebar_centre : float
        Nonlocal equivalent strain at ``x = L/2`` [-].
    elongation : float
        ``u(L) - u(0)`` [mm].
    bar : PerfectDamageBar
        The bar this state belongs to (used by :meth:`ebar`).
    """

    xi: float
    sigma: float
    force: float
    ebar_centre: float
    elongation: float
    bar: PerfectDamageBar = field(repr=False, compare=False, default=None)

    def ebar(self, s):
        """Nonlocal equivalent strain [-] at ``s = x - L/2`` [mm] (vectorised, even in s)."""
        b, sig, xi = self.bar, self.sigma, self.xi
        s = np.minimum(np.abs(np.asarray(s, dtype=float)), b.L / 2)
        ell, h, l, Ew = np.sqrt(b.c), b.W / 2, b.L / 2, b.phi * b.E
        front = b.kappa_i if xi > 0 else self.ebar_centre  # ebar(xi)
        delta, m, d = 1 / Ew - 1 / b.E, (l - h) / ell, (h - xi) / ell
        T, v0 = np.tanh(m), front - sig / Ew  # v = ebar - sigma/E_w in the weak zone
        vh = (v0 / np.cosh(d) - sig * delta * T * np.tanh(d)) / (1 + T * np.tanh(d))  # v(h)
        sw = np.clip(s, xi, h)
        weak = sig / Ew + v0 * _sinh_ratio((h - sw) / ell, d) + vh * _sinh_ratio((sw - xi) / ell, d)
        outer = sig / b.E + (vh + sig * delta) * _cosh_ratio((l - s) / ell, m)
        out = np.where(s < h, weak, outer)
        if xi > 0:
            k = np.sqrt(max(sig / (Ew * b.kappa_i) - 1, 0.0)) / ell
            out = np.where(s < xi, self.ebar_centre * np.cos(k * s), out)
        return out


def _elastic_state(bar, sigma):
    """Undamaged state at stress ``sigma`` (linear scaling of the onset profile)."""
    on = onset_state(bar)
    r = sigma / on.sigma
    return BarState(0.0, float(sigma), float(sigma * bar.A), r * on.ebar_centre,
                    r * on.elongation, bar)


def onset_state(bar):
    """State at damage onset (``xi = 0``, ``ebar(L/2) = kappa_i``, stress ``sigma_0``)."""
    return state_at_band_halfwidth(bar, 0.0)


def state_at_band_halfwidth(bar, xi):
    """State with damaged band ``|x - L/2| < xi`` [mm], ``0 <= xi < W/2``.

    Raises
    ------
    ValueError
        If ``xi`` is negative or the band would reach the weak-zone edge (``xi >= W/2``).
    """
    xi = float(xi)
    if not 0.0 <= xi < bar.W / 2:
        raise ValueError(f"xi = {xi} outside [0, W/2 = {bar.W / 2}): band must stay in weak zone")
    ell, Ew, ki = np.sqrt(bar.c), bar.phi * bar.E, bar.kappa_i
    beta, tr = _beta(bar, xi), np.tanh((bar.L / 2 - xi) / ell)
    if xi == 0.0:
        q = np.sqrt(beta / (tr - beta))
    else:
        qmax = 0.5 * np.pi * ell / xi
        g = lambda q: q * np.tan(q * xi / ell) + q**2 * tr - (1 + q**2) * beta
        q = brentq(g, 0.0, qmax * (1 - 1e-14), xtol=1e-15, rtol=1e-15, maxiter=500)
    lam, k = 1 + q**2, q / ell
    sigma = lam * Ew * ki
    damaged = lam * ki * np.tan(k * xi) / k if xi > 0 else 0.0
    u = 2 * (damaged + sigma * (bar.W / 2 - xi) / Ew + sigma * (bar.L - bar.W) / (2 * bar.E))
    return BarState(xi, float(sigma), float(sigma * bar.A), float(ki / np.cos(k * xi)),
                    float(u), bar)


def state_at_centre_ebar(bar, ebar0):
    """State with ``ebar(L/2) = ebar0`` [-]; ``ebar0 < kappa_i`` gives the elastic state.

    ``ebar_centre`` increases monotonically with ``xi``, so the root is unique.

    Raises
    ------
    ValueError
        If ``ebar0`` would require the band to leave the weak zone.
    """
    if ebar0 <= bar.kappa_i:
        on = onset_state(bar)
        return _elastic_state(bar, on.sigma * ebar0 / bar.kappa_i)
    xmax = bar.W / 2 * (1 - 1e-12)
    if ebar0 > state_at_band_halfwidth(bar, xmax).ebar_centre:
        raise ValueError(f"ebar0 = {ebar0} needs a damaged band wider than the weak zone")
    f = lambda xi: state_at_band_halfwidth(bar, xi).ebar_centre - ebar0
    return state_at_band_halfwidth(bar, brentq(f, 0.0, xmax, xtol=1e-14, rtol=1e-14))


def state_at_end_displacement(bar, u_end, n_check=400):
    """State with elongation ``u_end`` [mm]; ``u_end`` up to the onset value is elastic.

    Requires the elongation to increase with ``xi`` (true for typical data, see the
    module docstring); this is checked on ``n_check`` samples of ``xi``.

    Raises
    ------
    ValueError
        If the post-onset path is not monotonic in elongation (snap-back) or
        ``u_end`` needs a band wider than the weak zone.
    """
    on = onset_state(bar)
    if u_end <= on.elongation:
        return _elastic_state(bar, on.sigma * u_end / on.elongation)
    xis = np.linspace(0.0, bar.W / 2 * (1 - 1e-12), n_check)
    us = np.array([state_at_band_halfwidth(bar, x).elongation for x in xis])
    if np.any(np.diff(us) < -1e-12 * us[-1]):  # tolerance: round-off plateau for small c
        raise ValueError("snap-back: elongation is not monotonic in xi along the damage "
                         "path; use state_at_centre_ebar / state_at_band_halfwidth instead")
    if u_end > us[-1]:
        raise ValueError(f"u_end = {u_end} needs a damaged band wider than the weak zone")
    f = lambda xi: state_at_band_halfwidth(bar, xi).elongation - u_end
    return state_at_band_halfwidth(bar, brentq(f, 0.0, xis[-1], xtol=1e-14, rtol=1e-14))
