"""Monolithic Newton-Raphson on a damage problem under indirect displacement control.

The unknowns are the free dofs q and the load factor lambda. The equations are equilibrium (and the
diffusion equation) r(q) - lambda f_hat = 0 and the control constraint v . q = tau, with v a linear
functional of the displacements (an end displacement, an elongation over a gauge length, a CMOD).
With v the displacement of the loaded point this is plain displacement control; with another v it
traces snap-back. The bordered matrix [[K, -f_hat], [v^T, 0]] is assembled into one sparse pattern
built once, and stays regular at limit points of the load.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp

from fracid.fem.assembly import SparsePattern, dot, norm2
from fracid.fem.linear_solvers import SingularMatrixError, factorize


class IncrementFailed(RuntimeError):
    """One increment did not converge (the caller cuts the step)."""


@dataclass(frozen=True)
class NewtonOptions:
    """Convergence settings of the Newton-Raphson iterations.

    The solver checks the residual of every field a problem declares (its ``blocks``: ``"u"``, and
    ``"ebar"`` for the gradient model, or any other name a new formulation gives) against
    :meth:`tolerance` of that field.

    Parameters
    ----------
    rtol_u : float
        Relative tolerance on the equilibrium residual, scaled by the norm of the internal forces.
    rtol_ebar : float
        Relative tolerance on the residual of the diffusion equation, scaled by the norm of the
        equivalent-strain source.
    max_iterations : int
        Iterations before an increment counts as failed.
    field_rtol : mapping {field: float}
        Relative tolerances of other fields (or overriding the two above); a field named nowhere
        gets ``rtol_u``.
    """

    rtol_u: float = 1e-8
    rtol_ebar: float = 1e-8
    max_iterations: int = 12
    field_rtol: tuple = ()

    def __post_init__(self):
        named = dict(self.field_rtol.items() if hasattr(self.field_rtol, "items") else self.field_rtol)
        object.__setattr__(self, "field_rtol", tuple(sorted(named.items())))
        for name, value in [("rtol_u", self.rtol_u), ("rtol_ebar", self.rtol_ebar)] + [
                (f"field_rtol[{field!r}]", v) for field, v in self.field_rtol]:
            if not (0.0 < value < 1.0):
                raise ValueError(f"NewtonOptions.{name} = {value!r}; it must be in (0, 1)")
        if int(self.max_iterations) != self.max_iterations or self.max_iterations < 1:
            raise ValueError(f"NewtonOptions.max_iterations = {self.max_iterations!r}; it must be a positive integer")

    def tolerance(self, field_name: str) -> float:
        """Relative tolerance of the residual of field ``field_name``."""
        named = dict(self.field_rtol)
        return named.get(field_name, self.rtol_ebar if field_name == "ebar" else self.rtol_u)


@dataclass
class SolverStatistics:
    """Counters and timers of a forward analysis (wall times in s)."""

    steps: int = 0
    iterations: int = 0
    failed_increments: int = 0
    time_linear: float = 0.0
    time_total: float = 0.0
    linear_solves: int = 0
    factorizations: int = 0

    def as_dict(self) -> dict:
        return dict(self.__dict__)


@dataclass
class ControlledSystem:
    """A :class:`~fracid.fem.problem.DamageProblem` bordered by the load factor and one control functional."""

    problem: object
    control: np.ndarray
    pattern: SparsePattern = field(init=False)
    border_values: np.ndarray = field(init=False)
    _scale: np.ndarray | None = field(init=False, default=None)
    _entry_scale: np.ndarray | None = field(init=False, default=None)

    def __post_init__(self):
        n = self.problem.n_free
        f_idx = np.flatnonzero(self.problem.load_vector)
        v_idx = np.flatnonzero(self.control)
        if v_idx.size == 0:
            raise ValueError("the control functional is zero on the free dofs: it cannot be prescribed")
        rows = np.concatenate([f_idx, np.full(v_idx.size, n)])
        cols = np.concatenate([np.full(f_idx.size, n), v_idx])
        self.border_values = np.concatenate([-self.problem.load_vector[f_idx], self.control[v_idx]])
        self.pattern = SparsePattern(n + 1, self.problem.element_dofs, rows, cols)

    def evaluate(self, z: np.ndarray, tau: float, kappa_old: np.ndarray, state=None):
        """Residual of the bordered system, element arrays, relative residual per field, and the
        problem's evaluation ``state`` (pass it back to skip re-evaluating at the same z and history)."""
        p = self.problem
        q, lam = z[:-1], z[-1]
        internal, arrays, references = state if state is not None else p.evaluate(q, kappa_old)
        residual = np.append(internal - lam * p.load_vector, dot(self.control, q) - tau)
        external = abs(lam) * norm2(p.load_vector)
        errors = {}
        for name, idx in p.blocks.items():
            scale = max(references[name], external if name == "u" else 0.0)
            norm = float(norm2(residual[idx]))
            errors[name] = norm / scale if scale > 0.0 else norm
        return residual, arrays, errors, (internal, arrays, references)

    def matrix(self, arrays):
        """The bordered tangent (CSC), with the nonlocal coupling of the integral model if any."""
        return _add_coupling(self.pattern.matrix(arrays.tangent, self.border_values), _coupling(arrays))

    def scaled_matrix_scale(self) -> np.ndarray:
        """The diagonal of S of :meth:`scaled_matrix` (after its first call)."""
        return self._scale

    def scaled_matrix(self, arrays):
        """The bordered matrix equilibrated as S M S, and the diagonal of S.

        S = diag(1 / sqrt|M_ii|) of the first matrix assembled (the virgin elastic state; 1 on the
        border). The rows of equilibrium (order E t) and of the diffusion equation (order mm^2)
        differ by six orders of magnitude; equilibrated, SuperLU reaches 1e-15 relative residuals
        instead of 1e-7 and PARDISO no longer perturbs pivots of the virgin state.

        A nonlocal coupling (integral model) has a pattern of its own that changes with the
        loading points, so it is scaled entry by entry with the same S and added: the sum has a
        new pattern, and PARDISO then redoes its symbolic analysis (correct, only slower).
        """
        matrix = self.pattern.matrix(arrays.tangent, self.border_values)
        if self._scale is None:
            diagonal = np.abs(matrix.diagonal())
            self._scale = np.where(diagonal > 0.0, 1.0 / np.sqrt(np.where(diagonal > 0.0, diagonal, 1.0)), 1.0)
            self._entry_scale = self._scale[matrix.indices] * np.repeat(self._scale, np.diff(matrix.indptr))
        matrix.data *= self._entry_scale
        coupling = _coupling(arrays)
        if coupling is not None:
            coupling = sp.csc_matrix(coupling, copy=True)
            coupling.data *= self._scale[coupling.indices] * np.repeat(self._scale[:-1], np.diff(coupling.indptr))
        return _add_coupling(matrix, coupling), self._scale


