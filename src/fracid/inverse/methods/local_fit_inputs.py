"""Inputs shared by the local fits (the Kalman filter and Gauss-Newton): the checked data and prior, and the box.

Both fits take the same Bayesian problem (measured ``y_exp`` with covariance ``C_exp``, prior ``N(x0, C0)``)
inside the same box of bounds, and mark a parameter on a bound the same way, so these checks live here once.
"""

from __future__ import annotations

import numpy as np

from fracid.data.covariance_matrix import as_covariance

__all__ = ["BOUND_TOLERANCE", "at_bound", "box", "check_inputs", "snap_to_bounds"]

#: Distance to a bound, relative to the box's span, within which a parameter is on it: the solvers' tolerance.
BOUND_TOLERANCE = 1e-9


def check_inputs(y_exp, C_exp, x0, C0):
    """The data and prior of a local fit as arrays, checked.

    Parameters
    ----------
    y_exp : array_like
        Measured observations (n,).
    C_exp : array_like or Covariance
        Their covariance; a scalar is a 1 x 1 covariance.
    x0 : array_like
        Prior mean (p,).
    C0 : array_like
        Prior covariance (p, p).

    Returns
    -------
    y_exp, C_exp, x0, C0
        y_exp and x0 as float arrays, C_exp as a :class:`~fracid.data.covariance_matrix.Covariance` of
        their size, C0 as a float (p, p) array.

    Raises
    ------
    ValueError
        When C_exp or C0 has the wrong size, or C0 is not symmetric positive definite.
    """
    y_exp, x0 = np.asarray(y_exp, float), np.asarray(x0, float)
    C_exp = as_covariance(C_exp if np.ndim(C_exp) != 0 else np.atleast_2d(C_exp), name="C_exp")
    if C_exp.n != y_exp.size:
        raise ValueError(f"C_exp has shape {C_exp.shape}; expected {(y_exp.size, y_exp.size)}")
    C0 = np.atleast_2d(np.asarray(C0, float))
    if C0.shape != (x0.size, x0.size):
        raise ValueError(f"C0 has shape {C0.shape}; expected {(x0.size, x0.size)}")
    if not np.allclose(C0, C0.T) or np.any(np.linalg.eigvalsh(0.5 * (C0 + C0.T)) <= 0):
        raise ValueError("C0 must be symmetric positive definite")
    return y_exp, C_exp, x0, C0


def box(bounds, p):
    """The box of ``bounds`` as two float arrays of p entries.

    Parameters
    ----------
    bounds : (lower, upper) or None
        Scalars or arrays broadcast to p entries; None: unbounded.
    p : int
        Number of parameters.

    Returns
    -------
    lower, upper : ndarray
        -inf and +inf when ``bounds`` is None.

    Raises
    ------
    ValueError
        When a lower bound is above its upper bound.
    """
    if bounds is None:
        return np.full(p, -np.inf), np.full(p, np.inf)
    lower, upper = (np.broadcast_to(np.asarray(b, float), (p,)).copy() for b in bounds)
    if np.any(lower > upper):
        raise ValueError(f"bounds: lower {lower.tolist()} above upper {upper.tolist()}")
    return lower, upper


def snap_to_bounds(x, lower, upper):
    """x with every entry within :data:`BOUND_TOLERANCE` of the box's span from a bound put on that bound.

    The solvers stop within their tolerance of an active bound; snapping makes the bound exact. An
    unbounded direction is measured against ``|x|`` + 1 instead of the span.
    """
    span = np.where(np.isfinite(upper - lower), upper - lower, np.abs(x) + 1.0)
    x = np.where(x - lower <= BOUND_TOLERANCE * span, lower, x)
    return np.where(upper - x <= BOUND_TOLERANCE * span, upper, x)


def at_bound(x, lower, upper):
    """Boolean mask of the entries of x within :data:`BOUND_TOLERANCE` of the box's span from a bound."""
    span = np.where(np.isfinite(upper - lower), upper - lower, 1.0)
    return (np.abs(x - lower) <= BOUND_TOLERANCE * span) | (np.abs(upper - x) <= BOUND_TOLERANCE * span)
