"""The model's own (form) error: a std sigma_m per group of data blocks, identified with the parameters.

The data are y_exp = h(x) + b + e, e ~ N(0, C) (measurement, and the mesh's error when it is added) and the
model error b ~ N(0, sigma_m^2 B) on each group of blocks: B = I (``kind = "variance"``: independent errors) or a
smooth kernel along the control (``kind = "bias"``, a Gaussian process: Kennedy and O'Hagan 2001), so that
C_s = C + sum_g sigma_g^2 B_g (:func:`with_model_error`).

sigma_m is estimated at the method's estimate x (residual r = y_exp - h(x), sensitivities J there) as the mode of
its posterior in log sigma, with the parameters integrated out by Laplace's approximation (:func:`log_marginal`):

    log p(sigma | y) = -1/2 r^T C_s^-1 r - 1/2 log det C_s - 1/2 log det(J^T C_s^-1 J + C0^-1) + log p(log sigma),

C0 the parameters' prior covariance (uniform over the bounds). The third term counts the degrees of freedom the
parameters take from the residual (for a linear model the estimate is then the restricted maximum likelihood
one, unbiased). The identification is then run again with C_s, and the two repeated to a fixed point
(:mod:`fracid.inverse.likelihood.terms`). Priors (:func:`log_prior`): half-Cauchy of scale ``scale`` x the group's
largest ``|y_exp|``, or log-uniform; the range is ``bounds`` x that value.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import minimize_scalar

from fracid.data.covariance_update import low_rank_update, plus_diagonal
from fracid.inverse.likelihood.correlation import block_modes

#: points of the grid in log sigma that brackets the mode before the bounded 1-D search (and of the posterior's
#: quadrature, :mod:`fracid.inverse.likelihood.marginal`)
GRID_POINTS = 41
#: sweeps over the groups (coordinate ascent) at most; one is enough for one group
SWEEPS = 4


@dataclass(frozen=True)
class ErrorGroups:
    """The groups of data blocks that share one sigma_m.

    Attributes
    ----------
    names : list of str
        Per group: its blocks' names joined by ``+``.
    blocks : list of list of str
        The blocks of each group.
    indices : list of ndarray
        The entries of y of each group.
    scales : ndarray
        The largest ``|y_exp|`` of each group [units of y]: the prior's scale and the bounds are fractions of it.
    modes : list of ndarray or None
        ``kind = "bias"``: the unit modes (n, r_g) of the kernel along the control on the group's entries; None for
        independent errors.
    """

    names: list
    blocks: list
    indices: list
    scales: np.ndarray
    modes: list


def error_groups(settings, blocks, quantities, y_exp, control) -> ErrorGroups:
    """The groups of ``settings.groups`` (one per block, or per observed quantity) over ``blocks``
    ((name, start, stop)) with their ``quantities`` (one per block; empty: all alike) and ``control`` [mm]."""
    y_exp = np.asarray(y_exp, float)
    keys = [name for name, _, _ in blocks] if settings.groups == "block" else \
        [quantities[i] if i < len(quantities) else "" for i in range(len(blocks))]
    order = list(dict.fromkeys(keys))
    grouped = [[b for b, key in zip(blocks, keys) if key == k] for k in order]
    indices = [np.concatenate([np.arange(start, stop) for _, start, stop in members]) for members in grouped]
    modes = [None if settings.kind == "variance" else block_modes(np.ones(y_exp.size), control, members,
                                                                  settings.correlation_length)
             for members in grouped]
    return ErrorGroups(["+".join(name for name, _, _ in members) for members in grouped],
                       [[name for name, _, _ in members] for members in grouped], indices,
                       np.array([max(float(np.max(np.abs(y_exp[i]))), np.finfo(float).tiny) for i in indices]), modes)


def with_model_error(base, sigma, groups: ErrorGroups):
    """C_s = base + sum_g sigma_g^2 B_g (module docstring); ``sigma`` per group [units of y]."""
    sigma = np.asarray(sigma, float)
    if groups.modes[0] is None:
        add = np.zeros(base.n)
        for s, index in zip(sigma, groups.indices):
            add[index] = s**2
        return plus_diagonal(base, add)
    return low_rank_update(base, np.hstack([s * modes for s, modes in zip(sigma, groups.modes)]))


def log_prior(sigma, scale, settings) -> np.ndarray:
    """log p(log sigma) up to a constant: half-Cauchy of scale ``settings.scale`` x ``scale`` (with the Jacobian
    sigma of the change to log sigma), or log-uniform (0)."""
    sigma = np.asarray(sigma, float)
    if settings.prior == "log-uniform":
        return np.zeros_like(sigma)
    return np.log(sigma) - np.log1p((sigma / (settings.scale * scale)) ** 2)


def log_marginal(sigma, residual, J, base, groups: ErrorGroups, precision, settings) -> float:
    """log p(sigma | y) up to a constant, Laplace's approximation at the estimate (module docstring).

    Parameters
    ----------
    sigma : array_like
        sigma_m per group [units of y].
    residual : ndarray, shape (n,)
        y_exp - h(x) at the estimate.
    J : ndarray, shape (n, p)
        dh/dx at the estimate.
    base : Covariance
        C: the measurement covariance (with the mesh's error when added).
    precision : ndarray, shape (p, p)
        C0^-1, the parameters' prior precision.
    """
    C = with_model_error(base, sigma, groups)
    W = C.whiten(J)
    information = np.linalg.slogdet(W.T @ W + precision)[1]
    value = -0.5 * (C.quadratic(residual) + C.logdet() + information)
    return float(value + np.sum(log_prior(sigma, groups.scales, settings)))


def estimate_sigma(residual, J, base, groups: ErrorGroups, precision, settings) -> np.ndarray:
    """The mode of p(log sigma | y) (:func:`log_marginal`) within the bounds: per group a grid in log sigma, then a
    bounded 1-D search around its best point; coordinate ascent over the groups.

    Returns
    -------
    ndarray
        sigma_m per group [units of y].
    """
    lower, upper = (np.log(np.asarray(settings.bounds, float)[k] * groups.scales) for k in (0, 1))
    sigma = np.sqrt(np.array([max(np.mean(np.asarray(residual)[i] ** 2), 1e-300) for i in groups.indices]))
    sigma = np.clip(sigma, np.exp(lower), np.exp(upper))
    for sweep in range(SWEEPS if len(groups.names) > 1 else 1):
        before = sigma.copy()
        for g in range(len(sigma)):
            sigma[g] = _best_in_log(lambda s: log_marginal(_set(sigma, g, s), residual, J, base, groups, precision,
                                                           settings), lower[g], upper[g])
        if sweep and np.allclose(sigma, before, rtol=1e-3):
            break
    return sigma


def _set(sigma, g, value):
    out = sigma.copy()
    out[g] = value
    return out


def _best_in_log(f, lower: float, upper: float) -> float:
    """The sigma in [e^lower, e^upper] maximising f(sigma): a grid in log sigma, then Brent's bounded search
    between the best point's neighbours."""
    grid = np.linspace(lower, upper, GRID_POINTS)
    values = np.array([f(np.exp(u)) for u in grid])
    best = int(np.argmax(values))
    lo, hi = grid[max(best - 1, 0)], grid[min(best + 1, grid.size - 1)]
    found = minimize_scalar(lambda u: -f(np.exp(u)), bounds=(lo, hi), method="bounded",
                            options={"xatol": 1e-4})
    return float(np.exp(found.x if -found.fun >= values[best] else grid[best]))


__all__ = ["GRID_POINTS", "ErrorGroups", "error_groups", "estimate_sigma", "log_marginal", "log_prior",
           "with_model_error"]
