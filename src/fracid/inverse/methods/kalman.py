"""Kalman filter for parameter identification (docs/theory.md, section 4.3): step by step, and the batch variant.

Bounds
    An update that leaves the box is projected back by :func:`project_to_box` (the most probable point
    of the update's Gaussian inside the box), and backtracking only moves between points of the box, so
    every point the filter evaluates is inside it. The covariance is the linearised posterior's, unchanged
    by the projection. For a parameter on a bound it describes the curvature of the objective there, not
    the spread of a posterior cut by the bound: the true posterior is one-sided, and the parameter is
    flagged in ``at_bound``.
Oscillation
    When the estimates of successive passes alternate (:func:`~fracid.inverse.methods.kalman_status.oscillates`),
    the steps are under-relaxed, halved at each detection down to
    :data:`~fracid.inverse.methods.kalman_status.MIN_RELAXATION` (``result.relaxation``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import lsq_linear

from fracid.data.covariance_matrix import as_covariance, independent_cuts
from fracid.inverse.methods.assimilation import assimilate
from fracid.inverse.methods.kalman_status import KalmanResult, judge_last_pass, judge_stop, relaxed
from fracid.inverse.methods.local_fit_inputs import at_bound, box, check_inputs, snap_to_bounds
from fracid.inverse.core.sensitivity import ForwardRunError, evaluate_points, exact_sensitivity, memoized


def project_to_box(x, C, lower, upper) -> np.ndarray:
    """The point of the box [lower, upper] nearest to x in the metric of C^-1.

    argmin (z - x)^T C^-1 (z - x) subject to lower <= z <= upper ("estimate projection", Simon &
    Chia 2002): the most probable point of the Gaussian N(x, C) inside the box. Along a valley of
    correlated parameters it slides along the valley rather than cutting across it, as clipping
    each parameter on its own would. Solved by :func:`scipy.optimize.lsq_linear` in standardised
    variables; clipping is the fallback when C is numerically singular.
    """
    x = np.asarray(x, float)
    if np.all((x >= lower) & (x <= upper)):
        return x
    scale = np.sqrt(np.diag(C))
    try:
        W = np.linalg.cholesky(np.linalg.inv(C / np.outer(scale, scale))).T  # W^T W = (standardised C)^-1
        z = lsq_linear(W, W @ (x / scale), bounds=(lower / scale, upper / scale)).x * scale
    except (np.linalg.LinAlgError, ValueError):
        z = x
    return snap_to_bounds(np.clip(z, lower, upper), lower, upper)


def _observation_groups(n, groups):
    if groups is None:
        return [np.array([i]) for i in range(n)]
    groups = [np.atleast_1d(np.asarray(g, dtype=int)) for g in groups]
    flat = np.concatenate(groups)
    if not np.array_equal(np.sort(flat), np.arange(n)) or np.any(np.diff([g.max() for g in groups]) <= 0):
        raise ValueError("observation groups must cover every observation once, in increasing order")
    return groups


def independent_groups(groups: list, C_exp) -> list:
    """Consecutive ``groups`` with each end moved on to the next position where ``C_exp`` splits into
    independent parts (:func:`~fracid.data.covariance_matrix.independent_cuts`), so that no group shares a
    correlated block with another (the filter assimilates them one after another as independent: a DIC frame
    with its rigid motion, an error term along a curve, stay whole); groups left empty are dropped. Groups that
    are not consecutive ranges are returned as they are."""
    if not all(np.array_equal(g, np.arange(g[0], g[-1] + 1)) for g in groups):
        return groups
    cuts = independent_cuts(as_covariance(C_exp))
    ends = np.unique(cuts[np.searchsorted(cuts, [g[-1] + 1 for g in groups])])
    return [np.arange(a, b) for a, b in zip(np.concatenate([[0], ends[:-1]]), ends) if b > a]


def _converged(x_new, x_old, C, tol):
    return bool(np.all(np.abs(x_new - x_old) <= tol * np.sqrt(np.diag(C))))


class _Linearizer:
    """Runs and sensitivities at the filter's points, with backtracking over failed runs.

    ``at(x, anchor, needed)`` tries x, then the points anchor + 2^-k (x - anchor), k = 1..max_backtracks,
    and returns the first (point, y, S) whose run succeeds (and that ``accept`` takes); failures are
    recorded in the result. The run at the point comes first, alone, so that a failing or worse point
    costs one run, not 2 p + 1.
    """

    def __init__(self, evaluate, sensitivity, executor, result, max_backtracks, n_outputs):
        self.evaluate, self.sensitivity, self.executor = memoized(evaluate), sensitivity, executor
        self.result, self.max_backtracks, self.n_outputs = result, max_backtracks, n_outputs
        self.last_full = None  # (point, y) of the last successful run over all outputs
        self.last_error = ""
        self.anchors_taken = []  # last full runs a pass was linearised at when the estimate was refused

    def at(self, x, anchor, needed, where, accept=None):
        tried = []
        for attempt in range(self.max_backtracks + 1):
            point = x if anchor is None or attempt == 0 else anchor + 0.5**attempt * (x - anchor)
            if any(np.array_equal(point, t) for t in tried):
                break
            tried.append(point)
            centre = evaluate_points(self.evaluate, [point], needed, self.executor)[0]
            if not centre.ok:
                self._fail(point, centre.error, where)
                continue
            if accept is not None and not accept(point, centre.y):
                self.result.runs += 1
                self.last_error = "the objective does not decrease along the step"
                continue
            try:
                y, S, records = self.sensitivity(self.evaluate, point, needed, self.executor)
            except ForwardRunError as err:
                self._fail(point, str(err), where)
                continue
            self.result.runs += len(records)
            self.result.run_equivalents += len(records) * (self.n_outputs if needed is None else needed) / self.n_outputs
            if needed is None or needed >= self.n_outputs:
                self.last_full = (point, y)
            return point, y, S
        return None

    def objective_at(self, x, objective):
        """The objective at x from a full run (remembered: no new run for a point already run); inf if it fails."""
        record = evaluate_points(self.evaluate, [x], None, self.executor)[0]
        return objective(x, record.y) if record.ok else np.inf

    def _fail(self, point, error, where):
        self.result.runs += 1
        self.last_error = error
        self.result.failures.append({**where, "x": point.tolist(), "error": error})


def kalman_filter(evaluate, y_exp, C_exp, x0, C0, *, groups=None, max_iterations: int = 10, tol: float = 0.01,
                  restart: str = "linearize", sensitivity=None, executor=None, bounds=None, callback=None,
                  max_backtracks: int = 4, names=None, damping: bool = True) -> KalmanResult:
    """Step-by-step Kalman filter with global iterations (docs/theory.md, section 4.3), bounded and failure tolerant.

    For t = 1..n the observations of group t are assimilated with :func:`~fracid.inverse.methods.assimilation.kalman_update`, using
    S_t = d h_t / d x and h_t at a linearisation point (forward runs only up to the last
    observation of the group). h is nonlinear, so the sequence is repeated (global iterations) until
    no parameter moves by more than ``tol`` standard deviations. Two ways to repeat it:

    ``restart="linearize"`` (default)
        Every pass starts again from the prior (x0, C0) and linearises h about the previous pass's
        estimate: y_t - h_t(x_lin) - S_t (x_{t-1} - x_lin) is the innovation. The fixed point is the
        Bayesian maximum a posteriori estimate; for a linear h every pass gives the closed-form
        posterior, and its sensitivities come from one set of full runs per pass. The passes are
        damped Gauss-Newton steps: a new linearisation point whose objective
        (y - h)^T C_exp^-1 (y - h) + (x - x0)^T C0^-1 (x - x0) is higher than the last one's (by more than
        :data:`OBJECTIVE_SLACK`) is moved halfway back, up to ``max_backtracks`` times.
    ``restart="prior-mean"``
        The thesis's wording (docs/theory.md, section 4.3): the last estimate becomes the new prior mean (prior covariance C0),
        linearising at the running estimate. It re-uses the data in every pass, so the covariance
        is optimistic and the estimate drifts towards the least-squares fit.

    Parameters
    ----------
    evaluate : callable(x, needed) -> RunRecord or ndarray
        The forward operator (e.g. :class:`~fracid.inverse.core.forward_operator.ForwardOperator`, or
        :class:`~fracid.inverse.core.runs.StoredOperator` to store every run).
    y_exp, C_exp : ndarray or Covariance
        Measured observations and their covariance (an (n, n) array or a
        :class:`~fracid.data.covariance_matrix.Covariance`). A group of more observations than
        parameters is assimilated in information form (:func:`~fracid.inverse.methods.assimilation.assimilate`),
        so no n x n matrix is formed for a diagonal, low-rank or block C_exp. Sequential assimilation
        assumes no correlation between groups (a block-diagonal C_exp); within a group any covariance
        is used. Consecutive groups are made so: each end is moved on to the end of the correlated block it
        falls in (:func:`independent_groups`).
    x0, C0 : ndarray
        Prior mean and covariance (from KNN or the user). x0 is moved into the bounds first.
    groups : sequence of index arrays, optional
        The observation sequence; one observation per step by default.
    sensitivity : callable, optional
        See :mod:`fracid.inverse.core.sensitivity`; by default the exact sensitivities of the runs where
        the model has direct differentiation, else central differences (:func:`exact_sensitivity`).
    executor : Executor, optional
        Runs the 2 p + 1 runs of central differences in parallel.
    bounds : (lower, upper) arrays, optional
        The box every estimate stays in (the identification bounds; see the module's notes).
    callback : callable(iteration, step, x, C), optional
    max_backtracks : int
        Halvings of a step towards the last good point when the run at the filter's point fails.
    names : sequence of str, optional
        Parameter names, for the status (a valley names its pair).
    damping : bool
        Under-relax the steps when the estimates of successive passes alternate (see the module's
        notes); False: the oscillation is only reported.

    Returns
    -------
    KalmanResult
        Never raises for a failed forward run: when no point near the filter's runs, the stage
        stops with the last complete estimate and a status of :func:`~fracid.inverse.methods.kalman_status.judge_stop`. The status judges
        convergence on the last pass's step in std and objective change
        (:func:`~fracid.inverse.methods.kalman_status.judge`): the loop itself stops at ``tol``.
    """
    if restart not in ("linearize", "prior-mean"):
        raise ValueError(f"restart = {restart!r}; choose 'linearize' or 'prior-mean'")
    y_exp, C_exp, x0, C0 = check_inputs(y_exp, C_exp, x0, C0)
    if sensitivity is None:
        evaluate, sensitivity = exact_sensitivity(evaluate)
    groups = independent_groups(_observation_groups(y_exp.size, groups), C_exp)
    lower, upper = box(bounds, x0.size)
    x0 = np.clip(x0, lower, upper)
    result = KalmanResult(x=x0.copy(), C=C0.copy(), passes=[{"iteration": 0, "x": x0.copy()}])
    lin = _Linearizer(evaluate, sensitivity, executor, result, max_backtracks, y_exp.size)
    objective = _map_objective(y_exp, C_exp, x0, C0 if restart == "linearize" else None)
    problem = _FilterProblem(y_exp, C_exp, x0, C0, groups, lower, upper, restart == "linearize", callback)
    stopped, last = _global_iterations(problem, lin, objective, result, max_iterations, tol, damping)
    if not _finish(result, lin, lower, upper, stopped):
        judge_last_pass(result, lambda x: lin.objective_at(x, objective), objective, last, max_iterations, names)
    return result


@dataclass(frozen=True)
class _FilterProblem:
    """What every pass of the filter assimilates: the checked data, prior, observation groups and box."""

    y_exp: np.ndarray
    C_exp: object
    x0: np.ndarray
    C0: np.ndarray
    groups: list
    lower: np.ndarray
    upper: np.ndarray
    linearize: bool  # restart="linearize": every pass from the prior, one linearisation per pass
    callback: object = None


def _global_iterations(problem, lin, objective, result, max_iterations, tol, damping):
    """The passes of the filter, until converged, stopped by a failed run, or ``max_iterations``.

    Returns
    -------
    stopped : str
        Why a failed run stopped the filter ("" if none did).
    last : tuple or None
        (the last pass's linearisation point, its estimate, the objective at the point or None), for
        :func:`~fracid.inverse.methods.kalman_status.judge_last_pass`.
    """
    previous, last = problem.x0.copy(), None
    for iteration in range(1, max_iterations + 1):
        fixed, f_start = None, None
        if problem.linearize and iteration > 1:
            fixed = _relinearize(lin, objective, previous, iteration, result)
            if fixed is None:
                return f"at iteration {iteration}: {lin.last_error}", last
            previous = fixed[0]
            f_start = objective(previous, fixed[1])
            result.passes[-1]["objective"] = f_start
        start = problem.x0 if problem.linearize else previous
        x, C, stopped = _one_pass(problem, lin, result, iteration, start.copy(), problem.C0.copy(), fixed)
        if stopped:
            return stopped, last
        result.iterations = iteration
        last = (previous, x, f_start)
        result.converged = iteration > 1 and _converged(x, previous, C, tol)
        x = relaxed(result, x, previous, C) if damping else x
        previous, result.x, result.C = x, x, C
        result.passes.append({"iteration": iteration, "x": x.copy()})
        if result.converged:
            break
    return "", last


def _relinearize(lin, objective, previous, iteration, result):
    """(point, y, S) of the pass's one linearisation, at the last estimate or backtracked towards the last full
    run while its objective rises; failing that, at the last full run itself, once per such point (the pass is
    then a Gauss-Newton step from the best point run: a first pass that ended beside its last full run, a little
    above it, must not stop the filter there); None when no point is taken (then ``result.x`` is that last full
    run's point)."""
    anchor = lin.last_full[0] if lin.last_full is not None else None
    accept = None if anchor is None else _decreases(objective, *lin.last_full)
    where = {"iteration": iteration, "step": 0}
    got = lin.at(previous, anchor, None, where, accept)
    if got is None and anchor is not None and not any(np.array_equal(anchor, a) for a in lin.anchors_taken):
        lin.anchors_taken.append(anchor)
        got = lin.at(anchor, None, None, where)
    if got is None:  # keep the last point that ran (and its pass's covariance)
        result.x = anchor if anchor is not None else result.x
    return got


def _one_pass(problem, lin, result, iteration, x, C, fixed):
    """One pass over the observation groups from (x, C).

    Parameters
    ----------
    fixed : (point, y, S) or None
        The pass's one linearisation; None: linearise at the running estimate before every step.

    Returns
    -------
    x, C, stopped
        The estimate and covariance after the last group, and why a failed run stopped the pass ("" if
        none did).
    """
    last_point = None
    for step, rows in enumerate(problem.groups, start=1):
        if fixed is not None:
            point, y, S = fixed
        else:
            got = lin.at(x, last_point, int(rows.max()) + 1, {"iteration": iteration, "step": step})
            if got is None:
                return x, C, f"at iteration {iteration}, step {step}: {lin.last_error}"
            point, y, S = got
            x = last_point = point
        innovation = problem.y_exp[rows] - y[rows] - S[rows] @ (x - point)
        x, C, _ = assimilate(x, C, S[rows], innovation, problem.C_exp.take(rows))
        x = project_to_box(x, C, problem.lower, problem.upper)
        result.history.append({"iteration": iteration, "step": step, "observations": rows.tolist(),
                               "x": x.copy(), "C": C.copy()})
        if problem.callback is not None:
            problem.callback(iteration, step, x, C)
    return x, C, ""


def _map_objective(y_exp, C_exp, x0, C0):
    """(x, y) -> (y_exp - y)^T C_exp^-1 (y_exp - y) + (x - x0)^T C0^-1 (x - x0); without the prior's term
    when C0 is None."""
    W0 = None if C0 is None else np.linalg.inv(C0)

    def f(x, y):
        d = x - x0
        return float(C_exp.quadratic(y_exp - y) + (0.0 if W0 is None else d @ W0 @ d))

    return f


#: Rise of the objective (in chi^2 units) a damped step may bring and still be taken: far below the
#: one-std level (1), and above the noise that adaptive load steps put in the computed curve.
OBJECTIVE_SLACK = 0.1


def _decreases(objective, anchor, y_anchor):
    """Accept a point whose objective is not above the anchor's (within :data:`OBJECTIVE_SLACK`)."""
    reference = objective(anchor, y_anchor)
    return lambda x, y: bool(np.all(np.isfinite(y))) and objective(x, y) <= reference + OBJECTIVE_SLACK


def _finish(result, lin, lower, upper, stopped) -> str:
    """The run at the final estimate (backtracking to the last full run if it fails), the status of a stop
    and the bound flags; returns why the filter stopped ("" if it did not)."""
    got = lin.at(result.x, lin.last_full[0] if lin.last_full is not None else None, None,
                 {"iteration": result.iterations, "step": "final"})
    if got is not None:
        result.x, result.y = got[0], got[1]
    else:
        result.y = np.full(result.y.size if result.y is not None else lin.n_outputs, np.nan)
        stopped = stopped or f"the forward run at the final estimate failed: {lin.last_error}"
    if stopped:
        judge_stop(result, stopped)
    result.at_bound = at_bound(result.x, lower, upper)
    return stopped


def batch_kalman(
    evaluate,
    y_exp,
    C_exp,
    x0,
    C0,
    *,
    max_iterations: int = 20,
    tol: float = 0.01,
    sensitivity=None,
    executor=None,
    bounds=None,
) -> KalmanResult:
    """Batch variant: all observations at once, iterated (iterated extended Kalman filter).

    x_{k+1} = x0 + K_k (y_exp - h(x_k) - S_k (x0 - x_k)),  K_k = C0 S_k^T (S_k C0 S_k^T + C_exp)^-1,
    which is Gauss-Newton on the Bayesian objective: the step-by-step filter with a single group of
    all observations and re-linearised global iterations.
    Bounded and failure tolerant as :func:`kalman_filter`.
    """
    n = np.asarray(y_exp).size
    return kalman_filter(evaluate, y_exp, C_exp, x0, C0, groups=[np.arange(n)], max_iterations=max_iterations,
                         tol=tol, restart="linearize", sensitivity=sensitivity, executor=executor, bounds=bounds)
