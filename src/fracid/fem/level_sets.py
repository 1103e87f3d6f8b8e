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
    frac = np.where(v0 > 0, v0 / denom, -v0 / denom)  # part of the segment above the level
    frac = np.where(v0 > 0, np.clip(frac, 0, 1), np.clip(1 - frac, 0, 1))
    length = np.sum(dx * both, axis=-1) + np.sum(dx * frac * cross, axis=-1)
    length = length + (x[0] - start) * (v[..., 0] > 0) + (end - x[-1]) * (v[..., -1] > 0)
    return float(length) if np.ndim(length) == 0 else length
