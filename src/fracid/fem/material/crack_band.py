"""Smeared crack band with a traction-separation law (Hordijk's by default): a rotating crack in plane
stress (docs/theory.md, section 5.3).

**Choice: rotating crack.** The crack normal follows the major principal direction of the
(effective) stress, which is that of the strain for an isotropic bulk: the crack is coaxial. A fixed
crack keeps the normal of crack initiation and needs a shear-retention factor, an extra parameter
that no force-CMOD curve identifies, and it locks stress when the principal directions turn after
cracking (spurious stress transfer across the band); the rotating crack has neither, and in mode I
(the notched beam, the tension test) the two coincide.

**The law.** With s = D eps the effective stress per unit E (D the unit plane-stress matrix), its
major principal value lambda_1 and the projectors P_1, P_2 on its principal directions, the crack
strain e_c n (x) n (n the major direction) takes the stress normal to the crack down to
(1 - omega) E lambda_1 and leaves the rest of the elastic response alone:

    sigma = E (s - omega <lambda_1> (P_1 + nu P_2))        (P_1 + nu P_2 = D (n (x) n) / D_nnnn),

so a crack transmits no Poisson stress across the band and a closed crack (lambda_1 <= 0) carries
compression. The history kappa is the largest lambda_1 reached (Rankine, in strain units). In
uniaxial tension the crack strain is e_c = (1 - nu^2) omega kappa, and omega(kappa) is set so that
the stress follows the traction-separation law sigma_L (:class:`~fracid.fem.material.tsl.TractionSeparationLaw`,
e.g. Hordijk's) of the crack opening w = h e_c, h the crack band width:

    E (kappa - w / h') = sigma_L(w),   h' = (1 - nu^2) h,

the stress of the band equal to the cohesive traction of its crack. The energy dissipated per unit
band volume is then Gf / h, per unit crack area Gf, whatever the element size. The equation has one
root in w when the band is narrower than the snap-back limit h' < E / max|d sigma_L / dw|
(:func:`snap_back_limit`); wider elements are refused. The law enters through a
:class:`~fracid.fem.material.tsl.ScaledLaw` (the law at the parameters, with the elements' strength factors).
"""

from __future__ import annotations

import numpy as np

from fracid.fem.material.damage import update_history


def major_principal(s):
    """Major principal value lambda_1 of stress-like tensors in Voigt components and d lambda_1 / ds.

    Parameters
    ----------
    s : ndarray, shape (..., 1) or (..., 3)
        A uniaxial value, or plane (sxx, syy, sxy).

    Returns
    -------
    lam : ndarray, shape (...)
    dlam : ndarray, shape s.shape
    """
    s = np.asarray(s, dtype=float)
    if s.shape[-1] == 1:
        return s[..., 0], np.ones_like(s)
    m, a, t, r = _plane_invariants(s)
    dlam = np.stack([0.5 + 0.5 * a / r, 0.5 - 0.5 * a / r, t / r], axis=-1)
    return m + r, dlam


def _plane_invariants(s):
    """m = (sxx + syy) / 2, a = (sxx - syy) / 2, sxy and r = sqrt(a^2 + sxy^2) (kept above 1e-12 ``|m|`` + 1e-30,
    see :func:`principal_tension`): lambda_1,2 = m +- r."""
    m = 0.5 * (s[..., 0] + s[..., 1])
    a = 0.5 * (s[..., 0] - s[..., 1])
    t = s[..., 2]
    return m, a, t, np.maximum(np.hypot(a, t), 1e-12 * np.abs(m) + 1e-30)


def principal_tension(s):
    """Major principal value of plane stress-like tensors, its tensile part on its projector, and
    their derivatives.

    Parameters
    ----------
    s : ndarray, shape (..., 3)
        Voigt components (sxx, syy, sxy).

    Returns
    -------
    lam : ndarray, shape (...)
        Major principal value lambda_1.
    F : ndarray, shape (..., 3)
        <lambda_1> P_1 in Voigt components (zero where lambda_1 <= 0).
    dF : ndarray, shape (..., 3, 3)
        dF_i / ds_j.
    dlam : ndarray, shape (..., 3)
        d lambda_1 / ds_j.

    Notes
    -----
    In 2D, P_1 = (s - lambda_2 I) / (lambda_1 - lambda_2), so with m = (sxx + syy) / 2,
    a = (sxx - syy) / 2, r = sqrt(a^2 + sxy^2) (lambda_1,2 = m +- r):
    lambda_1 P_1 = (m + r) / 2 (1, 1, 0) + (m / r + 1) / 2 (a, -a, sxy), a closed form with a
    closed-form derivative. At equal principal values (r = 0) the direction is undefined; r is kept
    above 1e-12 ``|m|`` + 1e-30 there (the damage term then acts along an arbitrary but fixed axis).
    """
    s = np.asarray(s, dtype=float)
    m, a, t, r = _plane_invariants(s)
    lam = m + r
    ones = np.array([1.0, 1.0, 0.0])
    u = np.stack([a, -a, t], axis=-1)
    g = 0.5 * (m / r + 1.0)
    dm = np.broadcast_to(0.5 * ones, s.shape)
    dr = np.stack([0.5 * a, -0.5 * a, t], axis=-1) / r[..., None]
    dg = 0.5 * (dm / r[..., None] - (m / r**2)[..., None] * dr)
    du = np.array([[0.5, -0.5, 0.0], [-0.5, 0.5, 0.0], [0.0, 0.0, 1.0]])
    dlam = dm + dr
    F = 0.5 * lam[..., None] * ones + g[..., None] * u
    dF = 0.5 * ones[:, None] * dlam[..., None, :] + u[..., :, None] * dg[..., None, :] + g[..., None, None] * du
    tensile = (lam > 0.0)[..., None]
    return lam, np.where(tensile, F, 0.0), np.where(tensile[..., None], dF, 0.0), dlam


