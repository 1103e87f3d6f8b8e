"""Incremental analysis: adaptive steps along a control quantity, step cutting, stop criteria."""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from typing import Callable, Mapping

import numpy as np

from fracid.fem.path import ddm
from fracid.fem.path.ddm import ConcurrentDerivatives, PathDerivatives
from fracid.fem.path.recorder import ProbeSampler, Recorder, probed_at
from fracid.fem.path import linear_solvers
from fracid.fem.path.linear_backend import SingularMatrixError
from fracid.fem.formulations.protocol import initial_history
from fracid.fem.path.solver import ControlledSystem, IncrementFailed, NewtonOptions, SolverStatistics, solve_increment
from fracid.fem.path.step_sizes import StepSizes, check_steps


@dataclass
class PathResult:
    """Outcome of an incremental analysis, one entry per converged step (step 0 is the unloaded state).

    Attributes
    ----------
    control_name : str
        The prescribed functional.
    control : ndarray
        Its value at every step [mm].
    force : ndarray
        The load factor, i.e. the applied force for the unit load pattern [N].
    observables : dict {name: ndarray}
        Every named functional of the problem [mm], the load-point displacement (work-conjugate to
        the force, so for a symmetric model it is scaled by the number of copies), the external work,
        elastic energy and dissipated energy [N mm], and the specimen's observers.
    fields : dict {step: dict}
        Fields at the requested steps, as the problem's ``fields`` names them (nodal u and the named
        fields, the history and point outputs: e.g. u, ebar, kappa, omega of the gradient model).
    stats : SolverStatistics
    status : str
        Why the analysis ended.
    derivatives : dict or None
        With ``sensitivities`` asked: ``derivatives[name]`` (n_steps + 1, p) is d/dx of ``force`` or of
        the observable ``name`` at every step, x the parameters ``derivatives["names"]`` (the control
        is held; see :mod:`fracid.fem.path.ddm`), and of the observers that are differentiable (the
        damaged-zone widths); with ``probes`` also ``derivatives["probed"]`` {step: (n_probes, p)}.
    probed : dict {step: ndarray (n_probes,)}
        With ``probes`` asked: the probes [mm] at the steps on the checkpoints (:meth:`probed_at`).
    """

    control_name: str
    control: np.ndarray
    force: np.ndarray
    observables: dict
    fields: dict = field(default_factory=dict)
    stats: SolverStatistics = field(default_factory=SolverStatistics)
    status: str = ""
    derivatives: dict | None = None
    probed: dict = field(default_factory=dict)

    @property
    def n_steps(self) -> int:
        return self.control.size - 1

    @property
    def peak_force(self) -> float:
        """Largest absolute applied force [N]."""
        return float(np.max(np.abs(self.force)))

    def curve(self, name: str | None = None) -> tuple[np.ndarray, np.ndarray]:
        """(displacement-like quantity, force): the control by default, or any observable."""
        x = self.control if name is None or name == self.control_name else self.observables[name]
        return x, self.force

    def probed_at(self, controls) -> tuple:
        """(values (n, n_probes), derivatives (n, n_probes, p) or None) of the probes at the checkpoints
        ``controls`` [mm]; NaN beyond the last step (see :func:`~fracid.fem.path.recorder.probed_at`)."""
        return probed_at(self, controls)


class ConvergenceError(RuntimeError):
    """The analysis could not go on even with the smallest step; ``partial`` holds what converged.

    Attributes
    ----------
    partial : PathResult
        The steps that converged.
    snap_back : bool
        The diagnosis of :func:`snaps_back`: the failure came past the peak while the force was falling
        faster than the control could follow, so the curve snaps back under ``control`` and only a
        control that grows through the snap-back (an opening across the crack) can trace it.
    control : str or None
        The prescribed functional that failed.
    functionals : tuple of str
        Every functional of the problem (the controls it could have been run with).
    """

    def __init__(self, message: str, partial: PathResult, snap_back: bool = False, control: str | None = None,
                 functionals: tuple = ()):
        super().__init__(message)
        self.partial, self.snap_back, self.control, self.functionals = partial, snap_back, control, tuple(functionals)

    def __reduce__(self):  # pickled with its attributes (runs in worker processes)
        return type(self), (self.args[0], self.partial, self.snap_back, self.control, self.functionals)


