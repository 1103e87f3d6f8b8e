"""Gaussian-mixture proposals for importance sampling over the unit cube of the identified parameters.

The posterior of :mod:`fracid.inverse.sampling.posterior` lives on the unit cube of
:class:`~fracid.inverse.core.space.ParameterSpace` (where the prior, uniform or log-uniform between the bounds,
is uniform). A proposal is a defensive mixture (Hesterberg 1995): a share ``defensive`` of the prior
itself, which bounds every importance weight by the likelihood over that share, and Student-t
components (``dof`` degrees of freedom: heavier tails than the target, as importance sampling needs)
fitted to the weighted samples, so that a curved valley (the c-beta banana) is covered by several
local ellipses instead of one. Draws are kept inside the cube by rejection; the mass of the
mixture inside the cube (``inside``) makes the density of the kept draws exact.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.special import gammaln, logsumexp

__all__ = ["GaussianMixture", "amis_log_evidence", "amis_weights", "bootstrap_log_mean_std", "fit_mixture",
           "weighted_covariance", "weighted_quantile"]

#: draws used to measure a mixture's mass inside the unit cube
_MASS_DRAWS = 20_000
#: degrees of freedom of the Student-t components
DOF = 4.0


@dataclass(frozen=True)
class GaussianMixture:
    """``defensive`` x uniform(unit cube) + (1 - defensive) x sum_k weights[k] t_dof(means[k], covs[k]),
    restricted to the unit cube (``covs``: the scale matrices of the Student-t components).

    Attributes
    ----------
    weights : ndarray, shape (K,)
        Shares of the Gaussian components (sum 1).
    means : ndarray, shape (K, p)
    covs : ndarray, shape (K, p, p)
        In unit-cube coordinates.
    defensive : float
        Share of the uniform component, in [0, 1).
    inside : float
        Mass of the unrestricted mixture inside the cube (from :meth:`with_mass`; 1 until measured).
    """

    weights: np.ndarray
    means: np.ndarray
    covs: np.ndarray
    defensive: float = 0.1
    inside: float = 1.0

    @property
    def dimension(self) -> int:
        return self.means.shape[1]

    def with_mass(self, rng: np.random.Generator) -> "GaussianMixture":
        """The same mixture with ``inside`` measured by ``_MASS_DRAWS`` draws."""
        draws = self._draw(rng, _MASS_DRAWS)
        inside = float(np.mean(np.all((draws >= 0.0) & (draws <= 1.0), axis=1)))
        return GaussianMixture(self.weights, self.means, self.covs, self.defensive, max(inside, 1.0 / _MASS_DRAWS))

    def sample(self, rng: np.random.Generator, n: int) -> np.ndarray:
        """``n`` draws inside the unit cube, shape (n, p)."""
        kept: list[np.ndarray] = []
        while sum(len(k) for k in kept) < n:
            draws = self._draw(rng, max(2 * n, 64))
            kept.append(draws[np.all((draws >= 0.0) & (draws <= 1.0), axis=1)])
        return np.vstack(kept)[:n]

    def logpdf(self, u: np.ndarray) -> np.ndarray:
        """Log density of the draws of :meth:`sample` at ``u`` (shape (n, p)); -inf outside the cube."""
        u = np.atleast_2d(u)
        parts = [np.log(self.defensive) + np.zeros(len(u))] if self.defensive > 0 else []
        for w, mean, cov in zip(self.weights, self.means, self.covs):
            if w > 0:
                parts.append(np.log((1.0 - self.defensive) * w) + _student_logpdf(u, mean, cov))
        density = logsumexp(np.vstack(parts), axis=0) - np.log(self.inside)
        return np.where(np.all((u >= 0.0) & (u <= 1.0), axis=1), density, -np.inf)

    def _draw(self, rng, n) -> np.ndarray:
        p = self.dimension
        uniform = rng.random(n) < self.defensive
        component = rng.choice(len(self.weights), size=n, p=self.weights)
        normal = rng.standard_normal((n, p))
        factors = np.linalg.cholesky(self.covs)
        scale = np.sqrt(DOF / rng.chisquare(DOF, size=n))
        draws = self.means[component] + scale[:, None] * np.einsum("nij,nj->ni", factors[component], normal)
        return np.where(uniform[:, None], rng.random((n, p)), draws)


def _student_logpdf(u, mean, scale) -> np.ndarray:
    p = len(mean)
    factor = np.linalg.cholesky(scale)
    z = np.linalg.solve(factor, (u - mean).T)
    return (gammaln((DOF + p) / 2) - gammaln(DOF / 2) - 0.5 * p * np.log(DOF * np.pi) - np.sum(np.log(np.diag(factor)))
            - 0.5 * (DOF + p) * np.log1p(np.sum(z * z, axis=0) / DOF))


def weighted_covariance(u: np.ndarray, w: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Weighted mean and covariance of the rows of ``u`` (weights ``w`` >= 0, not all zero)."""
    w = w / w.sum()
    mean = w @ u
    d = u - mean
    return mean, (d * w[:, None]).T @ d


