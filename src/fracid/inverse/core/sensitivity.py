"""Sensitivities of the forward operator, behind one small interface.

A sensitivity method is a callable ``(evaluate, x, needed, executor) -> (y, S, records)``: the outputs
at x, the matrix S = d y / d x (n_outputs x n_parameters) and the runs it made. The Kalman filter only
sees this interface. :class:`DirectDifferentiation` reads S from the run itself (computed inside the
finite-element analysis, :mod:`fracid.fem.path.ddm`): one run instead of the 2 p + 1 of
:class:`CentralDifferences`, which stay the fallback for a model without it.
:func:`exact_sensitivity` picks the method for an operator.

:func:`sensitivity_history` (docs/theory.md, section 4.5): normalised sensitivities of the response to
every parameter along the load history, the information accumulated up to each step and, per
parameter, the share of its prior variance that the data up to that step remove (which stage of the
fracture process fixes which parameter).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from fracid.data.covariance_matrix import Block, Dense, Diagonal, as_covariance
from fracid.data.covariance_low_rank import LowRankPlusDiagonal
from fracid.inverse.core.forward_operator import RunRecord


class ForwardRunError(RuntimeError):
    """A forward run the method cannot do without (its own point) failed."""


def evaluate_points(evaluate, points, needed=None, executor=None) -> list[RunRecord]:
    """Evaluate ``evaluate(x, needed)`` at every point, in parallel when an executor is given.

    Plain arrays returned by ``evaluate`` (analytic test models) are wrapped in a :class:`RunRecord`.
    An ``evaluate`` with an ``evaluate_many(points, needed, executor)`` method (a run store or a
    memory of runs, see :class:`Memoized` and :class:`fracid.inverse.core.runs.StoredOperator`) is
    asked through it, so that runs already made are not made again.
    """
    if hasattr(evaluate, "evaluate_many"):
        return evaluate.evaluate_many(points, needed, executor)
    if executor is None:
        outputs = [evaluate(np.asarray(x, float), needed) for x in points]
    else:
        futures = [executor.submit(evaluate, np.asarray(x, float), needed) for x in points]
        outputs = [f.result() for f in futures]
    return [out if isinstance(out, RunRecord) else RunRecord(np.asarray(x, float), np.asarray(out, float))
            for x, out in zip(points, outputs)]


class Memoized:
    """``evaluate`` that remembers its runs in this process: a point asked again is not run again.

    The Kalman filter asks for the run at its own point before the perturbed ones (to see whether
    it succeeds and lowers the objective), then the sensitivity method asks for it again.
    """

    def __init__(self, evaluate):
        self.evaluate = evaluate
        self.memory: dict = {}

    def __call__(self, x, needed=None):
        return self.evaluate_many([x], needed, None)[0]

    def evaluate_many(self, points, needed=None, executor=None) -> list[RunRecord]:
        keys = [(np.asarray(x, float).tobytes(), needed) for x in points]
        missing = {key: x for key, x in zip(keys, points) if key not in self.memory}
        fresh = evaluate_points(self.evaluate, list(missing.values()), needed, executor)
        self.memory.update(zip(missing, fresh))
        return [self.memory[key] for key in keys]


def memoized(evaluate):
    """``evaluate`` itself if it already avoids repeated runs (has ``evaluate_many``), else :class:`Memoized`."""
    return evaluate if hasattr(evaluate, "evaluate_many") else Memoized(evaluate)


@dataclass(frozen=True)
class CentralDifferences:
    """S_j = (h(x + dx_j) - h(x - dx_j)) / (2 dx_j), dx_j = relative_step * max(``|x_j|``, floor_j).

    The 2 p + 1 runs go to the executor together. A failed perturbed run falls back to the
    one-sided difference with the other side; a failed central run raises :class:`ForwardRunError`.
    """

    relative_step: float = 1e-2

    def __call__(self, evaluate, x, needed=None, executor=None):
        x = np.asarray(x, dtype=float)
        p = x.size
        dx = self.relative_step * np.where(np.abs(x) > 0, np.abs(x), 1.0)
        points = [x] + [x + s * dx[j] * np.eye(p)[j] for j in range(p) for s in (1.0, -1.0)]
        records = evaluate_points(evaluate, points, needed, executor)
        centre = records[0]
        if not centre.ok:
            raise ForwardRunError(f"the forward run at x = {x.tolist()} failed: {centre.error}")
        S = np.empty((centre.y.size, p))
        for j in range(p):
            plus, minus = records[1 + 2 * j], records[2 + 2 * j]
            if plus.ok and minus.ok:
                S[:, j] = (plus.y - minus.y) / (2 * dx[j])
            elif plus.ok or minus.ok:
                side, sign = (plus, 1.0) if plus.ok else (minus, -1.0)
                S[:, j] = sign * (side.y - centre.y) / dx[j]
            else:
                raise ForwardRunError(f"both perturbed runs of parameter {j} failed at x = {x.tolist()}: {plus.error}")
        return centre.y, S, records


@dataclass(frozen=True)
class DirectDifferentiation:
    """S from the forward run at x (``RunRecord.S``, by direct differentiation inside the analysis).

    ``evaluate`` must return records with S (an operator from :func:`exact_sensitivity`); a record
    without S (a model or an observed quantity without derivatives) falls back to ``fallback``.
    A failed run raises :class:`ForwardRunError`.
    """

    fallback: object = CentralDifferences()

    def __call__(self, evaluate, x, needed=None, executor=None):
        x = np.asarray(x, dtype=float)
        record = evaluate_points(evaluate, [x], needed, executor)[0]
        if not record.ok:
            raise ForwardRunError(f"the forward run at x = {x.tolist()} failed: {record.error}")
        if record.S is None:
            return self.fallback(evaluate, x, needed, executor)
        return record.y, record.S, [record]


def exact_sensitivity(evaluate):
    """``(evaluate, sensitivity)`` for a method that needs S: the operator's differentiated version
    (its runs return S, see :meth:`~fracid.inverse.core.forward_operator.ForwardOperator.differentiated`)
    with :class:`DirectDifferentiation` where the model has direct differentiation, else ``evaluate``
    itself with :class:`CentralDifferences`."""
    make = getattr(evaluate, "differentiated", None)
    exact = make() if callable(make) else evaluate
    if getattr(exact, "sensitivities", False):
        return exact, DirectDifferentiation()
    return evaluate, CentralDifferences()


def sensitivity_label(sensitivity) -> str:
    """How a sensitivity method computes S, in words (for notes and reports)."""
    if isinstance(sensitivity, DirectDifferentiation):
        return "direct differentiation inside the analysis"
    if isinstance(sensitivity, CentralDifferences):
        return f"central differences (relative step {sensitivity.relative_step:g})"
    return getattr(sensitivity, "__name__", type(sensitivity).__name__)


@dataclass
class SensitivityHistory:
    """Sensitivities and information along the observation sequence.

    Attributes
    ----------
    names : list of str
    x : ndarray, shape (p,)
        Where the sensitivities are taken.
    y : ndarray, shape (n,)
        Response at x.
    S : ndarray, shape (n, p)
        d y / d x.
    normalised : ndarray, shape (n, p)
        d y_t / d x_j * x_j / max ``|y|`` of the block of y_t: the response change for a 100 % change
        of x_j, relative to the block's largest value.
    information : ndarray, shape (n, p, p)
        Fisher information of the observations 1..t: S_1:t^T C_1:t^-1 S_1:t.
    variance_share : ndarray, shape (n, p)
        1 - var_t(x_j) / var_0(x_j), with the posterior covariance (C0^-1 + information_t)^-1 of the
        linearised problem: the share of the prior variance of x_j removed by observations 1..t.
    """

    names: list
    x: np.ndarray
    y: np.ndarray
    S: np.ndarray
    normalised: np.ndarray
    information: np.ndarray
    variance_share: np.ndarray


#: largest block of another covariance whose information is solved entry by entry (beyond: whitened)
PREFIX_SOLVE_LIMIT = 200


def _prefix_whitening(C_exp) -> bool:
    """Whether ``C_exp.whiten`` is L^-1 with L its lower Cholesky factor, so that the first t whitened rows
    depend on the first t observations only (Diagonal, Dense and blocks of them)."""
    if isinstance(C_exp, Block):
        return all(_prefix_whitening(block) for block in C_exp.blocks)
    return isinstance(C_exp, (Diagonal, Dense))


def cumulative_information(S, C_exp) -> np.ndarray:
    """Fisher information of the observations 1..t for every t: S_1:t^T C_1:t^-1 S_1:t, shape (n, p, p).

    With a Cholesky whitening W = L^-1 S (C = L L^T, L lower triangular, so that C_1:t = L_1:t L_1:t^T)
    it is the running sum of w_t w_t^T: O(n p^2), no n x n matrix; a low-rank-plus-diagonal one by running
    Woodbury sums; another covariance of at most :data:`PREFIX_SOLVE_LIMIT` entries solves every leading
    block, a larger one (a DIC frame: sparse, with its rigid motion) sums its whitened rows: exact at the
    block's end, within the block in its whitening's order (the entries of one frame share a control value).

    Parameters
    ----------
    S : ndarray, shape (n, p)
        Sensitivities [units of y per unit of each parameter].
    C_exp : Covariance
        Covariance of the n observations [units of y squared].
    """
    S = np.asarray(S, float)
    if _prefix_whitening(C_exp):
        W = C_exp.whiten(S)
        return np.cumsum(W[:, :, None] * W[:, None, :], axis=0)
    if isinstance(C_exp, Block):  # blocks are independent: each adds its own prefixes to the blocks before
        parts, total = [], np.zeros((S.shape[1], S.shape[1]))
        for block, start, stop in zip(C_exp.blocks, C_exp.offsets[:-1], C_exp.offsets[1:]):
            parts.append(total + cumulative_information(S[start:stop], block))
            total = parts[-1][-1]
        return np.concatenate(parts)
    if isinstance(C_exp, LowRankPlusDiagonal):
        return _low_rank_prefix_information(S, C_exp)
    if C_exp.n > PREFIX_SOLVE_LIMIT:  # e.g. a DIC frame (sparse, plus its rigid motion): one solve per entry is
        W = C_exp.whiten(S)           # out of reach; exact at the block's end, its own elimination order within
        return np.cumsum(W[:, :, None] * W[:, None, :], axis=0)
    return np.array([S[: t + 1].T @ C_exp.take(slice(0, t + 1)).solve(S[: t + 1]) for t in range(S.shape[0])])


def _low_rank_prefix_information(S, C_exp) -> np.ndarray:
    """:func:`cumulative_information` of C = D + U U^T by Woodbury on running sums: with A_t = sum s_i s_i^T / d_i,
    B_t = sum u_i s_i^T / d_i and K_t = I + sum u_i u_i^T / d_i over the first t entries, the information is
    A_t - B_t^T K_t^-1 B_t: O(n k^3), exact, no leading block rebuilt."""
    d, U = C_exp.D.var, C_exp.U
    A = np.cumsum(S[:, :, None] * (S / d[:, None])[:, None, :], axis=0)
    B, K = np.zeros((U.shape[1], S.shape[1])), np.eye(U.shape[1])
    out = np.empty_like(A)
    for t in range(S.shape[0]):
        B += np.outer(U[t], S[t]) / d[t]
        K += np.outer(U[t], U[t]) / d[t]
        out[t] = A[t] - B.T @ np.linalg.solve(K, B)
    return out


def sensitivity_history(evaluate, x, C_exp, C0, *, names=None, blocks=None, sensitivity=None,
                        executor=None) -> SensitivityHistory:
    """Sensitivity of the response along the load history, and what the data up to each step identify.

    Parameters
    ----------
    evaluate : callable(x, needed) -> RunRecord or ndarray
        The forward operator.
    x : array_like, shape (p,)
        Parameter values (e.g. an estimate or a nominal set).
    C_exp : ndarray, shape (n, n), or Covariance
        Covariance of the measurements [units of y squared] (a diagonal one forms no n x n matrix).
    C0 : ndarray, shape (p, p)
        Prior covariance (e.g. from the bounds or from KNN): the reference the shares are taken from.
    names : sequence of str, optional
    blocks : sequence of (name, start, stop), optional
        Data blocks; each is normalised by its own largest ``|y|`` (global and local data differ in units).
    sensitivity : callable, optional
        The sensitivity method; by default :func:`exact_sensitivity`'s choice.
    """
    if sensitivity is None:
        evaluate, sensitivity = exact_sensitivity(evaluate)
    x = np.asarray(x, dtype=float)
    C_exp = as_covariance(C_exp if np.ndim(C_exp) != 0 else np.atleast_2d(C_exp), name="C_exp")
    C0 = np.atleast_2d(np.asarray(C0, float))
    y, S, _ = sensitivity(evaluate, x, None, executor)
    n, p = S.shape
    if C_exp.shape != (n, n) or C0.shape != (p, p):
        raise ValueError(f"C_exp must be {(n, n)} and C0 {(p, p)}; got {C_exp.shape} and {C0.shape}")
    scale = np.empty(n)
    for _, start, stop in blocks or [("all", 0, n)]:
        scale[start:stop] = np.max(np.abs(y[start:stop]))
    normalised = S * x[None, :] / scale[:, None]
    information = cumulative_information(S, C_exp)
    posterior = np.linalg.inv(np.linalg.inv(C0)[None, :, :] + information)
    variance_share = 1.0 - np.diagonal(posterior, axis1=1, axis2=2) / np.diag(C0)[None, :]
    return SensitivityHistory(list(names) if names is not None else [f"x{j}" for j in range(p)], x, y, S,
                              normalised, information, variance_share)