def snaps_back(force, control) -> bool:
    """Whether a path that failed was snapping back under its control.

    True past the peak when, over the last converged step, the force fell faster than the initial
    stiffness: dF/dtau < -F_1 / tau_1 (step 1 is elastic). Softening under a control that can follow
    it stays far flatter; as the curve turns back, dF/dtau goes to minus infinity.

    Parameters
    ----------
    force : ndarray
        The force [N] at every converged step, step 0 unloaded.
    control : ndarray
        The control [mm] at the same steps.
    """
    force, control = np.abs(np.asarray(force, dtype=float)), np.asarray(control, dtype=float)
    if force.size < 3 or not force[-1] < force.max() or control[1] <= 0.0:
        return False
    slope = (force[-1] - force[-2]) / (control[-1] - control[-2])
    return bool(slope < -force[1] / control[1])


@dataclass(frozen=True)
class StepOptions:
    """Adaptive step-size rule.

    Parameters
    ----------
    initial : float or None
        First increment of the control quantity [mm]; None: 1/20 of the control value at damage onset.
    maximum, minimum : float or None
        Bounds on the increment [mm]; None: ``max_factor`` x and 1e-4 x the initial increment.
    max_factor : float
        Largest increment relative to the initial one when ``maximum`` is None.
    grow, shrink : float
        Factor applied after an easy increment (at most ``easy_iterations``) and after a cut.
    easy_iterations : int
    onset_fraction : float
        The first increment after damage onset, as a fraction of ``initial``; the steps then grow
        back. Small first steps resolve the peak and keep the damaged zone that a single large step
        would create at once (an artefact, blatant in the local model) from appearing.
    jump_to_onset : bool
        While the response is linear, jump straight to just below damage onset. That step's
        position depends on the parameters; without the jump (and with ``initial`` given,
        ``onset_fraction = max_factor = 1`` and checkpoints at every step) the step sequence does
        not, which is what comparing derivatives with differences of runs needs.
    """

    initial: float | None = None
    maximum: float | None = None
    minimum: float | None = None
    max_factor: float = 4.0
    grow: float = 1.5
    shrink: float = 0.5
    easy_iterations: int = 4
    onset_fraction: float = 0.02
    jump_to_onset: bool = True


def _check_request(problem, control, target, stop_force_fraction, max_steps):
    if control not in problem.functionals:
        raise ValueError(f"unknown control {control!r}; this specimen offers {sorted(problem.functionals)}")
    if not (isinstance(target, (int, float)) and math.isfinite(target) and target > 0):
        raise ValueError(f"target = {target!r}: the final control value must be a positive finite number [mm]")
    if stop_force_fraction is not None and not 0.0 < stop_force_fraction < 1.0:
        raise ValueError(f"stop_force_fraction = {stop_force_fraction!r}; it must be in (0, 1) or None")
    if int(max_steps) != max_steps or max_steps < 1:
        raise ValueError(f"max_steps = {max_steps!r}; it must be a positive integer")


