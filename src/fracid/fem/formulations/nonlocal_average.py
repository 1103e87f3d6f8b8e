"""Nonlocal averaging of the integral-type damage model, built once per mesh.

The nonlocal equivalent strain at integration point i is the weighted mean

    ebar_i = sum_j w_j psi(``|x_j - x_i|``) eps_j / sum_j w_j psi(``|x_j - x_i|``)

over the integration points j (w_j their volume weights), with the Gaussian weight
psi(rho) = exp(-rho^2 / (2 l^2)). Dividing by the sum of the weights is the boundary correction: a
uniform field is reproduced everywhere, also where the support of psi sticks out of the body. The
averaging is linear, so it is one sparse matrix A with ebar = A eps (rows sum to 1).

The internal length follows from the gradient model's parameter by the Taylor expansion of the
average (Peerlings et al. 1996): ebar = eps + l^2 / 2 lap(eps) + ..., so c = l^2 / 2 and the integral
model uses the same :class:`~fracid.fem.material.parameters.DamageParameters` as the gradient model.
"""

from __future__ import annotations

import collections
import hashlib
import itertools
import math
import threading
from typing import NamedTuple

import numpy as np
import scipy.sparse as sp
from scipy.spatial import cKDTree


def internal_length(c: float) -> float:
    """Internal length l = sqrt(2 c) [mm] of the Gaussian weight from the gradient parameter c [mm^2].

    Raises ValueError unless c is positive and finite.
    """
    if not (isinstance(c, (int, float, np.number)) and math.isfinite(c) and c > 0):
        raise ValueError(f"c = {c!r} mm^2; the integral damage model needs c > 0 (internal length l = sqrt(2 c))")
    return math.sqrt(2.0 * c)


def averaging_matrix(points, weights, length: float, cutoff: float = 4.0, mirror=()) -> sp.csr_matrix:
    """Row-normalised Gaussian averaging matrix A over the integration points: ebar = A @ eps.

    Parameters
    ----------
    points : array_like, shape (n_pts, dim)
        Coordinates of the integration points [mm], dim 1 or 2 (or 3); e.g.
        ``disc.points.reshape(-1, disc.points.shape[-1])``.
    weights : array_like, shape (n_pts,)
        Their integration weights (volume, with the cross-section or the thickness) [mm^3]; > 0.
    length : float
        Internal length l of psi(rho) = exp(-rho^2 / (2 l^2)) [mm], > 0.
    cutoff : float
        Truncation radius in units of l [-]. The default 4 l drops weights below
        exp(-8) = 3.4e-4 of the central one, which keeps A sparse.
    mirror : sequence of (axis, coordinate)
        Symmetry planes x[axis] = coordinate [mm] of a half or quarter model: the mirror images of
        the points across every plane and every combination of planes contribute with their own
        weight, so the average equals that of the whole specimen for a symmetric field. Points must
        not lie on a plane (integration points never do); without planes the cut is treated as a
        free boundary (boundary correction).

    Returns
    -------
    scipy.sparse.csr_matrix, shape (n_pts, n_pts)
        A_ij = w_j psi_ij / sum_k w_k psi_ik [-]: each row sums to 1.

    Notes
    -----
    The neighbour lists come from one :class:`scipy.spatial.cKDTree` query per image (one without
    planes), not from a loop over points.
    """
    rows, cols, values, _ = _gaussian_pairs(points, weights, length, cutoff, mirror)
    matrix = sp.csr_matrix((values, (rows, cols)), shape=(len(weights),) * 2)  # sums the images of a pair
    return _scale_rows(matrix, 1.0 / _row_sums(matrix))


def _row_sums(matrix: sp.csr_matrix) -> np.ndarray:
    return np.add.reduceat(matrix.data, matrix.indptr[:-1]) if matrix.nnz else np.zeros(matrix.shape[0])


def _scale_rows(matrix: sp.csr_matrix, factors) -> sp.csr_matrix:
    """diag(factors) @ matrix, in place (the product of a diagonal and a sparse matrix copies both twice)."""
    matrix.data *= np.repeat(factors, np.diff(matrix.indptr))
    return matrix


