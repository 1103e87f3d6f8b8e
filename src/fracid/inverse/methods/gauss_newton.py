"""Bounded Gauss-Newton / Levenberg-Marquardt identification (docs/theory.md, sections 4.3 and 6).

The same Bayesian MAP estimate as the Kalman filter with ``restart="linearize"``, found by
:func:`scipy.optimize.least_squares` (trust region, bounds) with the Jacobian from the sensitivity
interface: with an exact sensitivity (direct differentiation) every linearisation costs about one run.

Notes on :func:`gauss_newton`
-----------------------------
Scaling: in the variables x / sqrt(diag C0) the prior term is a correlation matrix, so
``x_scale=1`` suits parameters of any magnitude. Stopping: least_squares' own tolerances (1e-12)
are only a safety net; the Jacobian callback ends the solve when the undamped Gauss-Newton step
within the box (:func:`scipy.optimize.lsq_linear`) moves no parameter by more than ``tol``
posterior std, and that step is then taken, as the Kalman filter's last pass is (one more
sensitivity call, unless the step is below ``tol**2`` std and reaches no bound): the error drops
to about its square. A failed forward run gets a residual a thousand times the best one, so the
trust region shrinks away from it; the failure is recorded with the number of linearisations
done before it. ``max_nfev = 4 max_iterations`` bounds the rejected trial points as well.
With an exact Jacobian (direct differentiation, docs/theory.md section 6) each iteration costs
about one forward run, against 2 p + 1 with central differences. C is the Laplace (Gauss-Newton)
posterior covariance, the Kalman filter's at its fixed point; on a bound it is the curvature
there, not the spread of the one-sided posterior (see ``at_bound``).
"""

from __future__ import annotations

import numpy as np
from scipy.linalg import solve_triangular
from scipy.optimize import least_squares, lsq_linear

from fracid.inverse.core.fit_status import CONVERGED, FAILED, NOT_CONVERGED, STABLE, STABLE_STEP
from fracid.inverse.methods.kalman_status import KalmanResult
from fracid.inverse.methods.local_fit_inputs import at_bound, box, check_inputs, snap_to_bounds
from fracid.inverse.core.sensitivity import ForwardRunError, exact_sensitivity, memoized


class _Done(Exception):
    """Raised from the Jacobian to end least_squares by our own stopping rule (the state is on the problem)."""


class _WhitenedProblem:
    """r(z) = [L_exp^-1 (h(x) - y_exp); L0^-1 (x - x0)] and J(z), in scaled variables z = x / s.

    s = sqrt(diag C0) puts every parameter in prior standard deviations (E ~ 1e4 MPa and kappa ~ 1e-4
    alike); L0^-1 (x - x0) is computed as chol(C0 / s s^T)^-1 ((x - x0) / s), the same vector.
    Every point costs one call of the sensitivity, shared by the residual and the Jacobian; a failed
    point is remembered as failed.
    """

    def __init__(self, evaluate, sensitivity, executor, y_exp, C_exp, x0, C0, limits, result):
        self.evaluate, self.sensitivity, self.executor = memoized(evaluate), sensitivity, executor
        self.y_exp, self.x0, self.result = y_exp, x0, result
        self.lower, self.upper = limits
        self.s = np.sqrt(np.diag(C0))
        self.C_exp = C_exp  # a Covariance (from check_inputs): used through its whitening
        self.W0 = solve_triangular(np.linalg.cholesky(C0 / np.outer(self.s, self.s)), np.eye(x0.size), lower=True)
        self.points = {}  # x bytes -> (y, S), or None where the run failed
        self.best = np.inf  # smallest |r| met: a failed point gets a residual far above it
        self.iteration = 0  # Jacobian evaluations so far
        self.last = None  # (x, y, J, C) at the last Jacobian
        self.step, self.moved = None, np.inf  # the bounded Gauss-Newton step from it, in x and in std

    def x(self, z):
        return np.clip(z * self.s, self.lower, self.upper)  # z * s may round an ulp outside the box

    def at(self, x):
        """(y, S) at x, or None if the forward run failed there (recorded in the result)."""
        key = x.tobytes()
        if key not in self.points:
            try:
                y, S, records = self.sensitivity(self.evaluate, x, None, self.executor)
                if not (np.all(np.isfinite(y)) and np.all(np.isfinite(S))):
                    raise ForwardRunError(f"non-finite outputs or sensitivities at x = {x.tolist()}")
                self.result.runs += len(records)
                self.result.run_equivalents += len(records)
                self.points[key] = (np.asarray(y, float), np.asarray(S, float))
            except ForwardRunError as err:  # its runs are unknown: counted as the one at x
                self.result.runs += 1
                self.result.run_equivalents += 1
                self.result.failures.append({"iteration": self.iteration, "x": x.tolist(), "error": str(err)})
                self.points[key] = None
        return self.points[key]

    def residual(self, z):
        x = self.x(z)
        got = self.at(x)
        if got is None:  # least_squares cannot take NaN: a large finite residual makes it shrink the step
            n = self.y_exp.size + x.size
            return np.full(n, 1e3 * (self.best + 1.0) / np.sqrt(n))
        r = np.concatenate([self.C_exp.whiten(got[0] - self.y_exp),
                            self.W0 @ ((x - self.x0) / self.s)])
        self.best = min(self.best, float(np.linalg.norm(r)))
        return r

    def jacobian_at(self, x):
        """J in z and the posterior covariance C = (S^T C_exp^-1 S + C0^-1)^-1 at x (x must have run)."""
        y, S = self.at(x)
        J = np.vstack([self.C_exp.whiten(S * self.s), self.W0])
        C = np.linalg.inv(J.T @ J) * np.outer(self.s, self.s)
        return y, J, 0.5 * (C + C.T)