def follow_path(
    problem,
    control: str,
    target: float,
    *,
    steps: StepOptions = StepOptions(),
    stop_force_fraction: float | None = None,
    max_steps: int = 2000,
    newton: NewtonOptions = NewtonOptions(),
    linear_solver=None,
    observers: Mapping[str, Callable] | None = None,
    field_steps="last",
    callback: Callable | None = None,
    checkpoints=None,
    sensitivities=None,
    probes=None,
) -> PathResult:
    """Trace the equilibrium path by increasing the functional ``control`` up to ``target``.

    Parameters
    ----------
    problem : Problem
        Any :class:`~fracid.fem.formulations.protocol.Problem`; its history is allocated from its declaration
        (:func:`~fracid.fem.formulations.protocol.initial_history`) and carried from step to step.
    control : str
        Name of the prescribed functional (one of ``problem.functionals``).
    target : float
        Final value of the control quantity [mm].
    steps : StepOptions
        Adaptive step-size rule. While the material is still undamaged, the response is linear and
        the next step jumps straight to just below damage onset.
    stop_force_fraction : float, optional
        Stop once the force has fallen below this fraction of its peak after the peak.
    max_steps : int
        Stop after this many converged steps.
    newton : NewtonOptions
    linear_solver : str, LinearSolver or None
        Backend: ``"superlu"``, ``"pardiso"``, an instance, or None / ``"auto"`` (PARDISO where the
        ``pardiso`` extra is installed, else SuperLU).
    observers : mapping {name: f(problem, q, arrays) -> float}, optional
        Scalar observables evaluated at every converged step (e.g. the damaged-zone width).
    field_steps : "last", "all", None or iterable of int
        Steps at which the fields are stored (the last converged step is always stored unless None).
    callback : callable(step, tau, force), optional
        Called after each converged step (progress reporting).
    checkpoints : array_like, optional
        Control values [mm] that must be steps of the analysis (the sampling points of measured
        data), so that the computed values there are not interpolated between steps and do not
        jitter with the adaptive step sequence.
    sensitivities : sequence of str, optional
        Parameters to differentiate the path with respect to (:mod:`fracid.fem.path.ddm`).
    probes : scipy.sparse matrix (n_probes, n_u), optional
        Point probes as weights of the nodal displacement vector (``fields[step]["u"]``); the run records
        ``probes @ u`` at the steps on ``checkpoints`` (every step without checkpoints) in
        ``PathResult.probed``, and with ``sensitivities`` ``probes @ du/dx`` in ``derivatives["probed"]``,
        never forming a dense (n_probes x unknowns) array (full-field data: :class:`ProbeSampler`).

    Returns
    -------
    PathResult

    Raises
    ------
    ConvergenceError
        When an increment fails even at the minimum step; its ``partial`` attribute holds the steps
        that converged.
    """
    _check_request(problem, control, target, stop_force_fraction, max_steps)
    check_steps(steps, target)
    sampler = None if probes is None else ProbeSampler(problem, probes, checkpoints)
    run = _Run(problem, control, linear_solver, newton, observers, field_steps, sensitivities, sampler)
    return run.trace(StepSizes(steps, target, checkpoints), max_steps, stop_force_fraction, callback)


