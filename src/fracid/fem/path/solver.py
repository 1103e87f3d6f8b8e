"""Monolithic Newton-Raphson on a damage problem under indirect displacement control.

The unknowns are the free dofs q and the load factor lambda. The equations are equilibrium (and those
of the problem's named fields) r(q) - lambda f_hat = 0 and the control constraint v . q = tau, with v a linear
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

from fracid.fem.mesh.assembly import SparsePattern, dot, norm2
from fracid.fem.path.linear_backend import SingularMatrixError, factorize


class IncrementFailed(RuntimeError):
    """One increment did not converge (the caller cuts the step)."""


@dataclass(frozen=True)
class NewtonOptions:
    """Convergence settings of the Newton-Raphson iterations.

    The solver checks the residual of every field a problem declares (its ``blocks``: ``"u"`` and
    the formulation's named fields) against :meth:`tolerance` of that field, each relative to the
    reference norm the formulation gives for it (the internal forces for ``"u"``).

    Parameters
    ----------
    rtol_u : float
        Relative tolerance on the equilibrium residual, scaled by the norm of the internal forces.
    max_iterations : int
        Iterations with a new factorization before an increment counts as failed.
    field_rtol : mapping {field: float}
        Relative tolerances of named fields (or of ``"u"``, overriding ``rtol_u``); a field named
        nowhere gets ``rtol_u``.
    reuse_ratio : float
        Modified Newton while the residual falls fast. The progress of an iterate is its largest
        relative residual over the field's tolerance (converged at 1). The factorization in hand
        (of an earlier iterate, or of the last step) solves the next iteration as long as the last
        iteration cut the progress by at least this factor and, at that rate, would converge within
        ``reuse_iterations`` more iterations; else the tangent at the iterate is factorized (a
        Newton iteration). An iterate that a kept factorization made worse is dropped and Newton
        goes on from the one before. 0: full Newton (only the first iteration of a step uses the
        last factorization). A factorization costs 4 to 15 evaluations of the residual on the 2D
        specimens (10k to 27k unknowns): 0.3 halves the factorizations of the beams at a tenth of
        their tolerance in the curves (docs/speed/README.md).
    reuse_iterations : int
        See ``reuse_ratio``.
    rtol_ebar : None
        Removed: ``field_rtol={field: value}`` gives a named field its tolerance.
    """

    rtol_u: float = 1e-8
    max_iterations: int = 12
    field_rtol: tuple = ()
    reuse_ratio: float = 0.3
    reuse_iterations: int = 6
    rtol_ebar: None = field(default=None, repr=False, compare=False)

    def __post_init__(self):
        if self.rtol_ebar is not None:
            raise TypeError(f"NewtonOptions(rtol_ebar={self.rtol_ebar!r}) was removed: give the tolerance of a named "
                            f"field in field_rtol, e.g. field_rtol={{'ebar': {self.rtol_ebar!r}}}")
        named = dict(self.field_rtol.items() if hasattr(self.field_rtol, "items") else self.field_rtol)
        object.__setattr__(self, "field_rtol", tuple(sorted(named.items())))
        for name, value in [("rtol_u", self.rtol_u)] + [
                (f"field_rtol[{field!r}]", v) for field, v in self.field_rtol]:
            if not (0.0 < value < 1.0):
                raise ValueError(f"NewtonOptions.{name} = {value!r}; it must be in (0, 1)")
        for name in ("max_iterations", "reuse_iterations"):
            value = getattr(self, name)
            if int(value) != value or value < (1 if name == "max_iterations" else 0):
                raise ValueError(f"NewtonOptions.{name} = {value!r}; it must be a "
                                 f"{'positive' if name == 'max_iterations' else 'non-negative'} integer")
        if not 0.0 <= self.reuse_ratio < 1.0:
            raise ValueError(f"NewtonOptions.reuse_ratio = {self.reuse_ratio!r}; it must be in [0, 1) (0: full Newton)")

    def tolerance(self, field_name: str) -> float:
        """Relative tolerance of the residual of field ``field_name``."""
        return dict(self.field_rtol).get(field_name, self.rtol_u)


@dataclass
class SolverStatistics:
    """Counters and timers of a forward analysis (wall times in s)."""

    steps: int = 0
    iterations: int = 0
    failed_increments: int = 0
    time_linear: float = 0.0  # factorizations and solves
    time_factorizations: float = 0.0
    time_total: float = 0.0
    linear_solves: int = 0
    factorizations: int = 0

    def as_dict(self) -> dict:
        return dict(self.__dict__)

    def add(self, other: "SolverStatistics") -> None:
        """Add the linear-algebra counters and times of ``other`` (the derivatives' own)."""
        for name in ("time_linear", "time_factorizations", "linear_solves", "factorizations"):
            setattr(self, name, getattr(self, name) + getattr(other, name))


@dataclass
class ControlledSystem:
    """A problem (:class:`~fracid.fem.formulations.protocol.Problem`) bordered by the load factor and one control functional."""

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
        self.pattern = SparsePattern.shared(n + 1, self.problem.element_dofs, rows, cols)

    def evaluate(self, z: np.ndarray, tau: float, history_old, state=None):
        """Residual of the bordered system, element arrays, relative residual per field, and the
        problem's evaluation ``state`` (pass it back to skip re-evaluating at the same z and history).
        ``history_old`` is the history of the last converged step, as the problem declares it."""
        p = self.problem
        q, lam = z[:-1], z[-1]
        internal, arrays, references = state if state is not None else p.evaluate(q, history_old)
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
    system: ControlledSystem, z0, tau, history_old, solver, options: NewtonOptions, stats: SolverStatistics, state=None,
    factor=None,
):
    """Newton-Raphson iterations for one increment to the control value ``tau``.

    ``state`` is the evaluation at ``z0`` returned by the previous increment: at a converged state the
    internal forces and tangent under the updated history equal those of the last iteration (the
    loading pattern does not change), so the first iteration of a step costs no evaluation. ``factor``,
    given with ``state``, solves the first iteration without a new factorization: the bordered tangent
    at that state (from the direct differentiation of the last step, :mod:`fracid.fem.path.ddm`) or the last
    one factorized in the last increment. Later iterations keep a factorization while the residual
    falls fast (``options.reuse_ratio``, modified Newton) and factorize the tangent otherwise.

    Returns
    -------
    z : ndarray
        Converged free dofs followed by the load factor.
    arrays : ElementArrays
        Element arrays at the converged state (trial history and point outputs).
    iterations : int
        Newton iterations: the factorizations of the increment, plus one if it started with ``factor``
        (for full Newton, every iteration).
    state : tuple
        The evaluation at the converged z (for the next increment).
    factor : callable
        The last factorization used (``rhs -> x``), to start the next increment with.

    Raises
    ------
    IncrementFailed
        On a non-finite residual, a singular tangent, or no convergence in ``options.max_iterations``
        factorizations.
    """
    z = z0.copy()
    scale = max(abs(tau), 1e-300)
    keep = started = factor is not None and state is not None
    fresh = 0  # new factorizations
    accepted = None  # (z, progress) of the iterate the kept factorization last solved at
    progress, rejected = None, False
    for iteration in range(options.max_iterations * (options.reuse_iterations + 1) + 1):
        residual, arrays, errors, state = system.evaluate(z, tau, history_old, state if iteration == 0 else None)
        if not np.all(np.isfinite(residual)):
            raise IncrementFailed(f"non-finite residual at iteration {iteration}")
        if iteration > 0 and abs(residual[-1]) <= 1e-10 * scale and all(
            err <= options.tolerance(name) for name, err in errors.items()
        ):
            return z, arrays, fresh + started, state, factor
        last, progress = progress, max(err / options.tolerance(name) for name, err in errors.items())
        if accepted is not None and progress > accepted[1]:
            # the kept factorization made it worse: back to the iterate before, with its own tangent
            z, progress, accepted, rejected = accepted[0].copy(), accepted[1], None, True
            continue
        if iteration > 0:
            # the second iteration tries the last step's factorization on the increment's nonlinearity
            first_try = iteration == 1 and options.reuse_ratio > 0.0
            keep = factor is not None and not rejected and (
                first_try or _keeps_factorization(options, progress, last))
            rejected = False
        if not keep and fresh >= options.max_iterations:
            break
        accepted = (z.copy(), progress) if keep and iteration > 0 else None
        dz, factor = _newton_step(system, arrays, residual, solver, stats, factor if keep else None, iteration)
        fresh += not keep
        z += dz
    detail = ", ".join(f"{k}: {v:.2e}" for k, v in errors.items())
    raise IncrementFailed(f"no convergence in {options.max_iterations} iterations (relative residuals {detail})")


def _keeps_factorization(options: NewtonOptions, progress: float, last: float | None) -> bool:
    """Whether the next iteration may solve with the factorization in hand (modified Newton)."""
    if last is None or options.reuse_ratio <= 0.0 or not progress <= options.reuse_ratio * last:
        return False
    if progress <= 1.0:
        return True
    rate = progress / last
    return rate > 0.0 and np.log(progress) <= options.reuse_iterations * np.log(1.0 / rate)


def _newton_step(system, arrays, residual, solver, stats, factor, iteration):
    """The iteration's correction dz, solved with ``factor`` or a new factorization of the tangent at
    ``arrays``; returns (dz, the factorization used)."""
    t0 = time.perf_counter()
    try:
        if factor is not None:
            equilibration = system.scaled_matrix_scale()
        else:
            matrix, equilibration = system.scaled_matrix(arrays)
            t0 = time.perf_counter()  # the assembly above is not linear-solver time
            factor = factorize(solver, matrix)
            stats.factorizations += 1
            stats.time_factorizations += time.perf_counter() - t0
        dz = equilibration * factor(-residual * equilibration)
    except SingularMatrixError as err:
        raise IncrementFailed(f"singular tangent at iteration {iteration}: {err}") from err
    finally:
        stats.time_linear += time.perf_counter() - t0
        stats.linear_solves += 1
    stats.iterations += 1
    return dz, factor
