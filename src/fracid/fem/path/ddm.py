"""Direct differentiation (DDM) of a traced path: d/dx of every recorded curve, step by step.

At each converged step the state z = (q, lambda) satisfies r(q, history(q, x), x) - lambda f_hat = 0
and v . q = tau, with tau the step's control value, held fixed. Differentiating with respect to the
parameters x gives the bordered system of the step's consistent tangent

    [ K   -f_hat ] [ q'      ]   [ -d r / d x ]
    [ v^T    0   ] [ lambda' ] = [     0      ]

with d r / d x taken at fixed q (the formulation's pseudo-load, which carries the history
variables' derivatives from the last step; docs/theory.md, section 6). :class:`PathDerivatives`
factorizes the converged bordered tangent: the derivatives cost a factorization, a pseudo-load, one
solve with p right-hand sides (its residual checked, :func:`~fracid.fem.path.linear_backend.refine`) and
the history update per step. :class:`ConcurrentDerivatives` (the default, ``BESIDE_PATH``) runs these
steps in a thread of their own while the path solves the next step: on the demo beam a run with three
parameters' derivatives costs 1.5 plain runs with PARDISO (2.0 in the path's thread) and the path is the
plain run's to the last digit (benchmarks/sensitivities.py). In the path's thread the factorization is
handed on: it starts the next increment's Newton iterations. (Iterative refinement with the
factorization modified Newton last kept, of an older tangent, was slower on the demo beam: 5.9 s against
4.3 s per run; so was PARDISO's CGS preconditioned by the LU it holds, benchmarks/ddm_preconditioned.py: 3
to 7 iterations per step, 2.48 s against 2.05 s; and GMRES preconditioned by it, 4 to 10 iterations per
right-hand side, 1.27 s against 0.73 s of factorizations and solves over the 88 steps.)

The derivatives are those of the discrete path at the steps' control values: the step sequence is
held, as the central differences of runs that land on the same control values (``checkpoints``) see it.
"""

from __future__ import annotations

import threading
import time
from concurrent.futures import ThreadPoolExecutor

import numpy as np

from fracid.fem.mesh.assembly import dot
from fracid.fem.path.linear_backend import factorize
from fracid.fem.path.linear_solvers import linear_solver
from fracid.fem.path.solver import SolverStatistics
from fracid.fem.path.linear_backend import refine
from fracid.fem.formulations.protocol import initial_history


#: whether a path's derivatives run beside it, in a thread of their own (:class:`ConcurrentDerivatives`);
#: False: in the path's thread, each step's factorization then starting the next increment
BESIDE_PATH = True

#: relative residual of the derivatives' solve (equilibrated bordered system) above which it is refined
DERIVATIVE_RTOL = 1e-10


