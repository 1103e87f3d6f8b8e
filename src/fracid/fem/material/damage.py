"""Damage evolution: exponential softening law and the history (Kuhn-Tucker) update."""

from __future__ import annotations

import numpy as np


def exponential_damage(kappa, kappa_i, alpha, beta):
    """Exponential softening law omega(kappa) and its derivative.

    omega = 0 for kappa < kappa_i, and
    omega = 1 - (kappa_i / kappa) (1 - alpha + alpha exp(-beta (kappa - kappa_i))) otherwise.

    Parameters
    ----------
    kappa : array_like
        History variable (largest equivalent strain reached) [-].
    kappa_i, alpha, beta : float
        Damage threshold [-], residual-stress parameter [-], softening rate [-].

    Returns
    -------
    omega, d_omega_d_kappa : ndarray
        Damage [-] and its derivative with respect to kappa; both zero below the threshold.
    """
    kappa = np.asarray(kappa, dtype=float)
    damaged = kappa >= kappa_i
    k = np.where(damaged, kappa, kappa_i)
    decay = np.exp(-beta * (k - kappa_i))
    g = 1.0 - alpha + alpha * decay
    omega = np.where(damaged, 1.0 - kappa_i / k * g, 0.0)
    d_omega = np.where(damaged, kappa_i / k * (g / k + alpha * beta * decay), 0.0)
    return omega, d_omega


def exponential_damage_parameter_derivatives(kappa, kappa_i, alpha, beta) -> dict:
    """Partial derivatives of :func:`exponential_damage` at fixed kappa with respect to its parameters.

    Returns
    -------
    dict {"kappa_i", "alpha", "beta": ndarray}
        d omega / d kappa_i [-], d omega / d alpha [-], d omega / d beta [-]; zero below the
        threshold (at kappa = kappa_i exactly, the derivative of the damaged branch).
    """
    kappa = np.asarray(kappa, dtype=float)
    damaged = kappa >= kappa_i
    k = np.where(damaged, kappa, kappa_i)
    decay = np.exp(-beta * (k - kappa_i))
    g = 1.0 - alpha + alpha * decay
    ratio = np.where(damaged, kappa_i / k, 0.0)
    return {
        "kappa_i": np.where(damaged, -(g + kappa_i * alpha * beta * decay) / k, 0.0),
        "alpha": ratio * (1.0 - decay),
        "beta": ratio * alpha * decay * (k - kappa_i),
    }


def update_history(kappa_old, driving):
    """Kuhn-Tucker update of the history variable.

    kappa = max(kappa_old, driving); the point is loading (d kappa / d driving = 1) where the driving
    strain reaches the history, unloading (derivative 0) where it is below. Neutral loading counts
    as loading: at the first iteration of a step (driving = kappa_old at the points that were loading)
    the tangent then continues the last step's loading pattern instead of starting from the secant
    stiffness, which is what keeps Newton from cycling near the peak.

    Returns
    -------
    kappa : ndarray
    loading : ndarray of bool
    """
    loading = driving >= kappa_old
    return np.where(loading, driving, kappa_old), loading


def kappa_at_damage(omega, kappa_i, alpha, beta):
    """Inverse of :func:`exponential_damage`: the kappa at which the damage reaches ``omega``.

    ``omega = 0`` returns ``kappa_i``. Raises ValueError if the law never reaches ``omega``.
    """
    from scipy.optimize import brentq

    if omega <= 0.0:
        return kappa_i
    # kappa_i / kappa -> 0, so omega -> 1 for every alpha and beta: any omega < 1 is reached
    if omega >= 1.0:
        raise ValueError(f"damage threshold omega = {omega} is never reached; it must be in [0, 1)")
    hi = kappa_i * 2.0
    while exponential_damage(hi, kappa_i, alpha, beta)[0] < omega:
        hi *= 2.0
    return brentq(lambda k: exponential_damage(k, kappa_i, alpha, beta)[0] - omega, kappa_i, hi, xtol=1e-14 * hi)
