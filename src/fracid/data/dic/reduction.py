"""Data reduction of a dense DIC field: thinning the points to a spacing, with the covariance kept consistent.

A DIC export at a step of a few pixels holds tens of thousands of points per frame, but its errors are
correlated over a subset (:mod:`fracid.data.dic_noise`): points closer than about half a subset carry
nearly the same information. :func:`thinned` keeps at most one point per square cell of side ``spacing``
[mm] (the point nearest the cell's centre). The data block then holds the kept points only and its
covariance is the marginal of the full one at those entries (:meth:`Covariance.take`: the kernel evaluated
at the kept points), which is exactly the distribution of the kept values: no information is invented, the
likelihood stays consistent, only the information of the dropped points is given up. Thinning to a
spacing near the correlation length (subset_size / 2) keeps most of it at a fraction of the cost (the cost of
the probes and of the covariance grows with the number of points; the forward run does not).
"""

from __future__ import annotations

import numpy as np

from fracid.data.errors import DataError


def thinned(points, spacing: float) -> np.ndarray:
    """The mask of the points kept when thinning to ``spacing`` [mm]: one per occupied square cell.

    Parameters
    ----------
    points : array_like, shape (n, 2)
        Positions [mm].
    spacing : float
        Side of the cells [mm], > 0.

    Returns
    -------
    ndarray of bool, shape (n,)
        True for the point nearest the centre of each occupied cell (the first of equals).
    """
    if not (np.isscalar(spacing) and np.isfinite(spacing) and spacing > 0):
        raise DataError(f"point_spacing = {spacing!r} [mm]: give a number > 0 (the smallest distance kept between "
                        "points, about half the DIC subset size)")
    points = np.asarray(points, float)
    origin = points.min(axis=0)
    cell = np.floor((points - origin) / spacing).astype(np.int64)
    distance = np.hypot(*((points - origin) / spacing - cell - 0.5).T)
    order = np.lexsort((np.arange(len(points)), distance, cell[:, 1], cell[:, 0]))
    first = np.ones(len(order), dtype=bool)
    first[1:] = np.any(np.diff(cell[order], axis=0) != 0, axis=1)
    mask = np.zeros(len(points), dtype=bool)
    mask[order[first]] = True
    return mask


__all__ = ["thinned"]
