"""Reference elements: shape functions and Gauss rules on the reference domain."""

from __future__ import annotations

import numpy as np


def gauss_line(n: int) -> tuple[np.ndarray, np.ndarray]:
    """Gauss-Legendre points and weights on [-1, 1]."""
    return np.polynomial.legendre.leggauss(n)


def line_quadratic(xi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Quadratic Lagrange shape functions on [-1, 1], nodes ordered (-1, 0, +1).

    Returns
    -------
    N, dN_dxi : ndarray, shape (n_points, 3)
    """
    xi = np.asarray(xi, dtype=float)
    N = np.stack([0.5 * xi * (xi - 1.0), 1.0 - xi * xi, 0.5 * xi * (xi + 1.0)], axis=-1)
    dN = np.stack([xi - 0.5, -2.0 * xi, xi + 0.5], axis=-1)
    return N, dN


def line_linear(xi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Linear Lagrange shape functions on [-1, 1], nodes ordered (-1, +1).

    Returns
    -------
    N, dN_dxi : ndarray, shape (n_points, 2)
    """
    xi = np.asarray(xi, dtype=float)
    N = np.stack([0.5 * (1.0 - xi), 0.5 * (1.0 + xi)], axis=-1)
    dN = np.stack([-0.5 * np.ones_like(xi), 0.5 * np.ones_like(xi)], axis=-1)
    return N, dN


def gauss_quad(n: int) -> tuple[np.ndarray, np.ndarray]:
    """Tensor Gauss rule on [-1, 1]^2: points (n*n, 2) and weights (n*n,)."""
    x, w = gauss_line(n)
    xi, eta = np.meshgrid(x, x, indexing="ij")
    return np.column_stack([xi.ravel(), eta.ravel()]), np.outer(w, w).ravel()


# corner nodes counterclockwise from (-1, -1), then mid-edge nodes of edges 0-1, 1-2, 2-3, 3-0
_Q_CORNERS = np.array([[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]])
_Q_MIDS = np.array([[0.0, -1.0], [1.0, 0.0], [0.0, 1.0], [-1.0, 0.0]])


def quad_linear(points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Bilinear shape functions of the 4-node quadrilateral.

    Returns
    -------
    N : ndarray, shape (n_points, 4)
    dN : ndarray, shape (n_points, 4, 2)
        Derivatives with respect to (xi, eta).
    """
    xi, eta = points[:, 0:1], points[:, 1:2]
    a, b = _Q_CORNERS[:, 0], _Q_CORNERS[:, 1]
    N = 0.25 * (1 + a * xi) * (1 + b * eta)
    dN = np.stack([0.25 * a * (1 + b * eta), 0.25 * b * (1 + a * xi)], axis=-1)
    return N, dN


def quad_serendipity(points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Quadratic serendipity shape functions of the 8-node quadrilateral (corners, then mid-edges).

    Returns
    -------
    N : ndarray, shape (n_points, 8)
    dN : ndarray, shape (n_points, 8, 2)
        Derivatives with respect to (xi, eta).
    """
    xi, eta = points[:, 0:1], points[:, 1:2]
    a, b = _Q_CORNERS[:, 0], _Q_CORNERS[:, 1]
    Nc = 0.25 * (1 + a * xi) * (1 + b * eta) * (a * xi + b * eta - 1)
    dNc = np.stack(
        [0.25 * a * (1 + b * eta) * (2 * a * xi + b * eta), 0.25 * b * (1 + a * xi) * (a * xi + 2 * b * eta)], axis=-1
    )
    # mid-edge nodes: (0, b) on the horizontal edges, (a, 0) on the vertical ones
    am, bm = _Q_MIDS[:, 0], _Q_MIDS[:, 1]
    horizontal = am == 0
    Nm = np.where(horizontal, 0.5 * (1 - xi**2) * (1 + bm * eta), 0.5 * (1 + am * xi) * (1 - eta**2))
    dNm_dxi = np.where(horizontal, -xi * (1 + bm * eta), 0.5 * am * (1 - eta**2))
    dNm_deta = np.where(horizontal, 0.5 * bm * (1 - xi**2), -eta * (1 + am * xi))
    N = np.concatenate([Nc, Nm], axis=1)
    dN = np.concatenate([dNc, np.stack([dNm_dxi, dNm_deta], axis=-1)], axis=1)
    return N, dN


# Triangles on the reference triangle (0, 0), (1, 0), (0, 1), in area coordinates
# L = (1 - xi - eta, xi, eta) with constant gradients; mid-edge nodes of edges 0-1, 1-2, 2-0.
_T_GRADIENTS = np.array([[-1.0, -1.0], [1.0, 0.0], [0.0, 1.0]])
_T_EDGES = np.array([[0, 1], [1, 2], [2, 0]])


def _area_coordinates(points: np.ndarray) -> np.ndarray:
    points = np.asarray(points, dtype=float)
    return np.column_stack([1.0 - points[:, 0] - points[:, 1], points[:, 0], points[:, 1]])


def triangle_linear(points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Linear shape functions of the 3-node triangle (corners (0, 0), (1, 0), (0, 1)).

    Parameters
    ----------
    points : ndarray, shape (n_points, 2)
        Points (xi, eta) of the reference triangle.

    Returns
    -------
    N : ndarray, shape (n_points, 3)
    dN : ndarray, shape (n_points, 3, 2)
        Derivatives with respect to (xi, eta).
    """
    L = _area_coordinates(points)
    return L, np.broadcast_to(_T_GRADIENTS, (L.shape[0], 3, 2)).copy()


def triangle_quadratic(points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Quadratic Lagrange shape functions of the 6-node triangle.

    Corners (0, 0), (1, 0), (0, 1) counterclockwise, then the mid-edge nodes of edges 0-1, 1-2, 2-0.

    Parameters
    ----------
    points : ndarray, shape (n_points, 2)
        Points (xi, eta) of the reference triangle.

    Returns
    -------
    N : ndarray, shape (n_points, 6)
    dN : ndarray, shape (n_points, 6, 2)
        Derivatives with respect to (xi, eta).
    """
    L = _area_coordinates(points)
    g = _T_GRADIENTS
    Nc = L * (2.0 * L - 1.0)
    dNc = (4.0 * L - 1.0)[:, :, None] * g[None, :, :]
    La, Lb = L[:, _T_EDGES[:, 0]], L[:, _T_EDGES[:, 1]]
    Nm = 4.0 * La * Lb
    dNm = 4.0 * (La[:, :, None] * g[_T_EDGES[:, 1]][None] + Lb[:, :, None] * g[_T_EDGES[:, 0]][None])
    return np.concatenate([Nc, Nm], axis=1), np.concatenate([dNc, dNm], axis=1)


def _symmetric_orbits(orbits) -> tuple[np.ndarray, np.ndarray]:
    """Points and weights of a rule given by (a, weight) orbits: a = 1/3 is the centroid, otherwise
    the three points with area coordinates (a, a, 1 - 2 a) and its permutations."""
    points, weights = [], []
    for a, w in orbits:
        L = [(a, a, a)] if a == 1.0 / 3.0 else [(1 - 2 * a, a, a), (a, 1 - 2 * a, a), (a, a, 1 - 2 * a)]
        points += [(l2, l3) for _, l2, l3 in L]
        weights += [w] * len(L)
    return np.array(points), np.array(weights)


_S10, _S15 = np.sqrt(10.0), np.sqrt(15.0)
_R4 = np.sqrt(38.0 - 44.0 * np.sqrt(0.4))
_R4W = np.sqrt(213125.0 - 53320.0 * _S10)
# symmetric rules with positive weights (weights sum to 1/2): degree -> orbits (a, weight)
_TRIANGLE_RULES = {
    1: ((1.0 / 3.0, 0.5),),
    2: ((1.0 / 6.0, 1.0 / 6.0),),
    # Strang & Fix / Dunavant, 6 points
    4: (((8.0 - _S10 + _R4) / 18.0, (620.0 + _R4W) / 7440.0), ((8.0 - _S10 - _R4) / 18.0, (620.0 - _R4W) / 7440.0)),
    # Radon / Hammer, 7 points
    5: ((1.0 / 3.0, 9.0 / 80.0), ((6.0 - _S15) / 21.0, (155.0 - _S15) / 2400.0),
        ((6.0 + _S15) / 21.0, (155.0 + _S15) / 2400.0)),
}


def gauss_triangle(degree: int) -> tuple[np.ndarray, np.ndarray]:
    """Gauss rule on the reference triangle (0, 0), (1, 0), (0, 1), exact for polynomials of ``degree``.

    Parameters
    ----------
    degree : int
        Polynomial degree integrated exactly, >= 1. Degrees 1, 2, 4 and 5 are the symmetric rules
        of 1, 3, 6 (Strang-Fix / Dunavant) and 7 (Radon) points; degree 3 uses the 6-point rule of
        degree 4 (positive weights); higher degrees a collapsed (Duffy) tensor Gauss-Legendre rule of
        ((degree + 3) // 2)^2 points.

    Returns
    -------
    points : ndarray, shape (n, 2)
        (xi, eta) of the points.
    weights : ndarray, shape (n,)
        Their weights, summing to 1/2 (the area of the reference triangle).
    """
    if not (isinstance(degree, (int, np.integer)) and degree >= 1):
        raise ValueError(f"degree = {degree!r}; a triangle rule needs an integer degree >= 1")
    key = 4 if degree == 3 else int(degree)
    if key in _TRIANGLE_RULES:
        return _symmetric_orbits(_TRIANGLE_RULES[key])
    # x = u, y = (1 - u) v on the unit square: dx dy = (1 - u) du dv, a polynomial of degree + 1 in u
    n = (degree + 3) // 2
    x, w = gauss_line(n)
    x, w = 0.5 * (x + 1.0), 0.5 * w
    u, v = np.meshgrid(x, x, indexing="ij")
    weights = np.outer(w, w) * (1.0 - u)
    return np.column_stack([u.ravel(), ((1.0 - u) * v).ravel()]), weights.ravel()