def averaging_length_derivative(points, weights, length: float, cutoff: float = 4.0, mirror=()) -> sp.csr_matrix:
    """d A / d l of :func:`averaging_matrix` [1/mm] (same arguments), for the direct differentiation.

    With W_ij = w_j psi_ij and s_i = sum_j W_ij, A = diag(1/s) W and d psi / d l = psi rho^2 / l^3, so
    dA/dl = diag(1/s) (W' - diag(s'/s) W). The truncation radius moves with l, but the weights it
    drops are exp(-cutoff^2 / 2) of the central one: their derivative is left out.
    """
    rows, cols, values, rho = _gaussian_pairs(points, weights, length, cutoff, mirror)
    n = len(weights)
    W = sp.csr_matrix((values, (rows, cols)), shape=(n, n))
    dW = sp.csr_matrix((values * rho**2 / length**3, (rows, cols)), shape=(n, n))
    s, ds = _row_sums(W), _row_sums(dW)
    return _scale_rows(dW - _scale_rows(W, ds / s), 1.0 / s)


def _gaussian_pairs(points, weights, length, cutoff, mirror):
    """Pairs (i, j) within ``cutoff`` l of each other (images across the planes included): rows, cols,
    the unnormalised weights w_j psi_ij and the distances rho_ij [mm]."""
    points = np.asarray(points, dtype=float)
    weights = np.asarray(weights, dtype=float)
    if points.ndim != 2 or weights.shape != (points.shape[0],):
        raise ValueError(f"points must be (n_pts, dim) and weights (n_pts,); got {points.shape} and {weights.shape}")
    if not (math.isfinite(length) and length > 0):
        raise ValueError(f"length = {length!r} mm; the internal length must be positive and finite")
    if not (math.isfinite(cutoff) and cutoff > 0):
        raise ValueError(f"cutoff = {cutoff!r}; it must be a positive number of internal lengths")
    if np.any(~np.isfinite(weights)) or np.any(weights <= 0):
        raise ValueError("every integration weight must be positive and finite")
    planes = [(int(axis), float(coordinate)) for axis, coordinate in mirror]
    if any(not 0 <= axis < points.shape[1] for axis, _ in planes):
        raise ValueError(f"mirror planes {planes}: the axis must be in [0, {points.shape[1]})")
    tree = cKDTree(points)
    rows, cols, distances = [], [], []
    for flips in itertools.product((False, True), repeat=len(planes)):
        image = points.copy()
        for (axis, coordinate), flip in zip(planes, flips):
            if flip:
                image[:, axis] = 2.0 * coordinate - image[:, axis]
        pairs = tree.sparse_distance_matrix(cKDTree(image), cutoff * length, output_type="ndarray")
        rows.append(pairs["i"])
        cols.append(pairs["j"])
        distances.append(pairs["v"])
    rows, cols, rho = (np.concatenate(a) for a in (rows, cols, distances))
    return rows, cols, weights[cols] * np.exp(-0.5 * (rho / length) ** 2), rho


class NonlocalAveraging(NamedTuple):
    """The averaging of one problem and the map of its integration points to the free dofs.

    Attributes
    ----------
    matrix : scipy.sparse.csr_matrix, shape (n_pts, n_pts)
        A of :func:`averaging_matrix`, over the points flattened in (element, point) order.
    self_weight : ndarray, shape (n_el, n_q)
        Its diagonal A_ii: the local part of the softening tangent, which fits the element matrices.
    point_dofs : ndarray of int, shape (n_pts, n_u)
        Free-dof number of each element displacement dof, repeated for the points of the element
        (-1: eliminated dof).
    n_free : int
        Number of free dofs.
    bound : CellBound
        The bound of the averages by cells of points (:func:`bounded_average`).
    rows : dict
        The rows of A that :func:`bounded_average` sliced last (``"mask"``, ``"matrix"``).
    """

    matrix: sp.csr_matrix
    self_weight: np.ndarray
    point_dofs: np.ndarray
    n_free: int
    bound: "CellBound"
    rows: dict