class _Run:
    """One incremental analysis of :func:`follow_path`: the solver, the records and the derivatives."""

    def __init__(self, problem, control, linear_solver, newton, observers, field_steps, sensitivities, probes=None):
        self.t_start = time.perf_counter()
        self.problem, self.control, self.newton = problem, control, newton
        self.solver = linear_solvers.linear_solver(linear_solver)
        self.system = ControlledSystem(problem, problem.functionals[control])
        self.stats = SolverStatistics()
        self.recorder = Recorder(problem, dict(observers or {}), field_steps, probes)
        self.derivatives = (PathDerivatives(problem, sensitivities, observers, probes)
                            if sensitivities is not None else None)
        # the derivatives beside the path, unless the caller's own solver instance would be shared
        self.concurrent = (ConcurrentDerivatives(self.derivatives, linear_solver)
                           if self.derivatives is not None and ddm.BESIDE_PATH
                           and (linear_solver is None or isinstance(linear_solver, str)) else None)
        self.derivative_tau = None  # the control of the step whose derivatives are in flight

    def trace(self, sizes: StepSizes, max_steps, stop_force_fraction, callback) -> PathResult:
        """Converged steps up to the target or a stop criterion (see :func:`follow_path`)."""
        stats, recorder = self.stats, self.recorder
        factor = None  # a factorization to start the next increment with (the derivatives' or the last iteration's)
        z = np.zeros(self.problem.n_free + 1)
        history = initial_history(self.problem)
        state = None  # evaluation at the current converged z, reused by the next increment
        tau, status = 0.0, "target reached"
        while tau < sizes.target * (1.0 - 1e-12):
            if stats.steps >= max_steps:
                status = f"stopped after max_steps = {max_steps} steps"
                break
            increment = sizes.increment(tau)
            try:
                z_new, arrays, iterations, state, factor = solve_increment(
                    self.system, z, tau + increment, history, self.solver, self.newton, stats, state, factor
                )
            except IncrementFailed as err:
                state = factor = None  # the failed iterations overwrote the problem's tangent buffer
                stats.failed_increments += 1
                if sizes.cut(increment):
                    self.wait_derivatives()  # a failure of the derivatives came first
                    raise _failure(self.control, tau, increment, stats, recorder, err,
                                   self.result("failed: " + str(err))) from None
                continue
            tau += increment
            if self.derivatives is not None:
                factor = self.differentiate(tau, z_new, history, arrays) or factor
            z, history = z_new, arrays.history
            stats.steps += 1
            force = recorder.record(stats.steps, tau, z[:-1], z[-1], arrays)
            if callback is not None:
                callback(stats.steps, tau, force)
            if stop_force_fraction is not None and abs(force) < stop_force_fraction * recorder.peak:
                status = f"force below {stop_force_fraction:g} of the peak"
                break
            sizes.advance(tau, increment, iterations, self.problem.onset_ratio(history))
        self.wait_derivatives()
        return self.result(status)

    def differentiate(self, tau, z, history, arrays):
        """The derivatives' step at the converged ``z`` (control ``tau``): in this thread, returning the
        factorization of the converged tangent for the next increment, or beside the path (None)."""
        if self.concurrent is None:
            try:
                return self.derivatives.step(self.system, z, history, arrays, self.solver, self.stats, tau=tau)
            except SingularMatrixError as err:
                raise self._singular(tau, err) from None
        self.wait_derivatives()
        self.concurrent.submit(self.system, z, history, arrays, tau)
        self.derivative_tau = tau
        return None

    def wait_derivatives(self):
        """Wait for the derivatives of the last step recorded (beside the path); if they failed, raise the
        :class:`ConvergenceError` of the steps before it."""
        if self.concurrent is None:
            return
        try:
            self.concurrent.wait()
        except SingularMatrixError as err:
            self.recorder.drop_last()
            self.stats.steps -= 1
            raise self._singular(self.derivative_tau, err) from None

    def _singular(self, tau, err) -> ConvergenceError:
        message = (f"the tangent of the converged step at {self.control} = {tau:.6g} mm is singular, so the "
                   f"derivatives are not defined there (a bifurcation of the path): {err}")
        return ConvergenceError(message, self.result("failed: singular tangent for the derivatives"),
                                control=self.control, functionals=tuple(self.problem.functionals))

    def result(self, status: str) -> PathResult:
        """The :class:`PathResult` of the steps recorded so far, ending with ``status``."""
        if self.concurrent is not None:
            self.stats.add(self.concurrent.stats)
            self.concurrent.stats = SolverStatistics()
        self.stats.time_total = time.perf_counter() - self.t_start
        control, force, observables, fields = self.recorder.curves()
        out = PathResult(self.control, control, force, observables, fields, self.stats, status,
                         probed=self.recorder.probed)
        if self.derivatives is not None:
            out.derivatives = self.derivatives.result()
        return out


def _failure(control, tau, increment, stats, recorder, err, partial) -> ConvergenceError:
    """The ConvergenceError of an increment that failed at the minimum step, with its snap-back diagnosis."""
    snap_back = snaps_back(partial.force, partial.control)
    message = (f"increment from {control} = {tau:.6g} mm failed at the minimum step {increment:.3g} mm "
               f"after {stats.steps} converged steps (peak force {recorder.peak:.6g} N): {err}")
    if snap_back:
        message += "; snap-back: past the peak the force fell faster than the elastic stiffness"
    return ConvergenceError(message, partial, snap_back, control, tuple(recorder.problem.functionals))
