"""Kalman filter for parameter identification (SPEC section 4): step by step, and the batch variant."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from fracid.inverse.sensitivity import CentralDifferences, evaluate_points


def kalman_update(x, C, S, innovation, R):
    """One Kalman update in Joseph form.

    Parameters
    ----------
    x : ndarray, shape (p,)
        Prior mean.
    C : ndarray, shape (p, p)
        Prior covariance.
    S : ndarray, shape (m, p)
        Sensitivity of the m observations to x.
    innovation : ndarray, shape (m,)
        Measured minus computed observations.
    R : ndarray, shape (m, m)
        Covariance of the measurement errors.

    Returns
    -------
    x_new, C_new, K : ndarray
        Posterior mean and covariance, and the gain. The Joseph form
        (I - K S) C (I - K S)^T + K R K^T keeps C symmetric positive definite under round-off.
    """
    A = S @ C @ S.T + R
    K = np.linalg.solve(A, S @ C).T  # C S^T A^-1 (A symmetric)
    I_KS = np.eye(x.size) - K @ S
    C_new = I_KS @ C @ I_KS.T + K @ R @ K.T
    return x + K @ innovation, 0.5 * (C_new + C_new.T), K


class GaussianEstimate:
    """Mixin of the results that hold an estimate's covariance ``C``: its standard deviations and
    correlation matrix."""

    @property
    def std(self) -> np.ndarray:
        return np.sqrt(np.diag(self.C))

    @property
    def correlation(self) -> np.ndarray:
        return self.C / np.outer(self.std, self.std)


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
        Global iterations done; ``converged`` says whether the estimate stopped changing.
    y : ndarray
        Computed observations at the final estimate.
    runs : int
        Forward runs made; ``run_equivalents`` weights each by the share of the curve it computed.
    """

    x: np.ndarray
    C: np.ndarray
    history: list = field(default_factory=list)
    iterations: int = 0
    converged: bool = False
    y: np.ndarray | None = None
    runs: int = 0
    run_equivalents: float = 0.0


def _observation_groups(n, groups):
    if groups is None:
        return [np.array([i]) for i in range(n)]
    groups = [np.atleast_1d(np.asarray(g, dtype=int)) for g in groups]
    flat = np.concatenate(groups)
    if not np.array_equal(np.sort(flat), np.arange(n)) or np.any(np.diff([g.max() for g in groups]) <= 0):
        raise ValueError("observation groups must cover every observation once, in increasing order")
    return groups


def _check_inputs(y_exp, C_exp, x0, C0):
    y_exp, x0 = np.asarray(y_exp, float), np.asarray(x0, float)
    C_exp, C0 = np.atleast_2d(np.asarray(C_exp, float)), np.atleast_2d(np.asarray(C0, float))
    if C_exp.shape != (y_exp.size, y_exp.size):
        raise ValueError(f"C_exp has shape {C_exp.shape}; expected {(y_exp.size, y_exp.size)}")
    if C0.shape != (x0.size, x0.size):
        raise ValueError(f"C0 has shape {C0.shape}; expected {(x0.size, x0.size)}")
    for name, M in (("C_exp", C_exp), ("C0", C0)):
        if not np.allclose(M, M.T) or np.any(np.linalg.eigvalsh(0.5 * (M + M.T)) <= 0):
            raise ValueError(f"{name} must be symmetric positive definite")
    return y_exp, C_exp, x0, C0


def _clip(x, bounds):
    return x if bounds is None else np.clip(x, bounds[0], bounds[1])


def _converged(x_new, x_old, C, tol):
    return bool(np.all(np.abs(x_new - x_old) <= tol * np.sqrt(np.diag(C))))


