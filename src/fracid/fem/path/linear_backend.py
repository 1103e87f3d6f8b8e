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