class CellBound(NamedTuple):
    """An upper bound of the averages A x from the maxima of x over cells of points (l by l squares).

    Attributes
    ----------
    order : ndarray of int, shape (n_pts,)
        The points sorted by cell.
    starts : ndarray of int, shape (n_cells,)
        Where each cell starts in ``order``.
    weights : scipy.sparse.csr_matrix, shape (n_pts, n_cells)
        sum over the points j of cell c of A_ij [-]: sum_c weights_ic max_{j in c} x_j >= (A x)_i, as A >= 0.
    """

    order: np.ndarray
    starts: np.ndarray
    weights: sp.csr_matrix


def cell_bound(matrix: sp.csr_matrix, points, size: float) -> CellBound:
    """The :class:`CellBound` of an averaging matrix over ``points`` (n_pts, dim) [mm], cells of ``size`` [mm]."""
    points = np.asarray(points, dtype=float)
    corner = np.floor((points - points.min(axis=0)) / size).astype(np.int64)
    _, cell = np.unique(corner, axis=0, return_inverse=True)
    cell = cell.ravel()
    order = np.argsort(cell, kind="stable")
    starts = np.flatnonzero(np.r_[True, np.diff(cell[order]) != 0])
    members = sp.csr_matrix((np.ones(cell.size), (np.arange(cell.size), cell)), shape=(cell.size, starts.size))
    return CellBound(order, starts, (matrix @ members).tocsr())


def bounded_average(averaging: NonlocalAveraging, x, floor, margin: float = 0.8):
    """The rows of A x that can reach ``floor``, exactly: (rows, (A x)[rows]).

    Parameters
    ----------
    averaging : NonlocalAveraging
    x : ndarray, shape (n_pts,)
        The values averaged (the local equivalent strain) [-].
    floor : ndarray, shape (n_pts,)
        The value below which a point's average is not needed (inf: never) [-].
    margin : float
        Rows are sliced from A where the bound reaches ``margin`` times the floor, and the slice is kept
        while it holds every row that must be computed (the next iterations of a step need about the same).

    Returns
    -------
    rows : ndarray of int
        A superset of the points whose average can reach the floor.
    values : ndarray
        (A x)[rows], equal to the full product's to the last bit (the same row sums in the same order).
    """
    bound = averaging.bound
    upper = bound.weights @ np.maximum.reduceat(x[bound.order], bound.starts)
    # the bound holds in exact arithmetic; its rounding and the product's are far below 1e-9 relative
    needed = upper >= floor * (1.0 - 1e-9)
    cached = averaging.rows
    if "mask" not in cached or not np.all(cached["mask"][needed]):
        mask = needed | (upper >= margin * floor)
        cached.update(mask=mask, matrix=averaging.matrix[np.flatnonzero(mask)])
    return np.flatnonzero(cached["mask"]), cached["matrix"] @ x


#: the averaging matrices built last, by mesh and internal length (:func:`cached_averaging_matrix`)
_CACHE: collections.OrderedDict = collections.OrderedDict()
_CACHE_LOCK = threading.Lock()
#: how many matrices the cache keeps: one is 12 bytes per pair of points within reach (the demo beam at
#: c = 21 mm^2: 11.5 million pairs, 140 MB), and the runs of a process share few internal lengths
#: (a run and its finite differences, the repeats of a benchmark)
CACHE_SIZE = 2


def cached_averaging_matrix(points, weights, length: float, cutoff: float = 4.0, mirror=(), with_bound=False):
    """:func:`averaging_matrix`, built once per process for the same points, weights, length, cutoff and
    planes, then shared (read-only: the caller must not change it); ``with_bound``: (A, its
    :class:`CellBound` of cells l by l).

    A process that runs many forward runs (a pool worker, a sampler, the finite differences of one
    run) builds it once per internal length: on the demo beam a build costs more than a gradient run.
    The key holds the bytes of the points and weights, so a different mesh never hits.
    """
    points, weights = np.ascontiguousarray(points, dtype=float), np.ascontiguousarray(weights, dtype=float)
    digest = hashlib.blake2b(points.tobytes(), digest_size=16)
    digest.update(weights.tobytes())
    key = (points.shape, digest.hexdigest(), float(length), float(cutoff),
           tuple((int(a), float(c)) for a, c in mirror))
    with _CACHE_LOCK:
        if key in _CACHE:
            _CACHE.move_to_end(key)
            entry = _CACHE[key]
            return entry if with_bound else entry[0]
    matrix = averaging_matrix(points, weights, length, cutoff, mirror)
    entry = (matrix, cell_bound(matrix, points, length))
    with _CACHE_LOCK:
        _CACHE[key] = entry
        while len(_CACHE) > CACHE_SIZE:
            _CACHE.popitem(last=False)
    return entry if with_bound else matrix