def crack_direction_stress(s, nu):
    """The stress a fully open crack removes, <lambda_1> (P_1 + nu P_2), with lambda_1 and the
    derivatives d/ds of both (see :func:`principal_tension` for the arguments and shapes)."""
    lam, F1, dF1, dlam = principal_tension(s)
    tensile = (lam > 0.0)[..., None]
    ones = np.array([1.0, 1.0, 0.0])  # P_1 + P_2 = I
    F = (1.0 - nu) * F1 + nu * np.where(tensile, lam[..., None] * ones, 0.0)
    dF = (1.0 - nu) * dF1 + nu * np.where(tensile[..., None], ones[:, None] * dlam[..., None, :], 0.0)
    return lam, F, dF, dlam


def crack_direction_stress_nu_derivative(s):
    """d/d nu of :func:`crack_direction_stress` at fixed s: <lambda_1> P_2 = <lambda_1> (I - P_1)
    in Voigt components, shape (..., 3) (zero where lambda_1 <= 0)."""
    lam, F1, _, _ = principal_tension(s)
    return np.where((lam > 0.0)[..., None], lam[..., None] * np.array([1.0, 1.0, 0.0]) - F1, 0.0)


def snap_back_limit(E, law, params) -> float:
    """Widest crack band [mm] for which the band's stress-strain law has no snap-back:
    h_max = E / max_w ``|d sigma / dw|`` (the softening slope of the band, -1 / (1/E - h / ``|sigma'|``),
    must stay negative), with E [MPa] and the steepest slope of ``law`` at ``params``
    (``law.steepest_slope(params)`` [MPa/mm])."""
    return float(E / law.steepest_slope(params))


def band_damage(kappa, band_width, E, law, tol=1e-13, max_iterations=60):
    """Damage omega(kappa) of the crack band and d omega / d kappa.

    Solves E (kappa - w / h) = sigma(w) for the opening w in [0, h kappa] by Newton steps kept in
    a shrinking bracket (bisection when a step leaves it), all points at once; omega = w / (h kappa).

    Parameters
    ----------
    kappa : ndarray
        Largest major principal effective stress / E reached [-].
    band_width : ndarray
        Crack band width h at each point [mm], below :func:`snap_back_limit`.
    E : float or ndarray
        Young's modulus [MPa] at each point.
    law : ScaledLaw
        The traction-separation law at its parameters, point by point (:class:`~fracid.fem.material.tsl.ScaledLaw`):
        ``traction(w)``, ``strength()`` [MPa] and ``opening_scale()`` [mm] (the tolerance's unit).

    Returns
    -------
    omega, d_omega : ndarray
        Damage [-] (0 below kappa_0 = ft / E) and its derivative.
    """
    kappa, h, E, ft, scale = np.broadcast_arrays(*(np.asarray(v, dtype=float) for v in (
        kappa, band_width, E, law.strength(), law.opening_scale())))
    cracked = kappa > ft / E
    k = np.where(cracked, kappa, ft / E)
    lo, hi = np.zeros_like(k), h * k
    w = np.zeros_like(k)
    for _ in range(max_iterations):
        sigma, tangent = law.traction(w)
        g = E * (k - w / h) - sigma
        slope = -E / h - tangent  # < 0 below the snap-back limit
        lo, hi = np.where(g > 0.0, w, lo), np.where(g > 0.0, hi, w)
        step = np.where(cracked, -g / slope, 0.0)
        trial = w + step
        w = np.where((trial >= lo) & (trial <= hi), trial, 0.5 * (lo + hi))
        if np.all(np.abs(step) <= tol * scale):
            break
    slope = -E / h - law.traction(w)[1]
    dw = -E / slope
    omega = np.where(cracked, w / (h * k), 0.0)
    d_omega = np.where(cracked, dw / (h * k) - w / (h * k * k), 0.0)
    return omega, d_omega


