"""The two-level estimator of the posterior: weighted draws on a coarse mesh, corrected by fine-mesh runs at a
subset of them (:func:`fracid.inverse.sampling.screened.screened_posterior` draws them).

The coarse level gives normalised weights w_i at draws x_i (adaptive importance sampling of the coarse posterior
p_c). A subset x_j, j = 1..N, is resampled from them and run on the fine mesh; r_j = L_f(x_j) / L_c(x_j) is the
ratio of the normalised likelihoods. The fine posterior's expectation of any g is

    E_f[g] = E_c[g] + (E_f[g] - E_c[g])
           ~ sum_i w_i g_c(x_i) + [sum_j rho_j g_f(x_j) - 1/N sum_j g_c(x_j)],   rho_j = r_j / sum_k r_k,

the coarse estimate plus a correction from the paired subset (a control variate: the fine and coarse values at
the same points, so the correction is small where the coarse posterior is close to the fine one). The estimate
is that of the fine model (the ratio is exact); its Monte-Carlo variance is the coarse estimate's (the delta
method of self-normalised importance sampling, sum_i w_i^2 (g_i - mean)^2, times mean(r^2) / mean(r)^2: the
fine weights w_i r_i spread more than w_i) plus the correction's,

    var_j[ r_j / mean(r) (g_f(x_j) - E_f[g]) - (g_c(x_j) - mean_j g_c) ] / N,

which vanishes when r is constant. As a linear combination it is a set of *signed* weights over the coarse draws
and the subset (:meth:`Levels.signed`): means and covariances are weighted sums, quantiles invert the signed
cumulative distribution made monotone (:func:`signed_quantile`). The evidence is Z_f = Z_c mean_j r_j.

"Equivalent independent draws" (:meth:`Levels.equivalent_draws`): per parameter, the posterior variance over the
estimator's variance of the posterior mean; the number of independent draws of the fine posterior whose mean is
as precise. It plays the part of the effective sample size of single-level importance sampling (whose Kish ESS
estimates the same ratio).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property

import numpy as np
from scipy.special import logsumexp

__all__ = ["SUBSET_TEMPER", "Levels", "resample_index", "signed_quantile", "subset_probabilities"]

#: the fine subset is drawn with probabilities w^alpha (normalised): alpha < 1 reaches into the coarse posterior's
#: tails, where a coarse mesh's error may leave the fine posterior more mass (1: draw from the coarse posterior)
SUBSET_TEMPER = 0.5


def subset_probabilities(w, alpha: float = SUBSET_TEMPER) -> np.ndarray:
    """w^alpha normalised (zero where w is zero): the probabilities of drawing the fine subset."""
    w = np.asarray(w, float)
    p = np.where(w > 0, w, 0.0) ** alpha
    return p / p.sum()


def resample_index(weights, n: int, rng: np.random.Generator) -> np.ndarray:
    """``n`` indices drawn by systematic resampling from normalised ``weights`` (each index about n w_i times)."""
    positions = (rng.random() + np.arange(n)) / n
    return np.minimum(np.searchsorted(np.cumsum(weights), positions), len(weights) - 1)


def signed_quantile(values, weights, q) -> np.ndarray:
    """Quantiles under signed weights summing to 1: the inverse of the cumulative sum in the order of
    ``values``, made non-decreasing (its running maximum) and clipped to [0, 1]; the mid-point rule as
    :func:`~fracid.inverse.sampling.mixture.weighted_quantile`, so that non-negative weights give its values."""
    order = np.argsort(values, kind="stable")
    v, w = np.asarray(values, float)[order], np.asarray(weights, float)[order]
    cdf = np.clip(np.maximum.accumulate(np.cumsum(w) - 0.5 * w) / w.sum(), 0.0, 1.0)
    cdf = np.maximum.accumulate(cdf)
    return np.interp(np.atleast_1d(q), cdf, v)


@dataclass(frozen=True)
class Levels:
    """The coarse draws, the fine subset and what the two-level estimator makes of them.

    Attributes
    ----------
    x : ndarray, shape (n, p)
        The coarse draws [parameters' units].
    w : ndarray, shape (n,)
        Their normalised coarse weights.
    y : ndarray, shape (n, m)
        Their computed values on the coarse mesh, shifted to the fine mesh's at the estimate (NaN: failed).
    index : ndarray of int, shape (N,)
        The subset: the coarse draws run on the fine mesh (repeated indices count as often as drawn).
    log_ratio : ndarray, shape (N,)
        log r_j = log L_f(x_j) - log L_c(x_j), both likelihoods normalised (-inf: the fine run failed).
    y_fine : ndarray, shape (N, m)
        The fine runs' computed values.
    log_evidence_coarse, log_evidence_coarse_error : float
        The coarse level's log evidence and its Monte-Carlo error.
    pick : ndarray, shape (n,), optional
        The probabilities with which the subset was drawn from the coarse draws (default: ``w``). A flatter
        choice (w^alpha, :func:`subset_probabilities`) reaches into the coarse posterior's tails, where the fine
        posterior may hold more mass than the coarse one; the weights below divide by it.

    Immutable: the weights derived from these arrays are computed once (cached properties).
    """

    x: np.ndarray
    w: np.ndarray
    y: np.ndarray
    index: np.ndarray
    log_ratio: np.ndarray
    y_fine: np.ndarray
    log_evidence_coarse: float = float("nan")
    log_evidence_coarse_error: float = float("nan")
    pick: np.ndarray | None = None

    @cached_property
    def _log_pick_ratio(self) -> np.ndarray:
        """log(w_j / pick_j) of the subset: the coarse posterior's weight over the subset's draw probability."""
        pick = self.w if self.pick is None else self.pick
        with np.errstate(divide="ignore"):
            return np.log(self.w[self.index]) - np.log(pick[self.index])

    @cached_property
    def coarse_subset(self) -> np.ndarray:
        """The coarse posterior's weights of the subset, sum 1 (1/N when drawn from ``w`` itself)."""
        return np.exp(self._log_pick_ratio - logsumexp(self._log_pick_ratio))

    @cached_property
    def rho(self) -> np.ndarray:
        """The fine weights of the subset, sum 1 (the exact fine posterior's importance weights against the
        subset's draw); zeros when every fine run failed."""
        log_w = self.log_ratio + self._log_pick_ratio
        if not np.any(np.isfinite(log_w)):
            return np.zeros(len(self.index))
        return np.exp(log_w - logsumexp(log_w))

    @property
    def fine_ess(self) -> float:
        """Kish's effective sample size of :attr:`rho`: near the subset's size when the coarse posterior is close
        to the fine one, small when it is a poor screen."""
        rho = self.rho
        return float(1.0 / np.sum(rho**2)) if rho.any() else 0.0

    @cached_property
    def spread(self) -> float:
        """E_c[r^2] / E_c[r]^2 >= 1 over the coarse posterior (estimated on the subset): 1 when the fine posterior is
        the coarse one, large when the coarse mesh screened poorly (the coarse draws then carry the fine estimate
        with an efficiency of 1 / spread)."""
        rho, c = self.rho, self.coarse_subset
        return max(float(np.sum(rho**2 / np.where(c > 0, c, np.inf))), 1.0) if rho.any() else math.inf

    def signed(self, values: str = "x") -> tuple[np.ndarray, np.ndarray]:
        """(values, weights) of the estimator as signed weights summing to 1: the coarse draws with w_i, the
        subset's fine values with rho_j, the subset's coarse values with -1/N. ``values`` "x" (the parameters)
        or "y" (the computed values)."""
        coarse, fine = (self.x, self.x[self.index]) if values == "x" else (self.y, self.y_fine)
        stacked = np.vstack([coarse, fine, coarse[self.index]])
        return stacked, np.concatenate([self.w, self.rho, -self.coarse_subset])

    def mean(self) -> np.ndarray:
        values, weights = self.signed()
        return weights @ values

    def cov(self) -> np.ndarray:
        values, weights = self.signed()
        centred = values - weights @ values
        cov = (weights[:, None] * centred).T @ centred
        return 0.5 * (cov + cov.T)

    def mean_variance(self) -> np.ndarray:
        """The Monte-Carlo variance of :meth:`mean` per parameter (module docstring) [units squared]."""
        mean = self.mean()
        coarse_mean = self.w @ self.x
        coarse = np.sum(self.w[:, None] ** 2 * (self.x - coarse_mean) ** 2, axis=0)
        sub, n = self.x[self.index], len(self.index)
        rho, c = self.rho, self.coarse_subset
        terms = n * (rho[:, None] * (sub - mean) - c[:, None] * (sub - c @ sub))
        # the coarse draws carry the fine estimate with weights w_i r_i: their spread costs it E_c[r^2] / E_c[r]^2
        return coarse * self.spread + np.var(terms, axis=0, ddof=1) / n

    @property
    def fine_runs(self) -> int:
        """The distinct fine runs of the subset."""
        return int(len(np.unique(self.index)))

    @property
    def coarse_ess(self) -> float:
        """Kish's effective sample size of the coarse weights."""
        return float(1.0 / np.sum(self.w**2))

    def coarse_equivalent_draws(self) -> np.ndarray:
        """Per parameter: the equivalent draws if the correction were exact (the coarse level's error alone): the
        bound that more fine runs cannot pass."""
        coarse_mean = self.w @ self.x
        coarse = np.sum(self.w[:, None] ** 2 * (self.x - coarse_mean) ** 2, axis=0) * self.spread
        return self.fine_variance() / np.maximum(coarse, 1e-300)

    def fine_variance(self) -> np.ndarray:
        """The posterior variance per parameter from the fine runs' own weights (non-negative, unlike the signed
        weights' on a small subset): the scale of the equivalent draws."""
        sub, rho = self.x[self.index], self.rho
        return rho @ (sub - rho @ sub) ** 2

    def equivalent_draws(self) -> np.ndarray:
        """Per parameter: the posterior variance over :meth:`mean_variance` (independent draws as precise)."""
        variance, error = self.fine_variance(), self.mean_variance()
        return np.where(error > 0, variance / np.maximum(error, 1e-300), np.where(variance > 0, np.inf, 0.0))

    def log_evidence(self) -> tuple[float, float]:
        """log Z_f = log Z_c + log mean_j r_j, and its Monte-Carlo error: the coarse one and the correction's
        (delta method, sqrt(var(r) / N) / mean(r)) added in quadrature [-]."""
        finite = np.isfinite(self.log_ratio)
        if not np.any(finite):
            return -math.inf, math.inf
        # E_c[r] = sum_i w_i r_i, estimated by the subset drawn with probabilities pick: mean_j r_j w_j / pick_j
        log_terms = self.log_ratio + self._log_pick_ratio
        n = len(log_terms)
        log_mean = float(logsumexp(log_terms) - math.log(n))
        correction = math.sqrt(float(np.var(np.exp(log_terms - log_mean), ddof=1)) / n)
        error = math.hypot(self.log_evidence_coarse_error, correction)
        return self.log_evidence_coarse + log_mean, error

    def quantiles(self, q, values: str = "x") -> np.ndarray:
        """Signed-weight quantiles of every column of the parameters ("x") or computed values ("y")."""
        stacked, weights = self.signed(values)
        ok = np.all(np.isfinite(stacked), axis=1) if values == "y" else np.ones(len(weights), bool)
        return np.column_stack([signed_quantile(stacked[ok, j], weights[ok], q) for j in range(stacked.shape[1])])

    def summary(self) -> dict:
        """What the result records of the two levels (JSON-ready)."""
        value, error = self.log_evidence()
        return {"coarse_draws": int(len(self.x)), "coarse_ess": self.coarse_ess,
                "fine_runs": self.fine_runs, "fine_draws": int(len(self.index)),
                "fine_ess": self.fine_ess, "spread": self.spread, "equivalent_draws": self.equivalent_draws().tolist(),
                "mean_error": np.sqrt(self.mean_variance()).tolist(),
                "log_evidence_coarse": self.log_evidence_coarse, "log_evidence": value, "log_evidence_error": error}

    def line(self, status: str, failed: int) -> str:
        """The two levels in one line (the summary's first)."""
        worst = float(np.min(self.equivalent_draws()))
        return (f"posterior: {len(self.x)} coarse draws (ESS {self.coarse_ess:.0f}) corrected by "
                f"{self.fine_runs} fine runs (fine/coarse likelihood ratio's spread {self.spread:.2f}): as precise as "
                f"{worst:.0f} independent draws, {failed} failed run{'' if failed == 1 else 's'}; {status}")
