"""The numbers a comparison of models ranks by: the Gaussian log-likelihood at the estimate, AIC and BIC, the
Laplace approximation of the log evidence, and the ranking by log evidence with its ties.

Every model sees the same data y_exp (n values, covariance C_exp) and has its own p parameters x, with the
prior of :func:`fracid.inverse.sampling.posterior.posterior`: uniform between the bounds of its
:class:`~fracid.inverse.core.space.ParameterSpace` (log-uniform for its log parameters), that is uniform on
the space's unit cube.

* log L(x) = -1/2 chi^2(x) - 1/2 log det(2 pi C_exp), chi^2 = (y(x) - y_exp)^T C_exp^-1 (y(x) - y_exp):
  the normalised Gaussian likelihood, the same the sampler's evidence carries;
* AIC = 2 p - 2 log L(x_hat), BIC = p ln n - 2 log L(x_hat) (lower is better);
* Laplace: log Z_L = log L(x_hat) + log prior(x_hat) + p/2 log(2 pi) + 1/2 log det Sigma, with Sigma the
  posterior covariance of x at x_hat under the flat prior, (S^T C_exp^-1 S)^-1 (S = dy/dx, the
  Gauss-Newton Hessian of -log L), and the prior density in the same coordinates x: 1 / (upper - lower)
  for a linear parameter, 1 / (x_hat ln(upper / lower)) for a log one (the Jacobian of x -> ln x). Exact
  for a model linear in x with bounds far from x_hat; an estimate at a bound (half the Gaussian cut
  off) or a curved valley makes it off, which the sampled evidence is not.

Units: chi^2, log-likelihoods and log evidences are dimensionless (natural logarithms); the densities are
per unit of the parameters.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["TIE_SIGMAS", "gaussian_log_likelihood", "information_criteria", "laplace_log_evidence",
           "log_prior_density", "rank_by_evidence"]

#: Two log evidences closer than this many combined Monte-Carlo standard errors are a tie: the sampling
#: cannot tell which is larger (about 95 % two-sided for normal errors)
TIE_SIGMAS = 2.0


def gaussian_log_likelihood(chi2: float, logdet: float, n: int) -> float:
    """log L = -1/2 chi^2 - 1/2 (n log(2 pi) + log det C_exp) [-].

    Parameters
    ----------
    chi2 : float
        (y - y_exp)^T C_exp^-1 (y - y_exp) [-].
    logdet : float
        log det C_exp (C_exp in units of y squared).
    n : int
        Number of data values.
    """
    return -0.5 * (float(chi2) + n * math.log(2.0 * math.pi) + float(logdet))


def information_criteria(log_likelihood: float, p: int, n: int) -> tuple[float, float]:
    """(AIC, BIC) = (2 p - 2 log L, p ln n - 2 log L) of a model of ``p`` parameters on ``n`` data values [-]."""
    return 2.0 * p - 2.0 * log_likelihood, p * math.log(n) - 2.0 * log_likelihood


def log_prior_density(x, space) -> float:
    """log of the prior density at ``x`` (units of the parameters): uniform between the bounds of ``space``,
    log-uniform for its log parameters (density 1 / (x ln(upper / lower))); -inf outside the bounds."""
    x = np.asarray(x, float)
    log = np.array(space.log, dtype=bool)
    if np.any(x < space.lower) or np.any(x > space.upper):
        return -math.inf
    span = np.where(log, np.log(space.upper / np.where(log, space.lower, 1.0)), space.upper - space.lower)
    return float(-np.sum(np.log(np.where(log, x * span, span))))


def laplace_log_evidence(log_likelihood: float, x, S, C_exp, space) -> float:
    """The Laplace approximation of the log evidence at the estimate ``x`` (module docstring).

    Parameters
    ----------
    log_likelihood : float
        log L(x) (:func:`gaussian_log_likelihood`).
    x : array_like, shape (p,)
        The estimate (units of the parameters).
    S : array_like, shape (n, p)
        dy/dx at ``x`` (units of y per unit of each parameter).
    C_exp : Covariance
        The data's covariance (:mod:`fracid.data.covariance_matrix`).
    space : ParameterSpace
        The bounds and log flags of the prior.

    Returns
    -------
    float
        log Z_L [-]; NaN when S^T C_exp^-1 S is singular (a direction the data do not see: the Gaussian has
        no finite width there) or not finite.
    """
    W = C_exp.whiten(np.asarray(S, float))
    sign, logdet_h = np.linalg.slogdet(W.T @ W)
    if sign <= 0 or not np.isfinite(logdet_h):
        return float("nan")
    p = len(np.atleast_1d(x))
    return float(log_likelihood + log_prior_density(x, space) + 0.5 * p * math.log(2.0 * math.pi) - 0.5 * logdet_h)


def rank_by_evidence(log_z, errors) -> tuple[list, list]:
    """The order of the models by log evidence, largest first (NaN last), and per model whether it ties with
    the first: its log evidence within :data:`TIE_SIGMAS` combined Monte-Carlo standard errors of the first's
    (the first ties with itself when another ties with it).

    Parameters
    ----------
    log_z, errors : sequence of float
        Log evidence of every model and its Monte-Carlo standard error [-].

    Returns
    -------
    order : list of int
        Indices into ``log_z``, best first.
    tied : list of bool
        Per model (in the order of ``log_z``), whether it ties with the best.
    """
    log_z, errors = np.asarray(log_z, float), np.asarray(errors, float)
    order = sorted(range(len(log_z)), key=lambda i: (not np.isfinite(log_z[i]), -np.nan_to_num(log_z[i], nan=0.0)))
    tied = [False] * len(log_z)
    if not order or not np.isfinite(log_z[order[0]]):
        return order, tied
    best = order[0]
    for i in order[1:]:
        gap = log_z[best] - log_z[i]
        if np.isfinite(gap) and gap <= TIE_SIGMAS * math.hypot(errors[best], errors[i]):
            tied[i] = tied[best] = True
    return order, tied
