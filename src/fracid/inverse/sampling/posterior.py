"""Samples of the identified parameters given the data, on the exact forward model: adaptive importance
sampling seeded by the Gaussian of the identification.

Target: p(x | y_exp) ~ exp(-1/2 (y(x) - y_exp)^T C_exp^-1 (y(x) - y_exp)) prior(x), with the prior
uniform between the identification bounds (log-uniform for parameters on a log scale): uniform on the
unit cube of :class:`~fracid.inverse.core.space.ParameterSpace`, where the sampler works.

Method (AMIS, Cornuet et al. 2012, with defensive mixtures, Hesterberg 1995): round 0 draws from a
Gaussian around the estimate (its covariance inflated) plus a share of the prior; every later round
from a Gaussian mixture fitted to all weighted samples so far (:func:`fracid.inverse.sampling.mixture.fit_mixture`),
which follows a curved valley with several ellipses. Every draw is one independent exact forward run,
so a round runs in parallel on the executor and goes through the run store (a rerun with the same seed
draws the same points and reuses them). All draws are reweighted against the mixture of all
proposals used (deterministic-mixture weights), so no run is wasted. It stops when the effective
sample size (ESS = (sum w)^2 / sum w^2) reaches the target or after ``max_rounds``. Failed runs and
runs without every output get weight 0 and are counted.

Why not MCMC on the exact model: its samples are sequential (a chain cannot use the pool), and a
thousand sequential runs of a beam are hours; the importance draws of one round run side by side.
Why not MCMC on an emulator: the emulator's error enters the posterior unmeasured.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from fracid.data.covariance_matrix import as_covariance
from fracid.inverse.sampling.mixture import (
    GaussianMixture,
    amis_log_evidence,
    amis_weights,
    fit_mixture,
)
from fracid.inverse.core.sensitivity import ForwardRunError, evaluate_points
from fracid.inverse.sampling.posterior_result import PosteriorResult

__all__ = ["ESS_ADVICE", "MAX_SCREENING", "MIN_ESS", "MIN_ESS_FRACTION", "PosteriorSettings", "ess_floor", "ess_status",
           "floor_text", "log_likelihood", "posterior"]

#: Effective sample size below which the sampling has failed: the weights sit on a few draws, and
#: quantiles of a few points are not credible intervals (at ESS 1 the interval is a point)
MIN_ESS = 50.0
#: ... or below this share of ``target_ess``, when that is larger
MIN_ESS_FRACTION = 0.05
#: What to change when the sampling failed (the status's and the configuration warning's advice)
ESS_ADVICE = ("draw more (samples_per_round, max_rounds of [posterior]), widen the first proposal (a larger "
              "inflation), or check the identification (a poor fit, an estimate at a bound, a std too small)")


#: the coarsest screening mesh: element sizes at most this multiple of the configured mesh's
MAX_SCREENING = 4.0


def ess_floor(target_ess: float) -> float:
    """The effective sample size below which the sampling has failed: ``max(MIN_ESS, MIN_ESS_FRACTION *
    target_ess)``, but never above ``target_ess`` itself (a lower target is the user's choice, warned
    about when the configuration is loaded).

    Examples
    --------
    >>> ess_floor(500.0), ess_floor(4000.0), ess_floor(30.0)
    (50.0, 200.0, 30.0)
    """
    return float(min(target_ess, max(MIN_ESS, MIN_ESS_FRACTION * target_ess)))


def floor_text(target_ess: float, key: str = "target_ess") -> str:
    """Which of its terms sets :func:`ess_floor` for ``target_ess``, in words (the messages that name the floor);
    ``key`` is the setting's name as the reader knows it (``posterior.target_ess`` in a configuration).

    Examples
    --------
    >>> floor_text(500.0)
    'the least effective sample size whose quantiles are credible intervals, above 5% of target_ess = 500'
    >>> floor_text(4000.0)
    '5% of target_ess = 4000'
    >>> floor_text(30.0)
    'target_ess = 30 itself, below the usual floor 50'
    """
    if target_ess < MIN_ESS:
        return f"{key} = {target_ess:g} itself, below the usual floor {MIN_ESS:g}"
    if MIN_ESS_FRACTION * target_ess > MIN_ESS:
        return f"{MIN_ESS_FRACTION:.0%} of {key} = {target_ess:g}"
    return (f"the least effective sample size whose quantiles are credible intervals, above {MIN_ESS_FRACTION:.0%} "
            f"of {key} = {target_ess:g}")


@dataclass(frozen=True)
class PosteriorSettings:
    """Settings of :func:`posterior`.

    Parameters
    ----------
    samples_per_round : int
        Forward runs per round (run side by side on the executor).
    max_rounds : int
        Rounds at most (runs at most: ``samples_per_round * max_rounds``).
    target_ess : float
        Stop when the effective sample size reaches this.
    components : int
        Gaussian components of the adapted proposals.
    defensive : float
        Share of the prior in every proposal (bounds the weights; covers what the Gaussian misses).
    inflation : float
        Standard-deviation multiplier of the first proposal around the Gaussian estimate.
    seed : int
        Seed of the draws (the same seed draws the same points: a rerun reuses the stored runs).
    screening : float
        Element sizes of the screening mesh over the configured mesh's [-]: the draws are screened on that
        coarse mesh and corrected by fine runs (:mod:`fracid.inverse.sampling.screened`); 1 turns screening off
        (every draw a fine run, the default). Used by :func:`sample_posterior` where the specimen can be
        coarsened; it pays where a coarse run costs far less than a fine one and the two posteriors are close
        (the fine / coarse likelihood ratio's spread near 1).
    fine_runs : int
        With screening: fine runs at most (in rounds of ``samples_per_round``).
    """

    samples_per_round: int = 200
    max_rounds: int = 10
    target_ess: float = 500.0
    components: int = 8
    defensive: float = 0.1
    inflation: float = 2.0
    seed: int = 0
    #: off by default: on the Grégoire demo a mesh 2 times coarser cost half a fine run and screened with a spread
    #: of about 2 (docs/posterior/README.md): 6000 coarse + 300 fine runs gave 239 equivalent draws, where 1750
    #: fine runs alone gave an ESS of 1014 for half the CPU time
    screening: float = 1.0
    fine_runs: int = 300

    def __post_init__(self):
        checks = [("samples_per_round", self.samples_per_round >= 2), ("max_rounds", self.max_rounds >= 1),
                  ("target_ess", self.target_ess > 1), ("components", self.components >= 1),
                  ("defensive", 0.0 <= self.defensive < 1.0), ("inflation", self.inflation > 0),
                  ("seed", isinstance(self.seed, (int, np.integer)) and self.seed >= 0),
                  ("screening", 1.0 <= self.screening <= MAX_SCREENING), ("fine_runs", self.fine_runs >= 2)]
        for name, ok in checks:
            if not ok:
                raise ValueError(f"posterior setting {name} = {getattr(self, name)!r} is out of range")

    def replace(self, **changes) -> "PosteriorSettings":
        return replace(self, **changes)


def log_likelihood(records, y_exp, C_exp, marginal=None):
    """-1/2 chi^2 of every record (-inf where the run failed or left outputs out), and the outputs;
    chi^2 = ``|C_exp.whiten(y - y_exp)|``^2 (``C_exp`` a :class:`~fracid.data.covariance_matrix.Covariance`), or
    ``marginal(residuals)``: the model error's std integrated out (relative to C_exp's normalisation)."""
    y = np.array([np.asarray(r.y, float) if r.ok else np.full(len(y_exp), np.nan) for r in records])
    good = np.all(np.isfinite(y), axis=1)
    residuals = np.where(good[:, None], y - y_exp, 0.0)
    value = -0.5 * C_exp.quadratic(residuals.T) if marginal is None else marginal(residuals)
    return np.where(good, value, -np.inf), y


def _first_proposal(space, x0, C0, settings, rng) -> GaussianMixture:
    """The estimate's Gaussian in unit-cube coordinates (linearised map), its std times ``inflation``."""
    u0 = np.clip(space.to_unit(x0)[0], 1e-6, 1 - 1e-6)
    log = np.array(space.log, dtype=bool)
    ratio = np.where(log, space.upper, 1.0) / np.where(log, space.lower, 1.0)
    span = np.where(log, np.log(ratio), space.upper - space.lower)
    jac = 1.0 / np.where(log, x0 * span, span)  # du/dx of ParameterSpace.to_unit
    cov = settings.inflation**2 * (jac[:, None] * np.asarray(C0, float) * jac[None, :])
    cov = cov + 1e-10 * np.eye(len(u0))
    return GaussianMixture(np.ones(1), u0[None], cov[None], settings.defensive).with_mass(rng)


