"""Incremental analysis: adaptive steps along a control quantity, step cutting, stop criteria."""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from typing import Callable, Mapping

import numpy as np

from fracid.fem.mesh.assembly import dot
from fracid.fem.path.ddm import PathDerivatives
from fracid.fem.path.linear_solvers import SingularMatrixError, linear_solver as _make_linear_solver
from fracid.fem.formulations.protocol import initial_history, state_energy, state_fields
from fracid.fem.path.solver import ControlledSystem, IncrementFailed, NewtonOptions, SolverStatistics, solve_increment


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
        damaged-zone widths).
    """

    control_name: str
    control: np.ndarray
    force: np.ndarray
    observables: dict
    fields: dict = field(default_factory=dict)
    stats: SolverStatistics = field(default_factory=SolverStatistics)
    status: str = ""
    derivatives: dict | None = None

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


def _check_steps(steps: StepOptions, target):
    for name in ("initial", "maximum", "minimum"):
        value = getattr(steps, name)
        if value is not None and not (math.isfinite(value) and 0 < value <= target):
            raise ValueError(f"step {name} = {value!r} [mm]; it must be positive and not above the target {target}")
    if not (steps.grow >= 1.0 and 0.0 < steps.shrink < 1.0):
        raise ValueError(f"step grow = {steps.grow}, shrink = {steps.shrink}: need grow >= 1 and 0 < shrink < 1")


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
    _check_steps(steps, target)
    t_start = time.perf_counter()
    solver = _make_linear_solver(linear_solver)
    system = ControlledSystem(problem, problem.functionals[control])
    stats = SolverStatistics()
    recorder = _Recorder(problem, control, dict(observers or {}), field_steps)
    derivatives = PathDerivatives(problem, sensitivities, observers) if sensitivities is not None else None
    factor = None  # a factorization to start the next increment with (the derivatives' or the last iteration's)

    z = np.zeros(problem.n_free + 1)
    history = initial_history(problem)
    state = None  # evaluation at the current converged z, reused by the next increment
    tau, status = 0.0, "target reached"
    base = steps.initial  # reference increment; set from the onset of damage when not given
    step = base if base is not None else 1e-3 * target  # elastic probe
    first_step = step
    marks = np.sort(np.asarray([] if checkpoints is None else checkpoints, dtype=float))
    elastic = True

    def result(final_status):
        stats.time_total = time.perf_counter() - t_start
        out = recorder.result(stats, final_status)
        if derivatives is not None:
            out.derivatives = derivatives.result()
        return out

    while tau < target * (1.0 - 1e-12):
        if stats.steps >= max_steps:
            status = f"stopped after max_steps = {max_steps} steps"
            break
        increment = min(step, target - tau)
        ahead = marks[marks > tau * (1.0 + 1e-12) + 1e-15]
        if ahead.size and ahead[0] < tau + increment:
            increment = ahead[0] - tau
        try:
            z_new, arrays, iterations, state, factor = solve_increment(
                system, z, tau + increment, history, solver, newton, stats, state, factor
            )
        except IncrementFailed as err:
            state = factor = None  # the failed iterations overwrote the problem's tangent buffer
            stats.failed_increments += 1
            step = increment * steps.shrink
            minimum = steps.minimum if steps.minimum is not None else 1e-4 * (base or first_step)
            if step < minimum:
                raise _failure(control, tau, increment, stats, recorder, err, result("failed: " + str(err))) from None
            continue
        tau += increment
        if derivatives is not None:
            try:
                factor = derivatives.step(system, z_new, history, arrays, solver, stats)
            except SingularMatrixError as err:
                message = (f"the tangent of the converged step at {control} = {tau:.6g} mm is singular, so the "
                           f"derivatives are not defined there (a bifurcation of the path): {err}")
                raise ConvergenceError(message, result("failed: singular tangent for the derivatives"),
                                       control=control, functionals=tuple(problem.functionals)) from None
        z, history = z_new, arrays.history
        stats.steps += 1
        force = recorder.record(stats.steps, tau, z[:-1], z[-1], arrays)
        if callback is not None:
            callback(stats.steps, tau, force)
        if stop_force_fraction is not None and abs(force) < stop_force_fraction * recorder.peak:
            status = f"force below {stop_force_fraction:g} of the peak"
            break
        onset_ratio = problem.onset_ratio(history)
        if elastic and 0.0 < onset_ratio < 1.0 and steps.jump_to_onset:
            # linear response so far: jump to just below damage onset
            tau_onset = tau / onset_ratio
            base = base if base is not None else tau_onset / 20.0
            # land half a small step below onset, so the next step clearly crosses it
            # (landing on it exactly would leave the crossing to rounding)
            step = max(tau_onset - 0.5 * base * steps.onset_fraction - tau, base * steps.onset_fraction)
            continue
        base = base if base is not None else increment
        if elastic:  # this step crossed damage onset: go on with small steps, growing again
            elastic = False
            step = base * steps.onset_fraction
            continue
        maximum = steps.maximum if steps.maximum is not None else steps.max_factor * base
        step = min(increment * steps.grow if iterations <= steps.easy_iterations else increment, maximum)
    return result(status)


def _failure(control, tau, increment, stats, recorder, err, partial) -> ConvergenceError:
    """The ConvergenceError of an increment that failed at the minimum step, with its snap-back diagnosis."""
    snap_back = snaps_back(partial.force, partial.control)
    message = (f"increment from {control} = {tau:.6g} mm failed at the minimum step {increment:.3g} mm "
               f"after {stats.steps} converged steps (peak force {recorder.peak:.6g} N): {err}")
    if snap_back:
        message += "; snap-back: past the peak the force fell faster than the elastic stiffness"
    return ConvergenceError(message, partial, snap_back, control, tuple(recorder.problem.functionals))


class _Recorder:
    """Collects the curves, observables and fields of the converged steps."""

    def __init__(self, problem, control, observers, field_steps):
        self.problem, self.control, self.observers, self.field_steps = problem, control, observers, field_steps
        self.keep = _field_selector(field_steps)
        # displacement work-conjugate to the load factor, for the whole specimen
        self.load_point = problem.symmetry_factor * problem.load_vector
        names = ["tau", "force", "work", "elastic", "load_point", *problem.functionals, *observers]
        self.records = {name: [0.0] for name in names}
        self.fields, self.last, self.peak = {}, None, 0.0

    def record(self, step, tau, q, force, arrays) -> float:
        rec, problem = self.records, self.problem
        displacement = dot(self.load_point, q)
        work = 0.5 * (force + rec["force"][-1]) * (displacement - rec["load_point"][-1])
        rec["work"].append(rec["work"][-1] + work)
        rec["tau"].append(tau)
        rec["force"].append(force)
        rec["load_point"].append(displacement)
        rec["elastic"].append(state_energy(problem, q, arrays))
        for name, vec in problem.functionals.items():
            rec[name].append(dot(vec, q))
        for name, fn in self.observers.items():
            rec[name].append(float(fn(problem, q, arrays)))
        if self.keep(step):
            self.fields[step] = state_fields(problem, q, arrays)
        self.last = (step, q, arrays)
        self.peak = max(self.peak, abs(force))
        return force

    def result(self, stats, status) -> PathResult:
        if self.last is not None and self.field_steps is not None and self.last[0] not in self.fields:
            step, q, arrays = self.last
            self.fields[step] = state_fields(self.problem, q, arrays)
        rec = {name: np.array(values) for name, values in self.records.items()}
        obs = {name: rec[name] for name in [*self.problem.functionals, *self.observers]}
        obs["load_point_displacement"] = rec["load_point"]
        obs["external_work"] = rec["work"]
        obs["elastic_energy"] = rec["elastic"]
        obs["dissipated_energy"] = rec["work"] - rec["elastic"]
        return PathResult(self.control, rec["tau"], rec["force"], obs, self.fields, stats, status)


def _field_selector(field_steps):
    if field_steps is None or field_steps == "last":
        return lambda step: False
    if field_steps == "all":
        return lambda step: True
    wanted = {int(s) for s in field_steps}
    return lambda step: step in wanted
