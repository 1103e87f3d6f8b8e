"""Modified von Mises equivalent strain, vectorised over integration points.

Every function takes strains as arrays with the components in the last axis (engineering shear
strains, gamma = 2 eps) and returns ``(eps_eq, d eps_eq / d strain)`` with the derivative taken with
respect to the same components. At a point where the deviatoric root vanishes (zero strain or a purely
volumetric strain) the root is not differentiable; its derivative is taken as zero there, a valid
subgradient, which only matters for the very first Newton iteration of a computation.
"""

from __future__ import annotations

import numpy as np


def _from_invariants(I1, J2, nu, eta):
    """eps_eq and its partial derivatives with respect to I1 and J2."""
    a = (eta - 1.0) / (1.0 - 2.0 * nu)
    root = np.sqrt(a * a * I1 * I1 + 12.0 * eta * J2 / (1.0 + nu) ** 2)
    eps_eq = (a * I1 + root) / (2.0 * eta)
    safe = np.where(root > 0.0, root, 1.0)
    has_root = root > 0.0
    d_I1 = (a + np.where(has_root, a * a * I1 / safe, 0.0)) / (2.0 * eta)
    d_J2 = np.where(has_root, 3.0 / ((1.0 + nu) ** 2 * safe), 0.0)
    return eps_eq, d_I1, d_J2


def modified_von_mises_3d(strain, nu, eta):
    """Equivalent strain of a 3D strain state.

    Parameters
    ----------
    strain : array_like, shape (..., 6)
        (exx, eyy, ezz, gxy, gyz, gzx), engineering shear strains [-].
    nu : float
        Poisson's ratio [-].
    eta : float
        Ratio of compressive to tensile strength [-].

    Returns
    -------
    eps_eq : ndarray, shape (...)
    d_eps_eq : ndarray, shape (..., 6)
        Derivative with respect to the six components.
    """
    e = np.asarray(strain, dtype=float)
    exx, eyy, ezz, gxy, gyz, gzx = np.moveaxis(e, -1, 0)
    I1 = exx + eyy + ezz
    J2 = (exx**2 + eyy**2 + ezz**2 - exx * eyy - eyy * ezz - ezz * exx) / 3.0 + (gxy**2 + gyz**2 + gzx**2) / 4.0
    eps_eq, d_I1, d_J2 = _from_invariants(I1, J2, nu, eta)
    dJ2 = np.stack(
        [(2 * exx - eyy - ezz) / 3.0, (2 * eyy - exx - ezz) / 3.0, (2 * ezz - exx - eyy) / 3.0, gxy / 2, gyz / 2, gzx / 2],
        axis=-1,
    )
    d = d_J2[..., None] * dJ2
    d[..., :3] += d_I1[..., None]
    return eps_eq, d


def _plane_stress_invariants(e, nu):
    """(k, s, I1, J2) of in-plane strains ``e`` (..., 3) with ezz = -k s, k = nu / (1 - nu), s = exx + eyy: in
    closed form (no 6-component state), I1 = (1 - k) s and J2 = (exx^2 + eyy^2 - exx eyy + k (k + 1) s^2) / 3
    + gxy^2 / 4."""
    exx, eyy, gxy = e[..., 0], e[..., 1], e[..., 2]
    k = nu / (1.0 - nu)
    s = exx + eyy
    return k, s, (1.0 - k) * s, (exx * exx + eyy * eyy - exx * eyy + k * (k + 1.0) * s * s) / 3.0 + 0.25 * gxy * gxy


def modified_von_mises_plane_stress(strain, nu, eta):
    """Equivalent strain in plane stress, with ezz = -nu/(1-nu) (exx + eyy) entering I1 and J2.

    Parameters
    ----------
    strain : array_like, shape (..., 3)
        In-plane strains (exx, eyy, gxy) [-].
    nu, eta : float
        Poisson's ratio and compressive/tensile strength ratio [-].

    Returns
    -------
    eps_eq : ndarray, shape (...)
    d_eps_eq : ndarray, shape (..., 3)
        Total derivative with respect to (exx, eyy, gxy), through ezz as well.
    """
    e = np.asarray(strain, dtype=float)
    exx, eyy, gxy = e[..., 0], e[..., 1], e[..., 2]
    k, s, I1, J2 = _plane_stress_invariants(e, nu)
    kk = 2.0 * k * (k + 1.0) * s
    eps_eq, d_I1, d_J2 = _from_invariants(I1, J2, nu, eta)
    d = np.empty(e.shape)
    volumetric = (1.0 - k) * d_I1
    d[..., 0] = volumetric + d_J2 * (2.0 * exx - eyy + kk) / 3.0
    d[..., 1] = volumetric + d_J2 * (2.0 * eyy - exx + kk) / 3.0
    d[..., 2] = d_J2 * 0.5 * gxy
    return eps_eq, d


