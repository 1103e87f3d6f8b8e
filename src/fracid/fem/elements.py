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
