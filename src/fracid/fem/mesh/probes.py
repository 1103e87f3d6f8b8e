"""Point probes: the sparse matrix of the element shape functions at given points.

``P = probe_matrix(nodes, cells, points)`` has one row per point and one column per node, so that
``P @ field`` is a nodal field interpolated at the points (a sensor, the pixels a camera follows).
Each point is located in its element (candidate elements by the distance of their centroids, a
:class:`scipy.spatial.cKDTree`, then the inverse isoparametric map by Newton's method) and the row
holds the element's shape functions at the point's reference coordinates. :func:`dof_matrix` turns
P into the operator on a vector of interleaved components (``u`` of the plane elements: dof
``2 j + c`` is component c of node j). Scikit-fem's ``CellBasis.probes`` is the model.

Element families by nodes per cell: 8-node serendipity and 4-node bilinear quadrilaterals, 6-node
quadratic and 3-node linear triangles (the numbering of :mod:`fracid.fem.mesh.elements`); a 4- or 3-node
family on the corners (``cells[:, :4]``, ``cells[:, :3]``) probes a field that lives on the corners.
Coordinates in mm.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np
import scipy.sparse as sp
from scipy.spatial import cKDTree

from fracid.fem.mesh.elements import quad_linear, quad_serendipity, triangle_linear, triangle_quadratic

#: relative tolerance on the reference coordinates for a point to count as inside an element
INSIDE_TOLERANCE = 1e-9
#: candidate elements (nearest centroids) tried per point before all elements whose box holds it
CANDIDATES = 8
_NEWTON_ITERATIONS = 30


@dataclass(frozen=True)
class _Shape:
    """A reference element: shape functions, its centre and whether reference points lie inside."""

    functions: Callable
    centre: tuple
    triangle: bool

    def inside(self, xi: np.ndarray, tol: float = INSIDE_TOLERANCE) -> np.ndarray:
        if self.triangle:
            return (xi[:, 0] >= -tol) & (xi[:, 1] >= -tol) & (xi[:, 0] + xi[:, 1] <= 1.0 + tol)
        return np.all(np.abs(xi) <= 1.0 + tol, axis=1)


_SHAPES = {
    8: _Shape(quad_serendipity, (0.0, 0.0), False),
    4: _Shape(quad_linear, (0.0, 0.0), False),
    6: _Shape(triangle_quadratic, (1.0 / 3.0, 1.0 / 3.0), True),
    3: _Shape(triangle_linear, (1.0 / 3.0, 1.0 / 3.0), True),
}


def _shape_of(cells: np.ndarray) -> _Shape:
    shape = _SHAPES.get(cells.shape[1]) if cells.ndim == 2 else None
    if shape is None:
        raise ValueError(f"cells has shape {cells.shape}; give (n_el, k) plane cells with k in {sorted(_SHAPES)} "
                         "nodes (8- or 4-node quadrilaterals, 6- or 3-node triangles)")
    return shape


def _check_mesh(nodes, cells, points) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    nodes, points = np.asarray(nodes, dtype=float), np.asarray(points, dtype=float)
    cells = np.asarray(cells)
    if nodes.ndim != 2 or nodes.shape[1] != 2:
        raise ValueError(f"nodes has shape {nodes.shape}; give (n_nodes, 2) plane coordinates [mm]")
    if not np.issubdtype(cells.dtype, np.integer) or cells.size == 0:
        raise ValueError(f"cells must be a non-empty integer array of node indices, got dtype {cells.dtype}")
    if cells.min() < 0 or cells.max() >= len(nodes):
        raise ValueError(f"cells refer to nodes outside 0..{len(nodes) - 1}")
    if points.ndim != 2 or points.shape[1] != 2 or len(points) == 0:
        raise ValueError(f"points has shape {points.shape}; give (n_points, 2) coordinates [mm]")
    if not np.all(np.isfinite(points)):
        raise ValueError("points holds NaN or infinite coordinates")
    return nodes, cells, points


def _newton(shape: _Shape, X: np.ndarray, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Reference coordinates xi (n, 2) with x(xi) = x in the elements of node coordinates X (n, k, 2),
    and whether Newton's method converged for each."""
    xi = np.tile(np.asarray(shape.centre, dtype=float), (len(x), 1))
    size = np.ptp(X, axis=1).max(axis=1)
    converged = np.zeros(len(x), dtype=bool)
    for _ in range(_NEWTON_ITERATIONS):
        N, dN = shape.functions(xi)
        residual = x - np.einsum("pa,pai->pi", N, X)
        converged = np.linalg.norm(residual, axis=1) <= 1e-12 * size
        J = np.einsum("pak,pai->pik", dN, X)  # d x_i / d xi_k
        det = J[:, 0, 0] * J[:, 1, 1] - J[:, 0, 1] * J[:, 1, 0]
        ok = np.abs(det) > 1e-14 * size**2
        safe = np.where(ok, det, 1.0)
        step = np.column_stack([J[:, 1, 1] * residual[:, 0] - J[:, 0, 1] * residual[:, 1],
                                J[:, 0, 0] * residual[:, 1] - J[:, 1, 0] * residual[:, 0]]) / safe[:, None]
        xi = np.where(ok[:, None], np.clip(xi + step, -3.0, 3.0), xi)  # far elements: keep xi bounded
        if converged.all():
            break
    return xi, converged