def modified_von_mises_uniaxial(strain, nu, eta):
    """Equivalent strain of the uniaxial stress state (eps, -nu eps, -nu eps), for 1D models.

    In closed form eps_eq = ((eta - 1) eps + (eta + 1) ``|eps|``) / (2 eta): eps in tension, ``|eps|``/eta in
    compression, independent of nu.

    Parameters
    ----------
    strain : array_like, shape (..., 1)
        Axial strain [-].
    nu : float
        Poisson's ratio [-] (unused: the uniaxial value does not depend on it).
    eta : float
        Ratio of compressive to tensile strength [-].

    Returns
    -------
    eps_eq : ndarray, shape (...)
    d_eps_eq : ndarray, shape (..., 1)
    """
    e = np.asarray(strain, dtype=float)[..., 0]
    sign = np.sign(e)
    eps_eq = ((eta - 1.0) * e + (eta + 1.0) * np.abs(e)) / (2.0 * eta)
    d = ((eta - 1.0) + (eta + 1.0) * sign) / (2.0 * eta)
    return eps_eq, d[..., None]


def _invariant_parameter_derivatives(I1, J2, nu, eta):
    """d eps_eq / d nu and d eps_eq / d eta at fixed invariants I1, J2 (zero root: the root's terms dropped)."""
    a = (eta - 1.0) / (1.0 - 2.0 * nu)
    root = np.sqrt(a * a * I1 * I1 + 12.0 * eta * J2 / (1.0 + nu) ** 2)
    eps_eq = (a * I1 + root) / (2.0 * eta)
    has_root = root > 0.0
    safe = np.where(has_root, root, 1.0)
    d_a = (I1 + np.where(has_root, a * I1 * I1 / safe, 0.0)) / (2.0 * eta)
    d_nu = d_a * 2.0 * (eta - 1.0) / (1.0 - 2.0 * nu) ** 2 - np.where(has_root, 6.0 * J2 / ((1.0 + nu) ** 3 * safe), 0.0)
    d_eta = (d_a / (1.0 - 2.0 * nu) + np.where(has_root, 6.0 * J2 / ((1.0 + nu) ** 2 * safe), 0.0) / (2.0 * eta)
             - eps_eq / eta)
    return d_nu, d_eta


def modified_von_mises_plane_stress_parameter_derivatives(strain, nu, eta) -> dict:
    """Derivatives of :func:`modified_von_mises_plane_stress` at fixed in-plane strain.

    Returns
    -------
    dict {"nu", "eta": ndarray, shape (...)}
        d eps_eq / d nu (through the invariants' coefficients and ezz = -nu/(1-nu)(exx + eyy)) and
        d eps_eq / d eta [-].
    """
    k, s, I1, J2 = _plane_stress_invariants(np.asarray(strain, dtype=float), nu)
    _, d_I1, d_J2 = _from_invariants(I1, J2, nu, eta)
    d_nu, d_eta = _invariant_parameter_derivatives(I1, J2, nu, eta)
    d_ezz = -s / (1.0 - nu) ** 2
    d_nu = d_nu + (d_I1 - d_J2 * (2.0 * k + 1.0) * s / 3.0) * d_ezz
    return {"nu": d_nu, "eta": d_eta}


def modified_von_mises_uniaxial_parameter_derivatives(strain, nu, eta) -> dict:
    """Derivatives of :func:`modified_von_mises_uniaxial` at fixed strain: ``{"nu": 0, "eta": ...}``."""
    e = np.asarray(strain, dtype=float)[..., 0]
    eps_eq = ((eta - 1.0) * e + (eta + 1.0) * np.abs(e)) / (2.0 * eta)
    return {"nu": np.zeros_like(e), "eta": (e + np.abs(e)) / (2.0 * eta) - eps_eq / eta}