def band_damage_parameter_derivatives(kappa, band_width, E, law):
    """Derivatives of the damage of :func:`band_damage` at fixed kappa, for the direct differentiation.

    From the band's equation g = E (kappa - w / h) - sigma(w) = 0 at fixed kappa:
    dw = -(dg/dx) / (dg/dw) with dg/dw = -E / h - sigma'(w), and omega = w / (h kappa).

    Parameters
    ----------
    kappa, band_width, E, law
        As in :func:`band_damage` (``law.parameter_derivatives(w)`` gives d sigma / d x at fixed w).

    Returns
    -------
    arguments : dict {"E", "band_width": ndarray}
        d omega / d E [1/MPa] and d omega / d h [1/mm] with respect to the arguments E and h (the
        caller chains them to the parameters: E = params.E times a stiffness factor, h the width
        times 1 - nu^2).
    law : dict {name: ndarray}
        d omega / d name [per unit parameter] for the law's parameters.
    All zero where the band has not cracked (kappa <= ft / E). At the onset kappa = ft / E, where
    omega leaves zero with a kink, the uncracked side's (zero) derivative is returned.
    """
    omega, _ = band_damage(kappa, band_width, E, law)
    kappa, h, E, ft = np.broadcast_arrays(*(np.asarray(v, dtype=float) for v in (kappa, band_width, E, law.strength())))
    cracked = kappa > ft / E
    k = np.where(cracked, kappa, 1.0)
    w = omega * h * k
    slope = -E / h - law.traction(w)[1]  # dg / dw < 0
    per_opening = np.where(cracked, 1.0 / (h * k), 0.0)  # d omega / d w at fixed h, kappa
    arguments = {"E": per_opening * (-(k - w / h) / slope),
                 "band_width": per_opening * (-E * w / (h * h * slope)) - np.where(cracked, w / (h * h * k), 0.0)}
    rates = {name: per_opening * rate / slope for name, rate in law.parameter_derivatives(w).items()}
    return arguments, rates


def element_mean(values, weights):
    """Weighted mean over the integration points of each element, broadcast back to the points."""
    values = np.broadcast_to(values, weights.shape)
    return np.broadcast_to((np.sum(values * weights, axis=1) / np.sum(weights, axis=1))[:, None], weights.shape)


def crack_band_stress(s, kappa_old, weights, band_width, E, nu, law, crackable=1.0):
    """Stress, material tangent and history of the rotating crack band at all points.

    Each element cracks as one band: its history kappa is the largest weighted mean over its points
    of the major principal effective stress / E, and one damage omega acts at all its points (each
    along its own principal direction). Point-wise damage would let the crack localise in one row
    of integration points, narrower than the band width the law is scaled by, and makes Newton's
    method stall on the alternating loading and unloading of neighbouring points.

    Parameters
    ----------
    s : ndarray, shape (n_el, n_q, 3)
        Effective stress per unit E, D eps [-].
    kappa_old : ndarray, shape (n_el, n_q)
        History of the last converged step (equal at the points of an element) [-].
    weights : ndarray, shape (n_el, n_q)
        Integration weights [mm^3].
    band_width : ndarray, shape (n_el, 1) or (n_el, n_q)
        [mm].
    E : ndarray, shape (n_el, n_q)
        Young's modulus [MPa] (element means are used).
    nu : float
        Poisson's ratio [-].
    law : ScaledLaw
        The traction-separation law at its parameters, its factors equal at the points of an element
        (:func:`element_mean`).
    crackable : float or ndarray, shape (n_el, n_q)
        1 where a crack may form, 0 where the material stays elastic.

    Returns
    -------
    sigma : ndarray, shape (n_el, n_q, 3)
        Stress [MPa].
    dsigma_ds : ndarray, shape (n_el, n_q, 3, 3)
        d sigma_q / d s_q [MPa], the point-wise part of the tangent.
    coupling : tuple of two ndarrays, shape (n_el, n_q, 3)
        (a, b) with d sigma_q / d s_p = dsigma_ds_q delta_qp - a_q (x) b_p within an element: the
        softening of the element's common damage.
    kappa, omega : ndarray, shape (n_el, n_q)
    """
    lam, F, dF, dlam = crack_direction_stress(s, nu)
    share = weights / np.sum(weights, axis=1, keepdims=True)
    kappa, loading = update_history(kappa_old, element_mean(lam, weights))
    h = (1.0 - nu * nu) * np.broadcast_to(band_width, weights.shape)
    mean = lambda v: element_mean(v, weights)  # noqa: E731
    omega, d_omega = (mean(crackable) * v for v in band_damage(kappa, h, mean(E), law))
    sigma = E[..., None] * (s - omega[..., None] * F)
    dsigma = E[..., None, None] * (np.eye(3) - omega[..., None, None] * dF)
    coupling = (E[..., None] * F, (d_omega * loading * share)[..., None] * dlam)
    return sigma, dsigma, coupling, kappa, omega
