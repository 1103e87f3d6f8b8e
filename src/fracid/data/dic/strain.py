"""Strain maps of a displacement field: a local least-squares plane fit at every point, the same for data and
model.

A DIC field is noisy at the scale of its step; its strains are the gradients of a plane fitted to the
displacements within ``radius`` of each point (the plane fit of :func:`~fracid.data.dic.estimators.plane_fit_rows`,
applied at every point at once). Applied alike to the measured and the computed displacements at the same
points, it biases neither: the difference of the two maps is the model's error, smoothed the same way. A rigid
motion leaves the strains zero (a translation has no gradient; a small rotation's gradient is antisymmetric and
leaves eps_xy unchanged).

Units: positions and radius [mm], displacements [mm], strains [-].
"""

from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree

__all__ = ["default_radius", "plane_gradients", "principal_strain", "strain_components"]


def default_radius(points) -> float:
    """2.5 times the median distance from a point to its nearest neighbour [mm]: about 20 points in a window
    (repeated points, e.g. one per frame and component, counted once)."""
    points = np.unique(np.asarray(points, float), axis=0)
    if len(points) < 2:
        return 1.0
    distances, _ = cKDTree(points).query(points, k=2)
    return 2.5 * float(np.median(distances[:, 1]))


def plane_gradients(points, values, radius: float) -> np.ndarray:
    """(d/dx, d/dy) of ``values`` at every point [value per mm], shape (n, 2): the plane fitted by least squares
    to the finite values within ``radius``; NaN where fewer than 3 points not on a line are in the window."""
    points, values = np.asarray(points, float), np.asarray(values, float)
    finite = np.isfinite(values)
    gradients = np.full((len(points), 2), np.nan)
    for i, window in enumerate(cKDTree(points[finite]).query_ball_point(points, radius)):
        if len(window) < 3:
            continue
        near = np.flatnonzero(finite)[window]
        X = np.column_stack([np.ones(near.size), points[near] - points[i]])
        coefficients, _, rank, _ = np.linalg.lstsq(X, values[near], rcond=None)
        if rank == 3:
            gradients[i] = coefficients[1:]
    return gradients


def strain_components(points, u, v, radius: float) -> tuple:
    """(eps_xx, eps_yy, eps_xy) [-] at every point from the displacements u (x) and v (y) [mm]; ``v`` None gives
    eps_xx only (the others NaN)."""
    du = plane_gradients(points, u, radius)
    if v is None:
        nan = np.full(len(du), np.nan)
        return du[:, 0], nan, nan
    dv = plane_gradients(points, v, radius)
    return du[:, 0], dv[:, 1], 0.5 * (du[:, 1] + dv[:, 0])


def principal_strain(eps_xx, eps_yy, eps_xy) -> np.ndarray:
    """The largest principal strain [-] (eps_xx where the others are NaN: a field of u alone)."""
    eps_xx, eps_yy, eps_xy = (np.asarray(a, float) for a in (eps_xx, eps_yy, eps_xy))
    centre, radius = 0.5 * (eps_xx + eps_yy), np.hypot(0.5 * (eps_xx - eps_yy), eps_xy)
    return np.where(np.isnan(eps_yy), eps_xx, centre + radius)