def locate(nodes, cells, points) -> tuple[np.ndarray, np.ndarray]:
    """The element holding each point and the point's reference coordinates in it.

    Parameters
    ----------
    nodes : array_like, shape (n_nodes, 2)
        Node coordinates [mm].
    cells : array_like of int, shape (n_el, k)
        Nodes of each element, k = 8, 4, 6 or 3 (numbering of :mod:`fracid.fem.mesh.elements`).
    points : array_like, shape (n_points, 2)
        Coordinates [mm].

    Returns
    -------
    element : ndarray of int, shape (n_points,)
        A holding element (points on shared edges or nodes: the one with the nearest centroid).
    xi : ndarray, shape (n_points, 2)
        Reference coordinates of each point in its element.

    Raises
    ------
    ValueError
        For points outside the mesh (the message lists them) or a malformed mesh.
    """
    element, xi = find_elements(nodes, cells, points)
    _reject_outside(np.asarray(points, dtype=float), element)
    return element, xi


def find_elements(nodes, cells, points) -> tuple[np.ndarray, np.ndarray]:
    """:func:`locate` without the refusal: the element of each point, -1 for a point outside the mesh (its
    reference coordinates then 0); ValueError for a malformed mesh only."""
    nodes, cells, points = _check_mesh(nodes, cells, points)
    shape = _shape_of(cells)
    X = nodes[cells]
    tree = cKDTree(X.mean(axis=1))
    k = min(CANDIDATES, len(cells))
    _, near = tree.query(points, k=k)
    near = near.reshape(len(points), k)
    element = np.full(len(points), -1)
    xi = np.zeros((len(points), 2))
    for rank in range(k):
        _try(shape, X, points, near[:, rank], element, xi)
    pending = np.flatnonzero(element < 0)
    if pending.size:  # elongated elements: every element whose bounding box holds the point
        low, high = X.min(axis=1), X.max(axis=1)
        pad = 1e-9 * np.ptp(nodes, axis=0).max()
        for p in pending:
            boxes = np.flatnonzero(np.all((points[p] >= low - pad) & (points[p] <= high + pad), axis=1))
            for candidate in boxes:
                if element[p] < 0:
                    _try(shape, X, points[p:p + 1], np.array([candidate]), element[p:p + 1], xi[p:p + 1])
    return element, xi


def _try(shape, X, points, candidates, element, xi) -> None:
    """Newton in ``candidates`` for the points not located yet; fills ``element`` and ``xi`` in place."""
    todo = np.flatnonzero(element < 0)
    if todo.size == 0:
        return
    found, ok = _newton(shape, X[candidates[todo]], points[todo])
    hit = ok & shape.inside(found)
    element[todo[hit]] = candidates[todo[hit]]
    xi[todo[hit]] = found[hit]


def _reject_outside(points, element) -> None:
    outside = np.flatnonzero(element < 0)
    if outside.size:
        listed = ", ".join(f"{i} ({points[i, 0]:.6g}, {points[i, 1]:.6g})" for i in outside[:10])
        more = f" and {outside.size - 10} more" if outside.size > 10 else ""
        raise ValueError(f"{outside.size} of {len(points)} points are outside the mesh: point {listed}{more} [mm]; "
                         "give points inside the specimen's mesh (of the modelled part: a symmetric half or quarter)")


def probe_matrix(nodes, cells, points) -> sp.csr_matrix:
    """The sparse matrix P (n_points x n_nodes) of the shape functions at ``points``: P @ f is the nodal
    field f interpolated at the points (exact for the polynomials the elements reproduce).

    Parameters
    ----------
    nodes, cells, points
        As :func:`locate`: node coordinates [mm], element nodes, point coordinates [mm].

    Returns
    -------
    scipy.sparse.csr_matrix, shape (n_points, n_nodes)
        Each row holds the shape functions of the point's element (summing to 1).
    """
    nodes, cells, points = _check_mesh(nodes, cells, points)
    element, xi = locate(nodes, cells, points)
    N, _ = _shape_of(cells).functions(xi)
    rows = np.repeat(np.arange(len(points)), cells.shape[1])
    return sp.csr_matrix((N.ravel(), (rows, cells[element].ravel())), shape=(len(points), len(nodes)))


def dof_matrix(P, component: int, n_components: int = 2) -> sp.csr_matrix:
    """P acting on a vector of ``n_components`` interleaved components (dof ``n_components j + c`` is
    component c of node j): its rows give ``component`` at the points.

    Parameters
    ----------
    P : sparse matrix, shape (n_points, n_nodes)
        From :func:`probe_matrix`.
    component : int
        0 (x) .. n_components - 1.
    n_components : int
        Components per node (2 for the plane displacement).

    Returns
    -------
    scipy.sparse.csr_matrix, shape (n_points, n_components n_nodes)
    """
    if not (isinstance(n_components, (int, np.integer)) and n_components >= 1):
        raise ValueError(f"n_components = {n_components!r}; give a positive integer")
    if not (isinstance(component, (int, np.integer)) and 0 <= component < n_components):
        raise ValueError(f"component = {component!r}; give an integer in [0, {n_components})")
    P = sp.csr_matrix(P)
    coo = P.tocoo()
    return sp.csr_matrix((coo.data, (coo.row, n_components * coo.col + component)),
                         shape=(P.shape[0], n_components * P.shape[1]))