class PathDerivatives:
    """Derivatives of the recorded curves with respect to the parameters ``names``.

    Parameters
    ----------
    problem
        A problem with ``differentiable`` (the parameters it can differentiate) and
        ``differentiate(q, history_old, history_old_rate, names)`` returning a
        :class:`~fracid.fem.formulations.damage_sensitivity.StepDerivative`.
    names : sequence of str
        The parameters, in the order of the derivatives' last axis.
    observers : mapping {name: observer}, optional
        The run's observers; those with ``differentiable`` true are differentiated by their
        ``derivative(problem, history, history_rate, names)`` (the zone widths of the damage models).
    probes : ProbeSampler, optional
        (:class:`~fracid.fem.path.recorder.ProbeSampler`) Its sparse matrix is applied to dq/dx at the
        steps it wants: ``result()["probed"]`` ``{step: ndarray (n_probes, p)}`` [mm per unit of x].

    Raises
    ------
    NotImplementedError
        When the problem has no direct differentiation.
    ValueError
        When a name is not a parameter the problem differentiates.
    """

    def __init__(self, problem, names, observers=None, probes=None):
        if not callable(getattr(problem, "differentiate", None)):
            raise NotImplementedError(f"{type(problem).__name__} has no direct differentiation; "
                                      "use finite differences of runs (fracid.inverse.core.sensitivity.CentralDifferences)")
        unknown = [n for n in names if n not in problem.differentiable]
        if unknown:
            raise ValueError(f"cannot differentiate with respect to {unknown}: {type(problem).__name__} "
                             f"differentiates {list(problem.differentiable)}")
        self.problem, self.names = problem, tuple(names)
        p = len(self.names)
        self.history_rate = _rates_like(initial_history(problem), p)
        self.load_point = problem.symmetry_factor * problem.load_vector
        self.observers = {name: fn for name, fn in (observers or {}).items() if getattr(fn, "differentiable", False)}
        keys = ["force", "load_point", "work", "elastic", *problem.functionals, *self.observers]
        self.records = {key: [np.zeros(p)] for key in keys}
        self._last = (0.0, 0.0)  # force and load-point displacement of the last step
        self.probes, self.probed = probes, {}

    def step(self, system, z, history_old, arrays, solver, stats, tau=None):
        """Differentiate the converged step z (history before the step ``history_old``, element arrays
        ``arrays`` at z, control value ``tau`` [mm], needed with probes); returns the factorization of
        the converged tangent, to start the next increment with."""
        problem, rec = self.problem, self.records
        q = z[:-1]
        derivative = problem.differentiate(q, history_old, self.history_rate, self.names)
        matrix, equilibration = system.scaled_matrix(arrays)
        rhs = np.vstack([-derivative.pseudo_load, np.zeros((1, len(self.names)))]) * equilibration[:, None]
        t0 = time.perf_counter()
        factor = factorize(solver, matrix)
        stats.factorizations += 1
        stats.time_factorizations += time.perf_counter() - t0
        # the derivatives are only as good as this solve (Newton's solves need only a descent direction):
        # its residual is checked, and refined with the same factorization if a backend left it high
        solution, _, _ = refine(factor, matrix, rhs, factor(rhs), DERIVATIVE_RTOL, 2)
        dz = equilibration[:, None] * solution
        stats.time_linear += time.perf_counter() - t0
        stats.linear_solves += 1
        dq, dforce = dz[:-1], dz[-1]
        self.history_rate, d_elastic = derivative.complete(dq)
        force, displacement = z[-1], dot(self.load_point, q)
        d_displacement = np.einsum("i,ip->p", self.load_point, dq)
        last_force, last_displacement = self._last
        rec["work"].append(rec["work"][-1] + 0.5 * (dforce + rec["force"][-1]) * (displacement - last_displacement)
                           + 0.5 * (force + last_force) * (d_displacement - rec["load_point"][-1]))
        rec["force"].append(dforce)
        rec["load_point"].append(d_displacement)
        rec["elastic"].append(d_elastic)
        for name, vector in problem.functionals.items():
            rec[name].append(np.einsum("i,ip->p", vector, dq))
        for name, observer in self.observers.items():
            rec[name].append(observer.derivative(problem, arrays.history, self.history_rate, self.names))
        self._last = (force, displacement)
        if self.probes is not None and self.probes.wanted(tau):
            self.probed[len(rec["force"]) - 1] = self.probes.matrix @ dq
        return factor

    def result(self) -> dict:
        """``{quantity: ndarray (n_steps + 1, p)}`` for the force, every functional, the load-point
        displacement and the energies (the names of :class:`~fracid.fem.path.path_following.PathResult`),
        ``"names"``: the parameters, and with probes ``"probed"``: ``{step: ndarray (n_probes, p)}``."""
        rec = {key: np.array(values) for key, values in self.records.items()}
        out = {name: rec[name] for name in [*self.problem.functionals, *self.observers]}
        out.update(force=rec["force"], load_point_displacement=rec["load_point"], external_work=rec["work"],
                   elastic_energy=rec["elastic"], dissipated_energy=rec["work"] - rec["elastic"])
        out["names"] = self.names
        if self.probes is not None:
            out["probed"] = self.probed
        return out


class ConcurrentDerivatives:
    """The steps of :class:`PathDerivatives` in a thread of their own, one step behind the path.

    The path never needs its derivatives (they need the path): the derivatives of step n (the
    factorization of its converged tangent, the solve and the history update) run while the path's
    Newton iterations solve step n + 1. The linear solvers release the GIL in their factorizations
    and solves, so on a second core a run with derivatives takes little more than a plain run; and
    the path is the plain run's to the last digit (its modified Newton no longer starts from the
    derivatives' factorization). On one core it costs what the steps one after the other cost.

    The element tangents are copied here, in the path's thread, before it goes on: the next iteration
    overwrites the problem's buffer. The derivatives' thread is one per process, with its
    own linear solver (:func:`~fracid.fem.path.linear_solvers.linear_solver` keeps one per thread and
    backend), shared by the runs of the process one step at a time.

    Parameters
    ----------
    derivatives : PathDerivatives
    solver : str or None
        The backend's name (a solver instance cannot be shared between threads: use
        :meth:`PathDerivatives.step` directly).
    """

    def __init__(self, derivatives: PathDerivatives, solver):
        self.derivatives, self.solver = derivatives, solver
        self.stats = SolverStatistics()
        self._pending = None

    def submit(self, system, z, history_old, arrays, tau) -> None:
        """Differentiate the converged step ``z`` (see :meth:`PathDerivatives.step`) in the derivatives' thread;
        the caller has waited for the step before (:meth:`wait`), whose failure it handles."""
        own = arrays._replace(tangent=np.array(arrays.tangent))
        self._pending = _derivatives_thread().submit(self._step, system, z, history_old, own, tau)

    def _step(self, system, z, history_old, arrays, tau):
        solver = linear_solver(self.solver)  # the derivatives' thread's own
        self.derivatives.step(system, z, history_old, arrays, solver, self.stats, tau=tau)

    def wait(self) -> None:
        """Wait for the step in flight; its exception propagates."""
        pending, self._pending = self._pending, None
        if pending is not None:
            pending.result()


_THREAD_LOCK = threading.Lock()
_THREAD: list = []


def _derivatives_thread() -> ThreadPoolExecutor:
    with _THREAD_LOCK:
        if not _THREAD:
            _THREAD.append(ThreadPoolExecutor(1, thread_name_prefix="fracid-derivatives"))
        return _THREAD[0]


def _rates_like(history, p: int):
    """Zero derivatives of a history (an array, or a dict of arrays) with respect to p parameters."""
    if isinstance(history, dict):
        return {name: _rates_like(value, p) for name, value in history.items()}
    return np.zeros(np.shape(history) + (p,))