def nonlocal_averaging(disc, length: float, element_dofs, n_free: int, cutoff: float = 4.0, mirror=()) -> NonlocalAveraging:
    """Build the :class:`NonlocalAveraging` of a discretisation (its matrix once per process, mesh and
    internal length: :func:`cached_averaging_matrix`).

    Parameters
    ----------
    disc : MixedDiscretization
    length : float
        Internal length l [mm].
    element_dofs : ndarray of int, shape (n_el, n_u)
        Free-dof number of the element displacement dofs (-1: eliminated).
    n_free : int
        Number of free dofs.
    cutoff, mirror
        See :func:`averaging_matrix`.
    """
    n_el, n_q = disc.weights.shape
    points = disc.points.reshape(n_el * n_q, -1)
    A, bound = cached_averaging_matrix(points, disc.weights.ravel(), length, cutoff, mirror, with_bound=True)
    return NonlocalAveraging(A, A.diagonal().reshape(n_el, n_q), np.repeat(np.asarray(element_dofs), n_q, axis=0),
                             int(n_free), bound, {})


def softening_coupling(averaging: NonlocalAveraging, g, h, active) -> sp.csc_matrix | None:
    """Tangent of the nonlocal softening between different points: K_nl = - G A_L H over the free dofs.

    Parameters
    ----------
    averaging : NonlocalAveraging
    g : ndarray, shape (n_el, n_q, n_u)
        w_i E_i d omega_i / d kappa_i B_i^T sigma_eff_i: internal forces per unit nonlocal strain
        at each point [N] (sigma_eff = D eps per unit E).
    h : ndarray, shape (n_el, n_q, n_u)
        d eps_eq_j / d u = B_j^T d_eq_j: the local equivalent strain per unit element dof [1/mm].
    active : ndarray of bool, shape (n_el, n_q)
        Points that are loading and damaging; only their rows of A enter (others have g = 0).

    Returns
    -------
    scipy.sparse.csc_matrix, shape (n_free, n_free), or None when no point is active
        [N/mm]; add it to the assembled element tangents.

    Notes
    -----
    A_L is the rows of A at the active points without their diagonal (the element tangents hold it),
    sliced from the shared matrix (a copy) rather than kept as a second matrix of the mesh's size.
    """
    points = np.flatnonzero(np.ravel(active))
    if points.size == 0:
        return None
    n_u, n = g.shape[-1], averaging.n_free
    A_L = averaging.matrix[points]
    A_L.data[A_L.indices == np.repeat(points, np.diff(A_L.indptr))] = 0.0  # the diagonal: in the element tangents
    # H only at the points the active ones average over: a small part of the mesh while damage is local
    used = np.flatnonzero(np.bincount(A_L.indices, minlength=A_L.shape[1]))  # sorted, as np.unique, 10x faster
    G = _point_columns(averaging.point_dofs[points], g.reshape(-1, n_u)[points], n, np.arange(points.size), points.size)
    H = _point_columns(averaging.point_dofs[used], h.reshape(-1, n_u)[used], n, used, A_L.shape[1]).T
    return (-(G @ (A_L @ H))).tocsc()


def _point_columns(dofs, values, n, columns, n_columns) -> sp.csc_matrix:
    """Sparse (n, n_columns) matrix whose column ``columns[k]`` holds the element vector ``values[k]``
    at the rows ``dofs[k]`` (negative dofs dropped, repeated dofs of tied groups summed)."""
    keep = dofs >= 0
    cols = np.broadcast_to(np.asarray(columns)[:, None], dofs.shape)
    return sp.csc_matrix((values[keep], (dofs[keep], cols[keep])), shape=(n, n_columns))