def posterior(evaluate, y_exp, C_exp, space, x0, C0, *, settings: PosteriorSettings = PosteriorSettings(),
              executor=None, progress=None, log=None, marginal=None) -> PosteriorResult:
    """Weighted samples of the parameters given the data by adaptive importance sampling on the exact model.

    Parameters
    ----------
    evaluate : callable or StoredOperator
        The forward operator (``evaluate(x)`` gives a run record or the outputs); a
        :class:`~fracid.inverse.core.runs.StoredOperator` stores every run and reuses stored ones.
    y_exp : ndarray, shape (m,)
        Measured values.
    C_exp : ndarray, shape (m, m), or Covariance
        Their covariance [units of y squared] (a diagonal one forms no m x m matrix).
    space : ParameterSpace
        Names and bounds of the parameters: the prior is uniform on its unit cube.
    x0, C0 : ndarray
        The Gaussian estimate to start from (an identification's ``x`` and ``C``).
    settings : PosteriorSettings
    executor : Executor, optional
        Runs the draws of a round side by side.
    progress : callable, optional
        ``progress(done_runs, max_runs)`` after every round.
    log : callable, optional
        ``log(text)``: a line per round.
    marginal : MarginalLikelihood, optional
        The likelihood with the model error's std integrated out per draw
        (:class:`~fracid.inverse.likelihood.marginal.MarginalLikelihood` over ``C_exp``); its posterior goes to
        ``model_error``.

    Returns
    -------
    PosteriorResult

    Raises
    ------
    ForwardRunError
        When every forward run failed or lacked outputs (nothing to weigh).
    """
    y_exp = np.asarray(y_exp, float)
    C_exp = as_covariance(C_exp, y_exp.size, name="C_exp")
    rng = np.random.default_rng(settings.seed)
    proposal = _first_proposal(space, np.asarray(x0, float), C0, settings, rng)
    proposals, densities, sizes, history = [], [], [], []
    u_all, loglik, outputs = np.empty((0, len(space.names))), np.empty(0), np.empty((0, len(y_exp)))
    weights, ess = np.empty(0), 0.0
    for round_ in range(settings.max_rounds):
        u = proposal.sample(rng, settings.samples_per_round)
        records = evaluate_points(evaluate, space.from_unit(u), None, executor)
        ll, y = log_likelihood(records, y_exp, C_exp, marginal)
        # every proposal's log density at every draw: the earlier ones at the new draws, the new one at all
        densities = [np.concatenate([row, q.logpdf(u)]) for row, q in zip(densities, proposals)]
        proposals.append(proposal)
        sizes.append(len(u))
        u_all, loglik, outputs = np.vstack([u_all, u]), np.concatenate([loglik, ll]), np.vstack([outputs, y])
        densities.append(proposal.logpdf(u_all))
        weights, ess = amis_weights(np.vstack(densities), loglik, sizes)
        history.append({"round": round_, "draws": len(u), "failed": int(np.sum(~np.isfinite(ll))), "ess": ess,
                        "components": len(proposal.weights)})
        if progress is not None:
            progress(len(u_all), settings.samples_per_round * settings.max_rounds)
        if log is not None:
            log(f"posterior round {round_ + 1}: {len(u_all)} draws, ESS {ess:.0f} (target {settings.target_ess:g})")
        if ess >= settings.target_ess or not np.any(weights > 0):
            break
        proposal = fit_mixture(u_all, weights, settings.components, defensive=settings.defensive, rng=rng)
    failed = int(np.sum(~np.isfinite(loglik)))
    if not np.any(weights > 0):
        raise ForwardRunError(f"posterior: all {len(u_all)} forward runs failed or lacked outputs; nothing to weigh. "
                              "Check the bounds of [identify.bounds] (the prior) and the forward runs of the "
                              "identification; failed runs are stored: --retry-failed runs them again")
    status = ess_status(ess, settings, len(u_all), len(proposals))
    lower, upper = space.lower, space.upper
    log_z, log_z_error = amis_log_evidence(np.vstack(densities), loglik, sizes)
    log_z -= 0.5 * (y_exp.size * np.log(2.0 * np.pi) + C_exp.logdet())
    ok = np.isfinite(loglik)
    sigma = [] if marginal is None else marginal.summary(outputs[ok] - y_exp, weights[ok])
    return PosteriorResult(list(space.names), space.from_unit(u_all), weights, loglik, outputs, y_exp,
                           C_exp.std(), ess, len(proposals), failed, np.asarray(x0, float),
                           np.asarray(C0, float), (lower, upper), log=tuple(space.log), status=status, history=history,
                           log_evidence=float(log_z), log_evidence_error=log_z_error, model_error=sigma)


def ess_status(ess: float, settings: PosteriorSettings, draws: int, rounds: int) -> str:
    """The sampler's verdict on its weights: converged, rough (below the target) or failed (below the floor)."""
    if ess >= settings.target_ess:
        return "converged"
    floor = ess_floor(settings.target_ess)
    if ess < floor:
        return (f"failed: effective sample size {ess:.3g} < {floor:g} (the floor: {floor_text(settings.target_ess)}) "
                f"after {draws} draws in {rounds} round{'s' if rounds != 1 else ''}: the weights sit on a few draws, so there are no credible "
                f"intervals; {ESS_ADVICE}")
    return (f"ESS {ess:.0f} below the target {settings.target_ess:g} after {rounds} rounds: the intervals are "
            "rough; raise max_rounds or samples_per_round")
