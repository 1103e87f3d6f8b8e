"""The interface every linear-solver backend follows, apart from the backends themselves, so that a
backend module (:mod:`fracid.fem.path.pardiso`) and the factory (:mod:`fracid.fem.path.linear_solvers`) both import
it and neither imports the other at module level.

A backend is any object with ``solve(matrix, rhs) -> x`` for a square sparse CSC matrix and a
right-hand side of shape (n,) or (n, k), and optionally ``factorize(matrix) -> solve(rhs)``, which keeps
a factorization for several right-hand sides given at different times (see :func:`factorize`). It raises
:class:`SingularMatrixError` when the matrix cannot be factorized, which the Newton solver treats as a
failed iteration (the step is cut).
"""

from __future__ import annotations

from typing import Protocol

import numpy as np

from fracid.fem.mesh.assembly import norm2


class SingularMatrixError(RuntimeError):
    """The tangent matrix could not be factorized."""


class LinearSolver(Protocol):
    name: str

    def solve(self, matrix, rhs: np.ndarray) -> np.ndarray: ...


def factorize(solver, matrix):
    """``rhs -> x`` solving with ``matrix``: the backend's kept factorization if it has ``factorize``,
    else a solve (a new factorization) per call."""
    keep = getattr(solver, "factorize", None)
    if keep is not None:
        return keep(matrix)
    return lambda rhs: solver.solve(matrix, rhs)


def block_norm(a: np.ndarray) -> float:
    """Euclidean (Frobenius) norm of a vector or of a block of right-hand sides (n, k), without BLAS
    (see :func:`~fracid.fem.mesh.assembly.dot`: vector BLAS calls go multithreaded at these sizes and
    then cost milliseconds each on a busy machine)."""
    return norm2(np.asarray(a).ravel(order="K"))


def refine(solve, matrix, rhs: np.ndarray, x: np.ndarray, rtol: float, steps: int):
    """Iterative refinement of a solution ``x`` of ``matrix @ x = rhs`` with an approximate solver.

    Parameters
    ----------
    solve : callable(r) -> ndarray
        Solves with (an approximation of) ``matrix``: a factorization, possibly with perturbed pivots.
    matrix : sparse matrix, shape (n, n)
    rhs : ndarray, shape (n,) or (n, k)
    x : ndarray, shape of ``rhs``
        The solution to refine (updated in place).
    rtol : float
        Stop once ||rhs - matrix x|| <= rtol ||rhs|| (Frobenius norm over the columns).
    steps : int
        At most this many corrections (0: only the residual is measured).

    Returns
    -------
    x : ndarray
    residual, scale : float
        ||rhs - matrix x|| of the returned x, and ||rhs||.
    """
    scale = block_norm(rhs)
    r = rhs - matrix @ x
    residual = block_norm(r)
    for _ in range(steps):
        if residual <= rtol * scale:
            break
        x += solve(r)
        r = rhs - matrix @ x
        residual = block_norm(r)
    return x, residual, scale
