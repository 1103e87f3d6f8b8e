"""Measures of level sets of fields sampled along lines (the extent of a damaged or opened zone)."""

from __future__ import annotations

import numpy as np


def superlevel_length(x, values, level, start, end) -> float:
    """Length of {s in [start, end] : v(s) > level}, v the piecewise-linear interpolant of samples.

    Parameters
    ----------
    x : ndarray, shape (n,)
        Increasing sample positions inside [start, end] [mm].
    values : ndarray, shape (..., n)
        Samples (several lines at once along the leading axes); held constant beyond the first and
        last sample.
    level : float
    start, end : float
        Ends of the line [mm].

    Returns
    -------
    float or ndarray, shape (...)
        Measure of the superlevel set [mm]; linear interpolation makes it accurate to O(h^2) for a
        smooth field, unlike counting integration points.
    """
    x = np.asarray(x, dtype=float)
    v = np.asarray(values, dtype=float) - level
    v0, v1 = v[..., :-1], v[..., 1:]
    dx = np.diff(x)
    both = (v0 > 0) & (v1 > 0)
    cross = (v0 > 0) != (v1 > 0)
    denom = np.where(cross, v0 - v1, 1.0)
    t = np.clip(v0 / denom, 0.0, 1.0)  # where the level is crossed, as a fraction of the segment
    frac = np.where(v0 > 0, t, 1.0 - t)  # part of the segment above the level: before a leaving crossing, after an entering one
    length = np.sum(dx * both, axis=-1) + np.sum(dx * frac * cross, axis=-1)
    length = length + (x[0] - start) * (v[..., 0] > 0) + (end - x[-1]) * (v[..., -1] > 0)
    return float(length) if np.ndim(length) == 0 else length


def superlevel_length_derivative(x, values, rates, level, level_rate):
    """Derivative of :func:`superlevel_length` (on an open line: no ends beyond the samples).

    Parameters
    ----------
    x : ndarray, shape (n,)
    values : ndarray, shape (..., n)
        Samples v.
    rates : ndarray, shape (..., n, p)
        Their derivatives with respect to p parameters.
    level : float
    level_rate : ndarray, shape (p,)
        The level's derivatives.

    Returns
    -------
    ndarray, shape (..., p)
        Sum over the segments the level crosses of the crossing point's motion: a crossing at
        t = v0 / (v0 - v1) of a segment of length dx that leaves (enters) the superlevel set adds
        (-)dx d t. The measure is not differentiable where a sample equals the level (a crossing
        appears or disappears): the derivative is then the one of the side the samples are on, i.e.
        a sample at the level counts as below it, as in :func:`superlevel_length`.
    """
    x = np.asarray(x, dtype=float)
    v = np.asarray(values, dtype=float) - level
    dv = np.asarray(rates, dtype=float) - np.asarray(level_rate, dtype=float)
    v0, v1, dv0, dv1 = v[..., :-1], v[..., 1:], dv[..., :-1, :], dv[..., 1:, :]
    dx = np.diff(x)
    cross = (v0 > 0) != (v1 > 0)
    denom = np.where(cross, v0 - v1, 1.0)
    # t = v0 / (v0 - v1): dt = (dv0 (v0 - v1) - v0 (dv0 - dv1)) / (v0 - v1)^2 = (v0 dv1 - v1 dv0) / (v0 - v1)^2
    dt = (v0[..., None] * dv1 - v1[..., None] * dv0) / (denom**2)[..., None]
    sign = np.where(v0 > 0, 1.0, -1.0)  # leaving: the part above grows with t; entering: shrinks
    return np.sum(np.where(cross[..., None], (sign * dx)[..., None] * dt, 0.0), axis=-2)