def kalman_filter(
    evaluate,
    y_exp,
    C_exp,
    x0,
    C0,
    *,
    groups=None,
    max_iterations: int = 10,
    tol: float = 0.01,
    restart: str = "linearize",
    sensitivity=CentralDifferences(),
    executor=None,
    bounds=None,
    callback=None,
) -> KalmanResult:
    """Step-by-step Kalman filter with global iterations (SPEC section 4).

    For t = 1..n the observations of group t are assimilated with :func:`kalman_update`, using
    S_t = d h_t / d x and h_t at a linearisation point (forward runs only up to the last
    observation of the group). h is nonlinear, so the sequence is repeated (global iterations) until
    no parameter moves by more than ``tol`` standard deviations. Two ways to repeat it:

    ``restart="linearize"`` (default)
        Every pass starts again from the prior (x0, C0) and linearises h about the previous pass's
        estimate: y_t - h_t(x_lin) - S_t (x_{t-1} - x_lin) is the innovation. The fixed point is the
        Bayesian maximum a posteriori estimate; for a linear h every pass gives the closed-form
        posterior, and its sensitivities come from one set of full runs per pass.
    ``restart="prior-mean"``
        The thesis's wording: the last estimate becomes the new prior mean (prior covariance C0),
        linearising at the running estimate. It re-uses the data in every pass, so the covariance
        is optimistic and the estimate drifts towards the least-squares fit.

    Parameters
    ----------
    evaluate : callable(x, needed) -> RunRecord or ndarray
        The forward operator (e.g. :class:`~fracid.inverse.forward_operator.ForwardOperator`).
    y_exp, C_exp : ndarray
        Measured observations and their covariance. Sequential assimilation assumes no correlation
        between groups (a block-diagonal C_exp); within a group any covariance is used.
    x0, C0 : ndarray
        Prior mean and covariance (from KNN or the user).
    groups : sequence of index arrays, optional
        The observation sequence; one observation per step by default.
    sensitivity : callable
        See :mod:`fracid.inverse.sensitivity`.
    executor : Executor, optional
        Runs the 2 p + 1 runs of each sensitivity in parallel.
    bounds : (lower, upper) arrays, optional
        Estimates are clipped to these (the parameters' valid ranges).
    callback : callable(iteration, step, x, C), optional

    Raises
    ------
    ForwardRunError
        When the forward run at the filter's own point fails.
    """
    if restart not in ("linearize", "prior-mean"):
        raise ValueError(f"restart = {restart!r}; choose 'linearize' or 'prior-mean'")
    y_exp, C_exp, x0, C0 = _check_inputs(y_exp, C_exp, x0, C0)
    groups = _observation_groups(y_exp.size, groups)
    result = KalmanResult(x=x0.copy(), C=C0.copy())
    previous = x0.copy()
    for iteration in range(1, max_iterations + 1):
        fixed_point = restart == "linearize" and iteration > 1
        x, C = (x0.copy() if restart == "linearize" else previous.copy()), C0.copy()
        if fixed_point:  # one linearisation for the whole pass
            y_lin, S_lin, records = sensitivity(evaluate, previous, None, executor)
            result.runs += len(records)
            result.run_equivalents += len(records)
        for step, rows in enumerate(groups, start=1):
            if fixed_point:
                lin, y, S = previous, y_lin, S_lin
            else:
                needed = int(rows.max()) + 1
                lin = x
                y, S, records = sensitivity(evaluate, x, needed, executor)
                result.runs += len(records)
                result.run_equivalents += len(records) * needed / y_exp.size
            innovation = y_exp[rows] - y[rows] - S[rows] @ (x - lin)
            x, C, _ = kalman_update(x, C, S[rows], innovation, C_exp[np.ix_(rows, rows)])
            x = _clip(x, bounds)
            result.history.append({"iteration": iteration, "step": step, "observations": rows.tolist(),
                                   "x": x.copy(), "C": C.copy()})
            if callback is not None:
                callback(iteration, step, x, C)
        result.iterations = iteration
        done = iteration > 1 and _converged(x, previous, C, tol)
        previous, result.x, result.C = x, x, C
        if done:
            result.converged = True
            break
    record = evaluate_points(evaluate, [result.x], None, executor)[0]
    result.y, result.runs, result.run_equivalents = record.y, result.runs + 1, result.run_equivalents + 1
    return result


def batch_kalman(
    evaluate,
    y_exp,
    C_exp,
    x0,
    C0,
    *,
    max_iterations: int = 20,
    tol: float = 0.01,
    sensitivity=CentralDifferences(),
    executor=None,
    bounds=None,
) -> KalmanResult:
    """Batch variant: all observations at once, iterated (iterated extended Kalman filter).

    x_{k+1} = x0 + K_k (y_exp - h(x_k) - S_k (x0 - x_k)),  K_k = C0 S_k^T (S_k C0 S_k^T + C_exp)^-1,
    which is Gauss-Newton on the Bayesian objective: the step-by-step filter with a single group of
    all observations and re-linearised global iterations.
    """
    n = np.asarray(y_exp).size
    return kalman_filter(evaluate, y_exp, C_exp, x0, C0, groups=[np.arange(n)], max_iterations=max_iterations,
                         tol=tol, restart="linearize", sensitivity=sensitivity, executor=executor, bounds=bounds)