def _coupling(arrays):
    # element arrays of other models (a NamedTuple without the field) have no coupling
    return getattr(arrays, "coupling", None)


def _add_coupling(matrix, coupling):
    """``matrix`` (n + 1, n + 1) plus ``coupling`` (n, n) padded with the border row and column, as CSC."""
    if coupling is None:
        return matrix
    coupling = sp.csc_matrix(coupling)
    padded = sp.csc_matrix((coupling.data, coupling.indices, np.append(coupling.indptr, coupling.indptr[-1])), shape=matrix.shape)
    return (matrix + padded).tocsc()


def solve_increment(
    system: ControlledSystem, z0, tau, kappa_old, solver, options: NewtonOptions, stats: SolverStatistics, state=None,
    factor=None,
):
    """Newton-Raphson iterations for one increment to the control value ``tau``.

    ``state`` is the evaluation at ``z0`` returned by the previous increment: at a converged state the
    internal forces and tangent under the updated history equal those of the last iteration (the
    loading pattern does not change), so the first iteration of a step costs no evaluation. ``factor``,
    given with ``state``, solves the first iteration without a new factorization: the bordered tangent
    at that state (from the direct differentiation of the last step, :mod:`fracid.fem.ddm`) or that of
    the last iteration of the last increment, whose iterate was within the tolerance of the state.
    The latter is one factorization less per step (169 -> 116 on the default beam) at the same
    iteration counts: the tangent one iterate before convergence is as good a first step.

    Returns
    -------
    z : ndarray
        Converged free dofs followed by the load factor.
    arrays : ElementArrays
        Element arrays at the converged state (trial history and damage).
    iterations : int
    state : tuple
        The evaluation at the converged z (for the next increment).
    factor : callable
        The last factorization used (``rhs -> x``), to start the next increment with.

    Raises
    ------
    IncrementFailed
        On a non-finite residual, a singular tangent, or no convergence in ``options.max_iterations``.
    """
    z = z0.copy()
    scale = max(abs(tau), 1e-300)
    for iteration in range(options.max_iterations + 1):
        residual, arrays, errors, state = system.evaluate(z, tau, kappa_old, state if iteration == 0 else None)
        if not np.all(np.isfinite(residual)):
            raise IncrementFailed(f"non-finite residual at iteration {iteration}")
        if iteration > 0 and abs(residual[-1]) <= 1e-10 * scale and all(
            err <= options.tolerance(name) for name, err in errors.items()
        ):
            return z, arrays, iteration, state, factor
        if iteration == options.max_iterations:
            break
        t0 = time.perf_counter()
        try:
            if iteration == 0 and factor is not None and state is not None:
                equilibration, solve = system.scaled_matrix_scale(), factor
            else:
                matrix, equilibration = system.scaled_matrix(arrays)
                t0 = time.perf_counter()  # the assembly above is not linear-solver time
                solve = factor = factorize(solver, matrix)
                stats.factorizations += 1
            dz = equilibration * solve(-residual * equilibration)
        except SingularMatrixError as err:
            raise IncrementFailed(f"singular tangent at iteration {iteration}: {err}") from err
        finally:
            stats.time_linear += time.perf_counter() - t0
            stats.linear_solves += 1
        stats.iterations += 1
        z += dz
    detail = ", ".join(f"{k}: {v:.2e}" for k, v in errors.items())
    raise IncrementFailed(f"no convergence in {options.max_iterations} iterations (relative residuals {detail})")
