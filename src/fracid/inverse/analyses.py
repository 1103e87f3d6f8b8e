"""Analyses of identifiability (SPEC section 4, "Analyses"): what each part of the data tells.

``sensitivity_history``: normalised sensitivities of the response to every parameter along the load
history, the information accumulated up to each step and, per parameter, the share of its prior
variance that the data up to that step remove (which stage of the fracture process fixes which
parameter).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from fracid.inverse.sensitivity import CentralDifferences


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
        d y_t / d x_j * x_j / max |y| of the block of y_t: the response change for a 100 % change
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


def sensitivity_history(evaluate, x, C_exp, C0, *, names=None, blocks=None, sensitivity=CentralDifferences(),
                        executor=None) -> SensitivityHistory:
    """Sensitivity of the response along the load history, and what the data up to each step identify.

    Parameters
    ----------
    evaluate : callable(x, needed) -> RunRecord or ndarray
        The forward operator.
    x : array_like, shape (p,)
        Parameter values (e.g. an estimate or a nominal set).
    C_exp : ndarray, shape (n, n)
        Covariance of the measurements.
    C0 : ndarray, shape (p, p)
        Prior covariance (e.g. from the bounds or from KNN): the reference the shares are taken from.
    names : sequence of str, optional
    blocks : sequence of (name, start, stop), optional
        Data blocks; each is normalised by its own largest |y| (global and local data differ in units).
    """
    x = np.asarray(x, dtype=float)
    C_exp, C0 = np.atleast_2d(np.asarray(C_exp, float)), np.atleast_2d(np.asarray(C0, float))
    y, S, _ = sensitivity(evaluate, x, None, executor)
    n, p = S.shape
    if C_exp.shape != (n, n) or C0.shape != (p, p):
        raise ValueError(f"C_exp must be {(n, n)} and C0 {(p, p)}; got {C_exp.shape} and {C0.shape}")
    scale = np.empty(n)
    for _, start, stop in blocks or [("all", 0, n)]:
        scale[start:stop] = np.max(np.abs(y[start:stop]))
    normalised = S * x[None, :] / scale[:, None]
    information = np.empty((n, p, p))
    variance_share = np.empty((n, p))
    prior_precision = np.linalg.inv(C0)
    for t in range(n):
        St = S[: t + 1]
        information[t] = St.T @ np.linalg.solve(C_exp[: t + 1, : t + 1], St)
        posterior = np.linalg.inv(prior_precision + information[t])
        variance_share[t] = 1.0 - np.diag(posterior) / np.diag(C0)
    return SensitivityHistory(list(names) if names is not None else [f"x{j}" for j in range(p)], x, y, S,
                              normalised, information, variance_share)
