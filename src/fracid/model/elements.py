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
