"""Width of the fracture process zone (FPZ) measured across the crack path from the damage field.

The history variable kappa lives at integration points. It is interpolated linearly (on a Delaunay
triangulation of the points, built once per mesh) onto sample lines across the crack path, and on
each line the extent of {kappa > threshold} is found by linear interpolation between samples. The
width therefore varies continuously with the model parameters, which finite-difference
sensitivities of local data need: counting damaged points would make it a staircase of the element
size.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial import Delaunay, cKDTree

from fracid.fem.level_sets import superlevel_length


@dataclass(frozen=True)
class AcrossSampler:
    """Linear interpolation of a point field onto lines across the crack path.

    Attributes
    ----------
    across : ndarray, shape (m,)
        Distances from the path of the samples of each line [mm].
    simplices : ndarray of int, shape (lines, m, 3)
        Points of the triangle holding each sample (-1 outside the triangulation).
    weights : ndarray, shape (lines, m, 3)
        Barycentric weights of the samples.
    """

    across: np.ndarray
    simplices: np.ndarray
    weights: np.ndarray

    def __call__(self, values: np.ndarray) -> np.ndarray:
        """Samples (lines, m) of the field given at the points; NaN outside the triangulation."""
        sampled = np.einsum("lmk,lmk->lm", values[np.maximum(self.simplices, 0)], self.weights)
        return np.where(self.simplices[..., 0] >= 0, sampled, np.nan)


def across_sampler(points, axis: int, along_range=(-np.inf, np.inf), lines: int = 60,
                   samples_per_point: int = 4) -> AcrossSampler:
    """Sample lines across the path ``x_axis = 0`` at ``lines`` positions along ``along_range``.

    Samples are spaced a quarter of the fine point spacing (10th percentile of the nearest-neighbour
    distances; ``samples_per_point`` per spacing), from 0 to the farthest point.
    """
    points = np.asarray(points, float)
    along, across = points[:, 1 - axis], np.abs(points[:, axis])
    lo, hi = max(along_range[0], along.min()), min(along_range[1], along.max())
    positions = np.linspace(lo, hi, lines)
    # the finest point spacing (the refined zone at the path), robust to clustered points
    spacing = np.percentile(cKDTree(points).query(points, k=2)[0][:, 1], 10)
    s = np.linspace(0.0, across.max(), min(int(np.ceil(across.max() / spacing * samples_per_point)) + 1, 4000))
    grid = np.empty((lines, s.size, 2))
    grid[..., axis] = s[None, :]
    grid[..., 1 - axis] = positions[:, None]
    mirrored = points.copy()
    mirrored[:, axis] = across  # the field is symmetric about the path: one side is enough
    tri = Delaunay(mirrored)
    simplex = tri.find_simplex(grid.reshape(-1, 2))
    T = tri.transform[np.maximum(simplex, 0)]
    b = np.einsum("nij,nj->ni", T[:, :2], grid.reshape(-1, 2) - T[:, 2])
    weights = np.column_stack([b, 1.0 - b.sum(axis=1)]).reshape(lines, s.size, 3)
    simplices = np.where((simplex >= 0)[:, None], tri.simplices[np.maximum(simplex, 0)], -1)
    return AcrossSampler(s, simplices.reshape(lines, s.size, 3), weights)


def fpz_width(sampler: AcrossSampler, kappa, kappa_threshold, mirror: bool) -> float:
    """Largest extent, across the crack path, of the zone where kappa exceeds ``kappa_threshold``.

    On each sample line the extent is the measure of {kappa > threshold} (linear interpolation);
    the FPZ width is the largest over the lines, doubled when the model is a symmetric half
    (``mirror``).
    """
    values = sampler(np.asarray(kappa, float))
    inside = np.isfinite(values)
    # a line holds its first inner value from the path on (the first points lie off the path) and
    # ends at its last inner sample: later samples outside the mesh count as below the threshold
    first = np.argmax(inside, axis=1)
    before = np.arange(values.shape[1])[None, :] < first[:, None]
    values = np.where(before, values[np.arange(values.shape[0]), first][:, None], values)
    below = kappa_threshold - 1.0 - abs(kappa_threshold)
    lengths = superlevel_length(sampler.across, np.where(np.isfinite(values), values, below), kappa_threshold,
                                sampler.across[0], sampler.across[-1])
    width = float(np.max(lengths, initial=0.0))
    return 2.0 * width if mirror else width


_SAMPLERS: dict = {}  # a few meshes' samplers, so the runs of a study triangulate each mesh once


def cached_sampler(points, axis: int, along_range) -> AcrossSampler:
    """:func:`across_sampler` of ``points``, kept for the next run on the same mesh."""
    key = (hash(points.tobytes()), points.shape, axis, tuple(along_range))
    if key not in _SAMPLERS:
        if len(_SAMPLERS) >= 8:
            _SAMPLERS.pop(next(iter(_SAMPLERS)))
        _SAMPLERS[key] = across_sampler(points, axis, along_range)
    return _SAMPLERS[key]


def zone_width_observer(zone, kappa_threshold: float):
    """Observer f(problem, q, arrays) -> width [mm] of the zone where kappa > ``kappa_threshold``, for
    :func:`~fracid.fem.path_following.follow_path`: across the crack path in 2D (see :func:`fpz_width`;
    ``zone`` a :class:`~fracid.specimens.description.ZoneWidth`), along a bar in 1D."""
    current = {}  # the problem of this run and its sampler: the mesh is looked up once per run, not per step

    def observe(problem, q, arrays):
        points = problem.disc.points
        if points.shape[-1] == 1:
            start, end = zone.along_range
            return superlevel_length(points[..., 0].ravel(), arrays.kappa.ravel(), kappa_threshold, start, end)
        if current.get("problem") is not problem:
            current.update(problem=problem, sampler=cached_sampler(points.reshape(-1, 2), zone.axis, zone.along_range))
        return fpz_width(current["sampler"], arrays.kappa.ravel(), kappa_threshold, zone.mirror)

    return observe