def gauss_newton(evaluate, y_exp, C_exp, x0, C0, *, sensitivity=None, executor=None, bounds=None,
                 max_iterations: int = 20, tol: float = 0.01, callback=None) -> KalmanResult:
    """Bayesian MAP estimate by a bounded Gauss-Newton / Levenberg-Marquardt method with the sensitivity as Jacobian.

    Minimises, inside the box ``bounds``, the objective of :func:`~fracid.inverse.methods.kalman.kalman_filter`
    with ``restart="linearize"``:

        Phi(x) = (y_exp - h(x))^T C_exp^-1 (y_exp - h(x)) + (x - x0)^T C0^-1 (x - x0),

    as the least-squares problem ``|r(x)|``^2 of the whitened residual
    r(x) = [L_exp^-1 (h(x) - y_exp); L0^-1 (x - x0)] (C_exp = L_exp L_exp^T, C0 = L0 L0^T), solved by
    :func:`scipy.optimize.least_squares` (method ``"trf"``) in the variables x / sqrt(diag C0), with
    the Jacobian [L_exp^-1 S; L0^-1] from ``sensitivity``. x and y are in the caller's units. Scaling,
    stopping rule, failed runs and the meaning of C: see the module's notes.

    Parameters
    ----------
    evaluate : callable(x, needed) -> RunRecord or ndarray
        The forward operator h.
    y_exp, C_exp : ndarray or Covariance
        Measured observations and their covariance (any symmetric positive definite (n, n) array, or a
        :class:`~fracid.data.covariance_matrix.Covariance`: a diagonal one forms no n x n matrix).
    x0, C0 : ndarray
        Prior mean and covariance. x0 is moved into the bounds first and is the starting point.
    sensitivity : callable, optional
        ``(evaluate, x, needed, executor) -> (y, S, records)``, see :mod:`fracid.inverse.core.sensitivity`;
        called once per point, with ``needed=None``. By default the exact sensitivities of the runs
        where the model has direct differentiation, else central differences (:func:`exact_sensitivity`).
    executor : Executor, optional
        Passed to the sensitivity.
    bounds : (lower, upper) arrays, optional
        The box (lower < upper for every parameter); None: unbounded.
    max_iterations : int
        Linearisations (Jacobian evaluations) at most.
    tol : float
        Stop when the bounded Gauss-Newton step from the last linearisation moves no parameter by
        more than ``tol`` posterior standard deviations (the Kalman filter's test).
    callback : callable(iteration, step, x, C), optional
        Called at every linearisation, with ``step = 1`` (all observations, as :func:`batch_kalman`).

    Returns
    -------
    KalmanResult
        x, C (posterior covariance at x), y = h(x), runs, iterations (linearisations), status,
        failures (``{"iteration", "x", "error"}``), at_bound, and a history entry per linearisation
        ``{"iteration", "step", "observations", "x", "C"}``. Never raises for a failed forward run:
        when the run at the starting point fails, ``status = "failed: ..."``.
    """
    y_exp, C_exp, x0, C0 = check_inputs(y_exp, C_exp, x0, C0)
    if sensitivity is None:
        evaluate, sensitivity = exact_sensitivity(evaluate)
    lower, upper = box(bounds, x0.size)
    if np.any(lower >= upper):
        raise ValueError("gauss_newton needs lower < upper for every parameter; leave a fixed parameter out of x")
    x0 = np.clip(x0, lower, upper)
    result = KalmanResult(x=x0.copy(), C=C0.copy())
    problem = _WhitenedProblem(evaluate, sensitivity, executor, y_exp, C_exp, x0, C0, (lower, upper), result)
    # off the bounds by our own margin: least_squares' own nudge would be a new point
    z_start = _strictly_inside(x0 / problem.s, lower / problem.s, upper / problem.s)
    if problem.at(problem.x(z_start)) is None:
        result.y = np.full(y_exp.size, np.nan)
        result.status = f"{FAILED}: the forward run at the starting point failed: {result.failures[-1]['error']}"
        result.at_bound = at_bound(x0, lower, upper)
        return result
    message = _solve(problem, z_start, max_iterations, tol, callback)
    x, y, C = _last_step(problem, tol, callback)
    result.x, result.y, result.C, result.iterations = x, y, C, problem.iteration
    word = CONVERGED if result.converged else STABLE if problem.moved < STABLE_STEP else NOT_CONVERGED
    result.status = word if result.converged else f"{word}: {message}, the last Gauss-Newton step was {problem.moved:.3g} std"
    result.at_bound = at_bound(x, lower, upper)
    return result


