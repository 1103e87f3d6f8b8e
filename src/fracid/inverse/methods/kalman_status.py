"""The result of a Kalman-filter identification and its status: what a user can act on.

Convergence is judged on what matters, the change of the objective between passes and the step in
standard deviations of the posterior covariance C; a step along a flat valley of correlated
parameters is named as such; an estimate alternating between passes is detected (and damped by
:func:`~fracid.inverse.methods.kalman.kalman_filter`); a filter that ends at a poor point is restarted from
the next-best points of the KNN population (:func:`restarted`). The criteria are the module constants.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from fracid.inverse.core.estimate import GaussianEstimate
from fracid.inverse.core.fit_status import (FAILED, NOT_CONVERGED, STABLE, STABLE_STEP, VALLEY, measurement_part,
                                            stable_step)

#: Converged: the last pass moved every parameter by less than this many standard deviations (of C) ...
CONVERGED_STEP = 0.1
#: ... and changed the objective by less than this fraction of it ...
CONVERGED_OBJECTIVE_RELATIVE = 0.01
#: ... or by less than this many chi-square units.
CONVERGED_OBJECTIVE_ABSOLUTE = 1.0
#: A flat valley: parameters correlated beyond this |r| (or a principal direction of C wider than the
#: next by :data:`VALLEY_WIDTH_RATIO`), the objective flat and the step across the valley below
#: :data:`CONVERGED_STEP`: "converged along a valley".
VALLEY_CORRELATION = 0.95
#: Std along the widest principal direction of C over the std along the next one: "much wider".
VALLEY_WIDTH_RATIO = 10.0
#: Two successive steps (in std units) whose cosine is below this alternate: an oscillation, when the
#: second is at least :data:`OSCILLATION_RATIO` times as long as the first (a fast-shrinking alternation
#: converges by itself).
OSCILLATION_COSINE = -0.5
OSCILLATION_RATIO = 0.5
#: Under-relaxation factor of a step after each detected oscillation (halving), and its floor.
DAMPING = 0.5
MIN_RELAXATION = 0.125
#: A poor point: chi-square per data point above this (the data noise gives about 1) ...
POOR_CHI2_PER_POINT = 10.0
#: Starts of the filter at most (the KNN prior, then the next-best population points) when it ends
#: at a poor point.
DEFAULT_MAX_STARTS = 3


@dataclass
class KalmanResult(GaussianEstimate):
    """Estimates of a Kalman-filter identification.

    Attributes
    ----------
    x, C : ndarray
        Final estimate and covariance.
    history : list of dict
        Per global iteration and step: ``{"iteration", "step", "observations", "x", "C"}``.
    iterations : int
        Global iterations done; ``converged`` says whether the estimate stopped changing (by the criteria
        of :mod:`fracid.inverse.methods.kalman_status`, a flat valley included).
    y : ndarray
        Computed observations at the final estimate (NaN where the run at it failed).
    runs : int
        Forward runs asked for; ``run_equivalents`` weights each by the share of the curve it computed.
    status : str
        ``"converged"`` (or ``"converged: ..."`` with the last pass's step and objective change),
        ``"converged along a valley (...)"``, ``"stopped but stable: ..."`` (iterations reached, or a failed
        run or no decrease of the objective stopped it, with the last passes moving less than half a std),
        ``"not converged: ..."`` (the same, still moving or oscillating) or ``"failed: ..."`` (no run
        succeeded at the estimate): the words of :mod:`fracid.inverse.core.fit_status`.
    failures : list of dict
        Failed forward runs at points the filter wanted: ``{"iteration", "step", "x", "error"}``.
    at_bound : ndarray of bool
        Parameters whose estimate lies on a bound of the box (see :func:`~fracid.inverse.methods.kalman.kalman_filter`, Notes).
    passes : list of dict
        Per global iteration: ``{"iteration", "x"}``, the estimate it ended with (after damping), and
        ``"objective"`` where a run gave it; the first entry (iteration 0) is the start.
    relaxation : float
        Under-relaxation of the steps at the end (1: none; see :func:`relaxed`).
    oscillations : int
        Passes whose estimate alternated with the one before and were damped.
    starts : list of dict
        Starts of the filter (:func:`~fracid.inverse.methods.kalman_status.restarted`); empty for a single filter.
    """

    x: np.ndarray
    C: np.ndarray
    history: list = field(default_factory=list)
    iterations: int = 0
    converged: bool = False
    y: np.ndarray | None = None
    runs: int = 0
    run_equivalents: float = 0.0
    status: str = ""
    failures: list = field(default_factory=list)
    at_bound: np.ndarray | None = None
    passes: list = field(default_factory=list)
    relaxation: float = 1.0
    oscillations: int = 0
    starts: list = field(default_factory=list)

    @property
    def passes_x(self) -> list:
        """The start and the estimate at the end of every pass."""
        return [p["x"] for p in self.passes]

    @property
    def failed(self) -> bool:
        """No forward run succeeded at the final estimate (its y is not finite)."""
        return self.y is None or not np.all(np.isfinite(self.y))


@dataclass
class PassChange:
    """What the last pass changed: the largest step of a parameter in std, the step across the widest
    direction of C (its largest component in the other principal directions, each in its own std), and
    the objective before and after."""

    moved: float
    across: float
    objective_before: float
    objective_after: float

    @property
    def objective_change(self) -> float:
        return abs(self.objective_after - self.objective_before)

    @property
    def flat(self) -> bool:
        """The objective changed by < 1 % or < 1 chi-square unit (:data:`CONVERGED_OBJECTIVE_RELATIVE`, ...)."""
        limit = max(CONVERGED_OBJECTIVE_ABSOLUTE, CONVERGED_OBJECTIVE_RELATIVE * abs(self.objective_before))
        return bool(np.isfinite(self.objective_change) and self.objective_change < limit)

    def text(self) -> str:
        return (f"the last pass moved the estimate by {self.moved:.3g} std and changed the objective by "
                f"{self.objective_change:.3g} (from {self.objective_before:.4g})")


def pass_change(x_before, x_after, C, f_before, f_after) -> PassChange:
    """:class:`PassChange` of a pass from ``x_before`` (objective ``f_before``) to ``x_after`` (C: its covariance)."""
    step = np.asarray(x_after, float) - np.asarray(x_before, float)
    std = np.sqrt(np.diag(C))
    w, V = np.linalg.eigh(C)
    z = np.abs(V.T @ step) / np.sqrt(np.maximum(w, np.finfo(float).tiny))
    across = float(np.max(z[:-1])) if z.size > 1 else float(z[0])
    return PassChange(float(np.max(np.abs(step) / std)), across, float(f_before), float(f_after))


def valley_text(C, names):
    """The valley of C in words, or None: the most correlated pair when ``|r|`` is above
    :data:`VALLEY_CORRELATION`, else the parameter that dominates a principal direction
    :data:`VALLEY_WIDTH_RATIO` times wider (in std) than the next one."""
    p = C.shape[0]
    if p < 2:
        return None
    std = np.sqrt(np.diag(C))
    r = C / np.outer(std, std) - np.eye(p)  # the diagonal (r = 1) out of the running
    i, j = sorted(divmod(int(np.argmax(np.abs(r))), p))
    if abs(r[i, j]) > VALLEY_CORRELATION:
        return f"parameters {names[i]} and {names[j]} correlated, r = {r[i, j]:.3g}"
    w, V = np.linalg.eigh(C)
    ratio = np.sqrt(w[-1] / max(w[-2], np.finfo(float).tiny))
    if ratio > VALLEY_WIDTH_RATIO:
        k = int(np.argmax(np.abs(V[:, -1]) * std))
        return f"the objective is flat along {names[k]}: C is {ratio:.3g} times wider in that direction"
    return None


def oscillates(points, C) -> bool:
    """The last two steps between ``points`` (estimates of successive passes) go back and forth: their
    cosine in std units is below :data:`OSCILLATION_COSINE`, the last is not negligible (a parameter moves by
    :data:`CONVERGED_STEP` or more) and not much shorter than the one before (:data:`OSCILLATION_RATIO`)."""
    if len(points) < 3:
        return False
    std = np.sqrt(np.diag(C))
    d1, d2 = (np.asarray(points[-2]) - points[-3]) / std, (np.asarray(points[-1]) - points[-2]) / std
    n1, n2 = np.linalg.norm(d1), np.linalg.norm(d2)
    if n1 == 0 or n2 < OSCILLATION_RATIO * n1 or np.max(np.abs(d2)) < CONVERGED_STEP:
        return False
    return bool(d1 @ d2 / (n1 * n2) < OSCILLATION_COSINE)


def first_steps(history) -> list:
    """The estimate after the first step of every pass."""
    return [h["x"] for h in history if h["step"] == 1]


def judge(result, change: PassChange | None, strict: bool, max_iterations: int, names):
    """Set ``result.converged`` and ``result.status`` of a filter that was not stopped.

    ``strict``: the filter's own criterion (no parameter moved by more than ``tol`` std) was met.
    ``change``: the last pass (None after a single pass with nothing to compare).
    """
    n = result.oscillations
    damped = f" (an oscillation between passes was damped: {n} step(s) under-relaxed)" if n else ""
    if strict or (change is not None and change.moved < CONVERGED_STEP and change.flat):
        result.converged = True
        result.status = ("converged" if strict else f"converged: {change.text()}") + damped
        return
    valley = valley_text(result.C, names) if change is not None else None
    if valley is not None and change.flat and change.across < CONVERGED_STEP:
        result.converged = True
        result.status = f"{VALLEY} ({valley}: `fracid study` maps the valley)"
        return
    result.converged = False
    reason = f"{max_iterations} global iterations reached"
    swinging = oscillates(result.passes_x, result.C)
    if swinging:
        reason = "the estimate oscillates between passes"
    elif oscillates(first_steps(result.history), result.C):
        reason = f"{reason}; the estimate oscillates at the first step of every pass"
    reason += damped
    detail = change.text() if change is not None else "a single pass"
    stable = change is not None and change.moved < STABLE_STEP and not swinging
    result.status = f"{STABLE if stable else NOT_CONVERGED}: {reason}, {detail}"


def relaxed(result, x, previous, C):
    """x, under-relaxed towards ``previous`` once the estimates of the passes alternate: the factor
    ``result.relaxation`` is multiplied by :data:`DAMPING` at each detection, down to :data:`MIN_RELAXATION`,
    and divided by it again (up to 1) after a pass that does not alternate (Gauss-Newton's speed back)."""
    if oscillates([*result.passes_x, x], C):
        result.relaxation = max(MIN_RELAXATION, result.relaxation * DAMPING)
        result.oscillations += 1
    else:
        result.relaxation = min(1.0, result.relaxation / DAMPING)
    return previous + result.relaxation * (x - previous) if result.relaxation < 1 else x


def judge_last_pass(result, objective_at, objective, last, max_iterations, names):
    """:func:`judge` a filter that was not stopped, from its last pass ``last`` = (start, undamped end,
    objective at the start or None), the objective at the final estimate (``objective(x, y)``) and C;
    ``objective_at(x)`` runs the model where the objective at the start is not known."""
    names = list(names) if names is not None else [f"x{i + 1}" for i in range(result.x.size)]
    change = None
    if last is not None and result.iterations > 0:
        start, end, f_start = last
        f_start = objective_at(start) if f_start is None else f_start
        f_end = objective(result.x, result.y) if not result.failed else np.inf
        result.passes[-1]["objective"] = f_end
        change = pass_change(start, end, result.C, f_start, f_end)
    judge(result, change, result.converged, max_iterations, names)


def judge_stop(result, stopped: str) -> None:
    """The status of a filter that ``stopped`` (a failed run, or no decrease of the objective along the step):
    ``"failed: ..."`` when no run succeeded at its estimate; else ``"stopped but stable: ..."`` when the final
    estimate is within :data:`~fracid.inverse.core.fit_status.STABLE_STEP` std of the last passes' estimates
    (the step it could not take stays inside the reported uncertainty), ``"not converged: ..."`` otherwise."""
    result.converged = False
    if result.failed:
        result.status = f"{FAILED}: stopped, {stopped}"
        return
    moved = stable_step([*result.passes_x[-2:], result.x], result.C) if len(result.passes_x) > 1 else np.inf
    word = STABLE if moved < STABLE_STEP else NOT_CONVERGED
    result.status = f"{word}: stopped {stopped}; the last passes moved the estimate by {moved:.3g} std"


# ------------------------------------------------------------------------------------------ restarts


def chi2_per_point(result, y_exp, C_exp) -> float:
    """(y_exp - y)^T C_exp^-1 (y_exp - y) / n_y at the result's estimate (inf when its run failed)."""
    from fracid.inverse.core.misfit import objective

    if result.failed:
        return float("inf")
    return float(objective(y_exp, C_exp, result.y)[0]) / np.size(y_exp)


def is_poor(result, y_exp, C_exp, best_population: float) -> bool:
    """A poor end: chi^2 per data point above :data:`POOR_CHI2_PER_POINT`, and the filter stopped, did not
    converge, or ended worse than the best population point (chi^2 ``best_population``); or its run failed."""
    chi2 = chi2_per_point(result, y_exp, C_exp)
    if not np.isfinite(chi2):
        return True
    worse = chi2 * np.size(y_exp) > best_population
    return chi2 > POOR_CHI2_PER_POINT and (not result.converged or worse)


def restarted(run, first, knn, y_exp, C_exp, max_starts: int = DEFAULT_MAX_STARTS):
    """The filter ``first`` (from the KNN prior), restarted from the next-best population points while
    it ends at a poor point (:func:`is_poor`), up to ``max_starts`` starts in all; the best end wins.

    Both are judged on the measurement-only misfit (:func:`~fracid.inverse.core.fit_status.measurement_part`
    of ``C_exp``): a model-error term in ``C_exp`` widens it where the fit is poor and would hide the poor end.

    Parameters
    ----------
    run : callable(x0) -> KalmanResult
        The filter from the prior mean x0 (same covariance and settings).
    first : KalmanResult
        The filter from the KNN prior.
    knn : KnnResult
        Its ranking gives the next starts (:meth:`~fracid.inverse.methods.knn.KnnResult.next_starts`).

    Returns
    -------
    KalmanResult
        The winner (lowest chi^2 at its estimate), with the forward runs and failures of every start
        added, ``starts`` (one dict per start: ``{"start", "x0", "x", "chi2_per_point", "status"}``) and
        the status saying how many starts were tried and which won.
    """
    C_exp = measurement_part(C_exp)  # a poor end is judged on the data's scatter alone, not on error terms
    best = best_population(knn, y_exp, C_exp)
    tried = [("the KNN prior", knn.x0, first)]
    if max_starts > 1 and is_poor(first, y_exp, C_exp, best):
        for index in knn.next_starts(max_starts - 1, avoid=[knn.x0]):
            rank = int(np.flatnonzero(knn.order == index)[0]) + 1
            result = run(knn.points[index])
            tried.append((f"population point ranked {rank}", knn.points[index], result))
            if not is_poor(result, y_exp, C_exp, best):
                break
    chi2 = [chi2_per_point(r, y_exp, C_exp) for _, _, r in tried]
    win = int(np.argmin(chi2)) if np.any(np.isfinite(chi2)) else 0
    winner = tried[win][2]
    winner.starts = [{"start": label, "x0": np.asarray(x0, float).tolist(), "x": r.x.tolist(),
                      "chi2_per_point": c, "status": r.status} for (label, x0, r), c in zip(tried, chi2)]
    if len(tried) > 1:
        _merge_runs(winner, [r for _, _, r in tried])
        winner.status = (f"{winner.status}; {len(tried)} starts tried after a poor end from the KNN prior "
                         f"(chi^2 per point {chi2[0]:.3g}), the start from {tried[win][0]} won "
                         f"(chi^2 per point {chi2[win]:.3g})")
    return winner


def best_population(knn, y_exp, C_exp) -> float:
    """The lowest chi^2 of the population under ``C_exp`` (from its computed values; its own objective ``f``
    when it did not keep them)."""
    from fracid.inverse.core.misfit import objective

    Y = getattr(knn, "Y", None)
    if Y is not None and np.size(Y):
        return float(np.min(objective(y_exp, C_exp, Y)))
    return float(knn.f[knn.order[0]]) if np.size(knn.f) else np.inf


def _merge_runs(winner, results):
    """The winner counts the forward runs and failures of every start."""
    others = [r for r in results if r is not winner]
    winner.runs += sum(r.runs for r in others)
    winner.run_equivalents += sum(r.run_equivalents for r in others)
    winner.failures = [f for r in others for f in r.failures] + winner.failures