def fit_mixture(u: np.ndarray, w: np.ndarray, components: int, *, defensive: float, rng: np.random.Generator,
                inflation: float = 1.5, iterations: int = 10) -> GaussianMixture:
    """A mixture fitted to weighted samples by weighted k-means in the whitened space (hard EM).

    Components: ``components`` centres started at draws of the weighted samples; each gets the weighted
    mean and covariance of the samples nearest to it (Mahalanobis distance of the whole cloud), the
    covariance multiplied by ``inflation`` (heavier tails than the target, as importance sampling
    needs) and shrunk towards the Silverman-scaled covariance of the cloud where a component holds
    few samples.

    Parameters
    ----------
    u : ndarray, shape (n, p)
        Samples in the unit cube.
    w : ndarray, shape (n,)
        Their importance weights (any scale, >= 0).
    components : int
        Number of Gaussian components.
    defensive : float
        Share of the uniform component of the result.
    rng : numpy.random.Generator
    inflation : float
        Covariance multiplier of every component.
    iterations : int
        k-means iterations.
    """
    keep = w > 0
    u, w = u[keep], w[keep] / w[keep].sum()
    p = u.shape[1]
    mean, cov = weighted_covariance(u, w)
    cov = cov + 1e-10 * np.eye(p)
    ess = 1.0 / np.sum(w**2)
    k = int(max(1, min(components, ess // (p + 2))))
    bandwidth = (4.0 / ((p + 2) * max(k, 1))) ** (2.0 / (p + 4))
    smooth = bandwidth * cov
    whiten = np.linalg.inv(np.linalg.cholesky(cov))
    z = u @ whiten.T
    centres = z[rng.choice(len(z), size=k, replace=len(z) < k, p=w)]
    for _ in range(iterations):
        label = np.argmin(((z[:, None, :] - centres[None]) ** 2).sum(axis=-1), axis=1)
        centres = np.array([_centre(z, w, label == j, centres[j]) for j in range(k)])
    label = np.argmin(((z[:, None, :] - centres[None]) ** 2).sum(axis=-1), axis=1)
    weights, means, covs = [], [], []
    for j in range(k):
        member = label == j
        mass = w[member].sum()
        if mass <= 0:
            continue
        m, c = weighted_covariance(u[member], w[member])
        n_j = mass**2 / np.sum(w[member] ** 2)  # effective samples of the component
        share = min(1.0, n_j / (10.0 * (p + 1)))
        weights.append(mass)
        means.append(m)
        covs.append(inflation * (share * c + (1.0 - share) * smooth) + 1e-12 * np.eye(p))
    weights = np.array(weights) / np.sum(weights)
    return GaussianMixture(weights, np.array(means), np.array(covs), defensive).with_mass(rng)


def _centre(z, w, member, previous):
    if not member.any() or w[member].sum() <= 0:
        return previous
    return (w[member] @ z[member]) / w[member].sum()


def weighted_quantile(values, weights, q) -> np.ndarray:
    """Quantiles of ``values`` under normalised ``weights`` (the inverse of the weighted CDF, with the
    mid-point rule so that equal weights give the usual quantiles)."""
    order = np.argsort(values)
    v, w = np.asarray(values)[order], np.asarray(weights, float)[order]
    cdf = (np.cumsum(w) - 0.5 * w) / w.sum()
    return np.interp(np.atleast_1d(q), cdf, v)


#: resamples of the bootstrap of the log evidence's Monte-Carlo error (:func:`bootstrap_log_mean_std`), and its seed
#: (fixed: the same draws give the same error)
BOOTSTRAP_RESAMPLES = 400
BOOTSTRAP_SEED = 0


def bootstrap_log_mean_std(log_w, resamples: int = BOOTSTRAP_RESAMPLES, seed: int = BOOTSTRAP_SEED) -> float:
    """The bootstrap standard deviation of log(mean(exp(log_w))) over the draws [-].

    Every resample draws the N values of ``log_w`` with replacement and takes the log of their mean; the std of
    those logs is the Monte-Carlo error of a log evidence from N importance weights. Unlike the delta method
    (:func:`amis_log_evidence`), it does not assume the error small: when a few draws carry the weight, the
    resamples that miss them fall far below and the std grows with the gap (inf when a resample keeps no
    finite weight).

    Parameters
    ----------
    log_w : array_like, shape (N,)
        The draws' log weights (-inf for a draw of weight 0).
    resamples : int
    seed : int

    Returns
    -------
    float
        The std [-]; inf with fewer than two finite weights.
    """
    log_w = np.asarray(log_w, float)
    if np.sum(np.isfinite(log_w)) < 2:
        return math.inf
    index = np.random.default_rng(seed).integers(0, len(log_w), size=(resamples, len(log_w)))
    logs = logsumexp(log_w[index], axis=1)
    return float(np.std(logs)) if np.all(np.isfinite(logs)) else math.inf


def amis_log_evidence(densities, loglik, sizes) -> tuple[float, float]:
    """log of the importance-sampling estimate of the evidence, Z = mean_i L_i p(u_i) / q(u_i), with the prior
    p uniform on the unit cube (density 1) and q the deterministic mixture of all proposals (``densities``,
    ``loglik``, ``sizes`` as :func:`amis_weights`), and its Monte-Carlo standard error as a std of log Z: the
    larger of the delta method's sqrt(var(w) / N) / mean(w) = sqrt(1 / ESS - 1 / N) and the bootstrap over the
    draws (:func:`bootstrap_log_mean_std`; the delta method alone calls 1-2 effective draws precise to ~1).
    -inf, inf when no draw has a finite likelihood."""
    n = np.array(sizes, float)
    log_q = logsumexp(densities + np.log(n / n.sum())[:, None], axis=0)
    log_w = np.where(np.isfinite(loglik), loglik - log_q, -np.inf)
    if not np.any(np.isfinite(log_w)):
        return -math.inf, math.inf
    total = len(log_w)
    w = np.exp(log_w - logsumexp(log_w))
    ess = 1.0 / float(np.sum(w**2))
    delta = math.sqrt(max(1.0 / ess - 1.0 / total, 0.0))
    return float(logsumexp(log_w) - math.log(total)), max(delta, bootstrap_log_mean_std(log_w))


def amis_weights(densities, loglik, sizes) -> tuple[np.ndarray, float]:
    """Deterministic-mixture weights of all draws against all proposals so far (``densities``: the log density
    of proposal t at draw i, shape (rounds, draws); ``sizes``: the draws of each), normalised, and their ESS."""
    n = np.array(sizes, float)
    log_q = logsumexp(densities + np.log(n / n.sum())[:, None], axis=0)
    log_w = np.where(np.isfinite(loglik), loglik - log_q, -np.inf)
    if not np.any(np.isfinite(log_w)):
        return np.zeros(len(loglik)), 0.0
    w = np.exp(log_w - logsumexp(log_w))
    return w, float(1.0 / np.sum(w**2)) if math.isfinite(np.sum(w**2)) else 0.0
