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

from fracid.fem.mesh.level_sets import superlevel_length, superlevel_length_derivative


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


def _line_values(sampler: AcrossSampler, values: np.ndarray, inside: np.ndarray) -> np.ndarray:
    """Samples (lines, m, ...) of point values (n_pts, ...) as the width measures them: a line holds its
    first inner value from the path on (the first points lie off the path)."""
    sampled = np.einsum("lmk...,lmk->lm...", values[np.maximum(sampler.simplices, 0)], sampler.weights)
    first = np.argmax(inside, axis=1)
    before = np.arange(inside.shape[1])[None, :] < first[:, None]
    held = sampled[np.arange(inside.shape[0]), first][:, None]
    mask = before.reshape(before.shape + (1,) * (sampled.ndim - 2))
    return np.where(mask, held, sampled)


def _line_lengths(sampler: AcrossSampler, kappa, kappa_threshold):
    """Sampled kappa per line (later samples outside the mesh count as below the threshold), and the
    length of {kappa > threshold} on each line."""
    inside = sampler.simplices[..., 0] >= 0
    values = _line_values(sampler, np.asarray(kappa, float), inside)
    below = kappa_threshold - 1.0 - abs(kappa_threshold)
    values = np.where(inside | (np.arange(inside.shape[1])[None, :] < np.argmax(inside, axis=1)[:, None]), values,
                      below)
    lengths = superlevel_length(sampler.across, values, kappa_threshold, sampler.across[0], sampler.across[-1])
    return values, np.atleast_1d(lengths), inside


def fpz_width(sampler: AcrossSampler, kappa, kappa_threshold, mirror: bool) -> float:
    """Largest extent, across the crack path, of the zone where kappa exceeds ``kappa_threshold``.

    On each sample line the extent is the measure of {kappa > threshold} (linear interpolation);
    the FPZ width is the largest over the lines, doubled when the model is a symmetric half
    (``mirror``).
    """
    _, lengths, _ = _line_lengths(sampler, kappa, kappa_threshold)
    width = float(np.max(lengths, initial=0.0))
    return 2.0 * width if mirror else width


def fpz_width_derivative(sampler: AcrossSampler, kappa, kappa_rate, kappa_threshold, threshold_rate,
                         mirror: bool) -> np.ndarray:
    """d/dx of :func:`fpz_width` (p parameters): the motion of the level-set crossings on the widest line.

    ``kappa_rate`` (n_pts, p) and ``threshold_rate`` (p,) are the derivatives of kappa and of the
    threshold. Not differentiable where two lines are equally wide (the derivative of the first of
    them is used) or where a sample sits on the threshold (see
    :func:`~fracid.fem.mesh.level_sets.superlevel_length_derivative`); zero while nothing exceeds it.
    """
    values, lengths, inside = _line_lengths(sampler, kappa, kappa_threshold)
    line = int(np.argmax(lengths))
    if lengths[line] <= 0.0:
        return np.zeros(np.shape(threshold_rate))
    rates = _line_values(sampler, np.asarray(kappa_rate, float), inside)[line]
    rates = np.where(np.isfinite(values[line])[:, None], rates, 0.0)
    width = superlevel_length_derivative(sampler.across, values[line], rates, kappa_threshold, threshold_rate)
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


class ZoneWidthObserver:
    """Observer f(problem, q, arrays) -> width [mm] of the zone where kappa > ``kappa_threshold``, for
    :func:`~fracid.fem.path.path_following.follow_path`: across the crack path in 2D (see :func:`fpz_width`;
    ``zone`` a :class:`~fracid.specimens.description.ZoneWidth`), along a bar in 1D.

    ``threshold_rate(names) -> (p,)``, the derivative of the threshold with respect to the
    parameters, makes the width differentiable (:meth:`derivative`, used by the direct
    differentiation of :mod:`fracid.fem.path.ddm`).
    """

    def __init__(self, zone, kappa_threshold: float, threshold_rate=None):
        self.zone, self.kappa_threshold, self.threshold_rate = zone, kappa_threshold, threshold_rate
        self._current = {}  # the problem of this run and its sampler: the mesh is looked up once per run

    def _sampler(self, problem):
        if self._current.get("problem") is not problem:
            points = problem.disc.points.reshape(-1, 2)
            self._current.update(problem=problem, sampler=cached_sampler(points, self.zone.axis, self.zone.along_range))
        return self._current["sampler"]

    def __call__(self, problem, q, arrays):
        points = problem.disc.points
        if points.shape[-1] == 1:
            start, end = self.zone.along_range
            return superlevel_length(points[..., 0].ravel(), arrays.history.ravel(), self.kappa_threshold, start, end)
        return fpz_width(self._sampler(problem), arrays.history.ravel(), self.kappa_threshold, self.zone.mirror)

    @property
    def differentiable(self) -> bool:
        return self.threshold_rate is not None

    def derivative(self, problem, kappa, kappa_rate, names) -> np.ndarray:
        """d width / dx (p,) [mm per unit parameter] at the state of history ``kappa`` with derivative
        ``kappa_rate`` (kappa.shape + (p,)). In 1D the zone is measured between the points, so its
        ends do not count: the derivative is that of the crossings inside the bar."""
        level_rate = np.asarray(self.threshold_rate(names), float)
        rates = kappa_rate.reshape(-1, kappa_rate.shape[-1])
        points = problem.disc.points
        if points.shape[-1] == 1:
            x = points[..., 0].ravel()
            order = np.argsort(x)
            return superlevel_length_derivative(x[order], kappa.ravel()[order], rates[order], self.kappa_threshold,
                                                level_rate)
        return fpz_width_derivative(self._sampler(problem), kappa.ravel(), rates, self.kappa_threshold, level_rate,
                                    self.zone.mirror)


def zone_width_observer(zone, kappa_threshold: float, threshold_rate=None) -> ZoneWidthObserver:
    """The :class:`ZoneWidthObserver` of ``zone`` at ``kappa_threshold`` (differentiable with ``threshold_rate``)."""
    return ZoneWidthObserver(zone, kappa_threshold, threshold_rate)
