"""Width of the fracture process zone (FPZ) measured across the crack path from the damage field."""

from __future__ import annotations

import numpy as np

from fracid.model.damage import kappa_at_damage


def fpz_width(points, kappa, kappa_threshold, axis: int, mirror: bool, along_range=(-np.inf, np.inf),
              spacing=None) -> float:
    """Largest extent, across the crack path, of the zone where kappa exceeds ``kappa_threshold``.

    The crack path is the line ``x_axis = 0`` (a symmetry line of the model). Integration points
    are grouped in bands along the path; in each band the damaged extent is the largest distance
    from the path of a damaged point plus half the local spacing of points (the extent a point
    represents). The FPZ width is the largest band value, doubled when the model is a symmetric
    half (``mirror``).

    Parameters
    ----------
    points : ndarray, shape (n, 2)
        Integration-point coordinates [mm].
    kappa : ndarray, shape (n,)
    kappa_threshold : float
    axis : int
        0 if the path is the line x = 0 (width measured along x), 1 if it is y = 0.
    mirror : bool
        Whether only one side of the path is modelled.
    along_range : (float, float)
        Part of the path considered [mm] (the ligament: damage at supports or platens is not FPZ).
    spacing : callable, optional
        ``_half_spacing`` of the points' distances from the path, when the caller has it already
        (the points do not change during an analysis).
    """
    along = points[:, 1 - axis]
    damaged = (kappa > kappa_threshold) & (along >= along_range[0]) & (along <= along_range[1])
    if not np.any(damaged):
        return 0.0
    across = np.abs(points[:, axis])
    # the bands are the distinct positions of points along the path (structured meshes)
    bands, band = np.unique(np.round(along[damaged], 9), return_inverse=True)
    extent = np.zeros(bands.size)
    spacing = spacing or _half_spacing(across)
    np.maximum.at(extent, band, across[damaged] + spacing(across[damaged]))
    width = float(extent.max())
    return 2.0 * width if mirror else width


def _half_spacing(coords):
    """Half the gap between consecutive distinct point coordinates, as a function of position."""
    levels = np.unique(np.round(coords, 9))
    gaps = np.diff(levels)
    half = 0.5 * np.concatenate([gaps[:1], np.minimum(gaps[1:], gaps[:-1]), gaps[-1:]]) if gaps.size else np.zeros(1)
    return lambda c: half[np.clip(np.searchsorted(levels, np.round(c, 9)), 0, levels.size - 1)]


def fpz_width_observer(params, damage_threshold: float, axis: int, mirror: bool, along_range=(-np.inf, np.inf)):
    """Observer f(problem, q, arrays) -> FPZ width [mm] for :func:`~fracid.model.path_following.follow_path`."""
    kappa_t = kappa_at_damage(damage_threshold, params.kappa_i, params.alpha, params.beta)

    cache = {}  # per problem: the points and their spacing across the path, computed once

    def observe(problem, q, arrays):
        if cache.get("problem") is not problem:
            points = problem.disc.points.reshape(-1, 2)
            cache.update(problem=problem, points=points, spacing=_half_spacing(np.abs(points[:, axis])))
        return fpz_width(cache["points"], arrays.kappa.ravel(), kappa_t, axis, mirror, along_range, cache["spacing"])

    return observe
