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

Prior sensitivity: the evidence depends on the prior's volume. With the prior uniform on the box B (in the prior's
coordinates: x, or ln x for a log parameter) of volume V_B, Z_B = (1 / V_B) int_B L. A box B' containing B
gives Z_B' = (V_B / V_B') Z_B + (1 / V_B') int_(B' - B) L: when the likelihood has negligible mass outside B,
log Z_B' = log Z_B - log(V_B' / V_B) exactly (:func:`prior_volume_shift`), and larger otherwise (the closed form
is then a lower bound). :func:`widened` gives B': every span multiplied by a factor about its centre, clipped to
the parameters' valid ranges; for p parameters and no clipping the shift is -p log(factor), so the log Bayes
factor of two models moves by -(p1 - p2) log(factor).

Units: chi^2, log-likelihoods and log evidences are dimensionless (natural logarithms); the densities are
per unit of the parameters.
"""

from __future__ import annotations

import math

import numpy as np

from fracid.inverse.core.space import ParameterSpace

__all__ = ["BOUND_MARGIN", "BOUND_SHARE", "PRIOR_WIDENING", "TIE_SIGMAS", "gaussian_log_likelihood", "information_criteria", "laplace_log_evidence",
           "bound_share", "log_prior_density", "log_prior_volume", "prior_volume_shift", "rank_by_evidence", "widened"]

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


def _spans(space) -> tuple[np.ndarray, np.ndarray]:
    """(centre, span) of every parameter of ``space`` in the prior's coordinates (x, or ln x for a log one)."""
    log = np.array(space.log, dtype=bool)
    lo = np.where(log, np.log(np.where(log, space.lower, 1.0)), space.lower)
    hi = np.where(log, np.log(np.where(log, space.upper, 1.0)), space.upper)
    return 0.5 * (lo + hi), hi - lo


def log_prior_volume(space) -> float:
    """log of the prior box's volume in the prior's coordinates: sum of log(upper - lower), log(ln(upper / lower))
    for a log parameter (units: of the linear parameters; the log ones are dimensionless)."""
    return float(np.sum(np.log(_spans(space)[1])))


def widened(space, factor: float, valid=None) -> ParameterSpace:
    """``space`` with every span multiplied by ``factor`` (>= 1) about its centre in the prior's coordinates (the
    geometric centre of a log parameter), clipped to ``valid`` = (lower, upper) when given (the parameters' valid
    ranges, units of the parameters)."""
    if not factor >= 1.0:
        raise ValueError(f"a widening factor must be >= 1, got {factor!r}")
    centre, span = _spans(space)
    log = np.array(space.log, dtype=bool)
    lo, hi = centre - 0.5 * factor * span, centre + 0.5 * factor * span
    lower, upper = np.where(log, np.exp(lo), lo), np.where(log, np.exp(hi), hi)
    if valid is not None:
        lower = np.maximum(lower, np.where(log, np.maximum(valid[0], 1e-300), valid[0]))
        upper = np.minimum(upper, valid[1])
    return ParameterSpace(space.names, np.minimum(lower, space.lower), np.maximum(upper, space.upper), log=space.log)


#: the factor on every prior span of the prior sensitivity (:func:`widened`) a comparison reports
PRIOR_WIDENING = 2.0
#: a draw within this share of a span (unit-cube coordinates) of a bound lies "at" the bound
BOUND_MARGIN = 0.02
#: the posterior weight at the bounds above which the likelihood is taken to go on beyond them (the widened
#: evidence's closed form is then only a lower bound)
BOUND_SHARE = 0.05


def bound_share(u, weights, margin: float = BOUND_MARGIN) -> float:
    """The weighted share of draws ``u`` (unit-cube coordinates, shape (N, p); ``weights`` summing to 1) within
    ``margin`` of a bound in any parameter [-]."""
    u = np.atleast_2d(np.asarray(u, float))
    near = np.any((u < margin) | (u > 1.0 - margin), axis=1)
    return float(np.sum(np.asarray(weights, float)[near]))


def prior_volume_shift(space, wider) -> float:
    """log Z_wider - log Z of a likelihood with negligible mass outside ``space`` (module docstring):
    -log(V_wider / V_space) [-]; a lower bound on the change when the likelihood goes on beyond the bounds."""
    return log_prior_volume(space) - log_prior_volume(wider)


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