def _solve(problem, z_start, max_iterations, tol, callback) -> str:
    """Run least_squares from ``z_start`` until the stopping rule (module notes); returns why it stopped.

    The Jacobian callback records every linearisation and the bounded Gauss-Newton step from it on
    ``problem`` (``last``, ``step``, ``moved``), and ends the solve by raising :class:`_Done`.
    """
    lb, ub = problem.lower / problem.s, problem.upper / problem.s

    def jacobian(z):
        x = problem.x(z)
        y, J, C = problem.jacobian_at(x)
        problem.iteration += 1
        problem.last = (x, y, J, C)
        _record(problem.result, problem.iteration, x, C, problem.y_exp.size, callback)
        step = _step(J, problem.residual(z), lb - z, ub - z) * problem.s
        problem.moved = float(np.max(np.abs(step) / np.sqrt(np.diag(C))))
        problem.step = step
        if problem.moved <= tol or problem.iteration >= max_iterations:
            raise _Done
        return J

    try:  # tolerances only as a safety net: the stopping rule is in jacobian()
        solved = least_squares(problem.residual, z_start, jac=jacobian, bounds=(lb, ub), method="trf",
                               x_scale=1.0, tr_solver="exact", ftol=1e-12, xtol=1e-12, gtol=1e-12,
                               max_nfev=4 * max_iterations)
        return f"least_squares stopped ({solved.message})"
    except _Done:
        return f"{max_iterations} iterations reached"


def _last_step(problem, tol, callback):
    """(x, y, C) at the last linearisation, or after the last Gauss-Newton step when converged (module notes).

    Sets ``result.converged``; the step is skipped when below ``tol**2`` std and reaching no new bound, or
    when its run fails.
    """
    result, lower, upper = problem.result, problem.lower, problem.upper
    x, y, _, C = problem.last
    result.converged = problem.moved <= tol
    x_new = snap_to_bounds(np.clip(x + problem.step, lower, upper), lower, upper)
    reaches_bound = np.any(at_bound(x_new, lower, upper) & ~at_bound(x, lower, upper))
    if result.converged and (problem.moved > tol**2 or reaches_bound):
        if problem.at(x_new) is not None:
            problem.iteration += 1
            (y, _, C), x = problem.jacobian_at(x_new), x_new
            _record(result, problem.iteration, x, C, problem.y_exp.size, callback)
    return x, y, C


def _step(J, r, lo, hi):
    """The undamped Gauss-Newton step argmin ``|r + J dz|`` within lo <= dz <= hi (exact for small p)."""
    return lsq_linear(J, -r, bounds=(lo, hi), method="bvls").x


def _record(result, iteration, x, C, n, callback):
    result.history.append({"iteration": iteration, "step": 1, "observations": list(range(n)), "x": x.copy(),
                           "C": C.copy()})
    if callback is not None:
        callback(iteration, 1, x, C)


def _strictly_inside(z, lb, ub):
    """z moved off an active bound by 2e-10 (relative), beyond the 1e-10 at which least_squares moves it."""
    margin = [2e-10 * np.maximum(1.0, np.abs(np.where(np.isfinite(b), b, 0.0))) for b in (lb, ub)]
    lo, hi = lb + margin[0], ub - margin[1]
    z = np.where(z < lo, lo, np.where(z > hi, hi, z))
    with np.errstate(invalid="ignore"):  # lb + ub of an unbounded parameter, not used
        return np.where(lo > hi, 0.5 * (lb + ub), z)
