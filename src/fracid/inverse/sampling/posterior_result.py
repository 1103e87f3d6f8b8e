"""The sampled posterior (:class:`PosteriorResult`): weighted draws of the parameters and what they give (mean,
covariance, credible intervals, the predictive band, resamples, the tables and the ArviZ data written of them).

:func:`fracid.inverse.sampling.posterior.posterior` draws them.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from fracid.inverse.sampling.mixture import weighted_covariance, weighted_quantile


@dataclass
class PosteriorResult:
    """Weighted samples of the posterior and what they give.

    Attributes
    ----------
    names : list of str
    x : ndarray, shape (n, p)
        Every draw, in the parameters' units.
    weights : ndarray, shape (n,)
        Normalised importance weights (sum 1; 0 for failed runs).
    log_likelihood : ndarray, shape (n,)
        -1/2 chi^2 of each draw (-inf for failed runs); with the model error marginalised, the log of its
        marginal likelihood less the base covariance's normalisation (:mod:`fracid.inverse.likelihood.marginal`).
    y : ndarray, shape (n, m)
        Computed observations of each draw (NaN for failed runs).
    y_exp, std_exp : ndarray, shape (m,)
        Measured values and their standard deviations.
    ess : float
        Effective sample size of the weights.
    rounds : int
    failed : int
        Draws whose forward run failed (or lacked outputs).
    estimate, estimate_cov : ndarray
        The Gaussian the sampler started from (the identification's estimate and covariance).
    bounds : (ndarray, ndarray)
    log : tuple of bool
        Per parameter: whether its prior is log-uniform (a log axis in plots).
    units : dict
    status : str
        ``"converged"`` (ESS reached), ``"ESS ... below the target ..."`` (between the floor
        :func:`~fracid.inverse.sampling.posterior.ess_floor` and the target: rough intervals) or ``"failed: effective sample size ..."``
        (below the floor: :attr:`sampling_failed`, no credible intervals).
    history : list of dict
        Per round: draws, failed, ESS after the round, components of the proposal.
    log_evidence, log_evidence_error : float
        log p(y_exp) of the model with its prior (uniform, or log-uniform, between the bounds) and the Gaussian
        likelihood with its normalisation (-1/2 log det(2 pi C_exp)), from the importance weights of all draws
        (:func:`~fracid.inverse.sampling.mixture.amis_log_evidence`), and its Monte-Carlo standard error (the larger
        of the delta method's and a bootstrap over the draws). Two models fitted to the same data compare by the
        difference (the log Bayes factor); below the sampler's floor of the effective sample size neither is
        credible (``fracid compare`` does not rank it).
    model_error : list of dict
        With the model's own error marginalised (:class:`~fracid.inverse.likelihood.marginal.MarginalLikelihood`):
        the posterior of its std per group (``group``, ``blocks``, ``mean``, ``median``, ``interval_90`` [units
        of y], ``grid``, ``probability``); empty otherwise.
    levels : Levels or None
        With coarse-mesh screening (:func:`~fracid.inverse.sampling.screened.screened_posterior`): the coarse draws
        and the fine subset (:class:`~fracid.inverse.sampling.levels.Levels`). ``x``, ``weights``, ``y`` are then the
        fine runs with their exact weights, the statistics the two-level estimator's, and ``ess`` the smallest
        number of equivalent independent draws of a parameter's mean.
    notes : list of str
        What the sampler could not do as asked (screening asked where the mesh cannot be coarsened).
    """

    names: list
    x: np.ndarray
    weights: np.ndarray
    log_likelihood: np.ndarray
    y: np.ndarray
    y_exp: np.ndarray
    std_exp: np.ndarray
    ess: float
    rounds: int
    failed: int
    estimate: np.ndarray
    estimate_cov: np.ndarray
    bounds: tuple
    log: tuple = ()
    units: dict = field(default_factory=dict)
    status: str = ""
    history: list = field(default_factory=list)
    log_evidence: float = float("nan")
    log_evidence_error: float = float("nan")
    model_error: list = field(default_factory=list)
    levels: object = None
    notes: list = field(default_factory=list)

    @property
    def converged(self) -> bool:
        return self.status == "converged"

    @property
    def sampling_failed(self) -> bool:
        """Whether the effective sample size stayed below the floor (:func:`~fracid.inverse.sampling.posterior.ess_floor`): the draws give no
        credible intervals (:meth:`credible_intervals` is NaN) and ``fracid posterior`` exits 3.
        (``failed`` is the count of failed forward runs.)"""
        return self.status.startswith("failed")

    @property
    def mean(self) -> np.ndarray:
        return self.weights @ self.x if self.levels is None else self.levels.mean()

    @property
    def cov(self) -> np.ndarray:
        return weighted_covariance(self.x, self.weights)[1] if self.levels is None else self.levels.cov()

    @property
    def mean_error(self) -> np.ndarray:
        """The Monte-Carlo standard error of :attr:`mean` per parameter: the delta method of self-normalised
        importance sampling, sqrt(sum_i w_i^2 (x_i - mean)^2), or the two-level estimator's
        (:meth:`~fracid.inverse.sampling.levels.Levels.mean_variance`)."""
        if self.levels is not None:
            return np.sqrt(self.levels.mean_variance())
        return np.sqrt(np.sum(self.weights[:, None] ** 2 * (self.x - self.mean) ** 2, axis=0))

    @property
    def std(self) -> np.ndarray:
        return np.sqrt(np.diag(self.cov))

    def quantiles(self, q) -> np.ndarray:
        """Weighted quantiles of every parameter, shape (len(q), p)."""
        if self.levels is not None:
            return self.levels.quantiles(q)
        return np.column_stack([weighted_quantile(self.x[:, j], self.weights, q) for j in range(self.x.shape[1])])

    def credible_intervals(self, level: float = 0.9) -> np.ndarray:
        """Equal-tailed credible intervals, shape (p, 2); NaN when :attr:`sampling_failed` (the quantiles of
        a few draws are not an interval: :meth:`quantiles` still gives them)."""
        if self.sampling_failed:
            return np.full((len(self.names), 2), np.nan)
        return self.quantiles([(1.0 - level) / 2.0, (1.0 + level) / 2.0]).T

    def predictive_band(self, level: float = 0.9) -> np.ndarray:
        """Weighted quantiles (lower, median, upper) of the computed observations, shape (3, m): the band
        of the model's response over the measured points (without measurement noise)."""
        ok = self.weights > 0
        q = [(1.0 - level) / 2.0, 0.5, (1.0 + level) / 2.0]
        if self.levels is not None:
            return self.levels.quantiles(q, "y")
        return np.column_stack([weighted_quantile(self.y[ok, i], self.weights[ok], q) for i in range(self.y.shape[1])])

    def resample(self, n: int, seed: int = 0) -> np.ndarray:
        """``n`` equally weighted draws (systematic resampling), shape (n, p)."""
        rng = np.random.default_rng(seed)
        positions = (rng.random() + np.arange(n)) / n
        index = np.minimum(np.searchsorted(np.cumsum(self.weights), positions), len(self.weights) - 1)
        return self.x[index]

    def summary(self) -> str:
        lines = [f"posterior: {len(self.x)} draws in {self.rounds} rounds, ESS {self.ess:.0f}, "
                 f"{self.failed} failed run{'' if self.failed == 1 else 's'}; {self.status}"]
        if self.levels is not None:
            lines[0] = self.levels.line(self.status, self.failed)
        lines.extend(f"  note: {note}" for note in self.notes)
        if np.isfinite(self.log_evidence):
            lines.append(f"  log evidence {self.log_evidence:.4g} +- {self.log_evidence_error:.2g} (Monte Carlo)")
        for g in self.model_error:
            lines.append(f"  model-error std of {g['group']}: mean {g['mean']:.4g}, 90 % interval "
                         f"[{g['interval_90'][0]:.4g}, {g['interval_90'][1]:.4g}] (marginalised per draw)")
        if self.sampling_failed:
            return "\n".join([*lines, "  no credible intervals: the effective sample size is below the floor"])
        intervals = self.credible_intervals(0.9)
        for j, name in enumerate(self.names):
            lines.append(f"  {name}: mean {self.mean[j]:.5g} (+- {self.mean_error[j]:.2g} Monte Carlo), std "
                         f"{self.std[j]:.3g}, 90 % interval "
                         f"[{intervals[j, 0]:.5g}, {intervals[j, 1]:.5g}] {self.units.get(name, '')}".rstrip())
        return "\n".join(lines)

    def to_dict(self) -> dict:
        """The statistics as plain values; ``interval_90`` holds None (JSON null) when :attr:`sampling_failed`."""
        intervals = self.credible_intervals(0.9).astype(object)
        intervals[~np.isfinite(intervals.astype(float))] = None
        return {"names": list(self.names), "mean": self.mean.tolist(), "mean_error": self.mean_error.tolist(),
                "std": self.std.tolist(),
                "cov": self.cov.tolist(), "interval_90": intervals.tolist(), "ess": self.ess, "draws": len(self.x),
                "rounds": self.rounds, "failed": self.failed, "status": self.status,
                "sampling_failed": self.sampling_failed,
                "estimate": np.asarray(self.estimate).tolist(), "estimate_cov": np.asarray(self.estimate_cov).tolist(),
                "units": dict(self.units), "history": self.history,
                "log_evidence": _finite_or_none(self.log_evidence),
                "log_evidence_error": _finite_or_none(self.log_evidence_error), "model_error": self.model_error,
                "screening": None if self.levels is None else self.levels.summary(), "notes": list(self.notes)}

    def save_csv(self, path) -> Path:
        """The draws: one row each, the parameters, the weight and the log-likelihood."""
        path = Path(path)
        header = ",".join([*self.names, "weight", "log_likelihood"])
        np.savetxt(path, np.column_stack([self.x, self.weights, self.log_likelihood]), delimiter=",",
                   header=header, comments="", fmt="%.10g")
        return path

    def to_inference_data(self, draws: int = 2000, seed: int = 0):
        """ArviZ InferenceData of ``draws`` resampled (equally weighted) draws in one chain, with the
        weighted draws' ESS in its attributes (needs the ``arviz`` extra)."""
        try:
            import arviz
        except ImportError as exc:
            raise ImportError("to_inference_data needs ArviZ: pip install 'fracid[arviz]'") from exc
        sample = self.resample(draws, seed)
        data = {name: sample[None, :, j] for j, name in enumerate(self.names)}
        return arviz.from_dict(posterior=data, attrs={"importance_ess": self.ess, "importance_draws": len(self.x),
                                                       "method": "adaptive importance sampling (fracid)"})


def _finite_or_none(value: float):
    """``value``, or None (JSON null) when it is not finite."""
    return float(value) if np.isfinite(value) else None


__all__ = ["PosteriorResult"]
