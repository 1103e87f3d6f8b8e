"""The posterior at the price of a coarse mesh: a coarse mesh screens, the fine mesh corrects.

A forward run on a mesh ``screening`` times coarser costs a fraction of a fine run, and its likelihood, with the
mesh's own error in it, is an honest screening model: the values computed on the coarse mesh are shifted by their
difference from the fine mesh's at the identification's estimate (the bias the coarse mesh adds there) and the
data covariance is widened by that difference (correlated along each curve, as the discretisation term of
:mod:`fracid.inverse.likelihood.discretisation`; the coarse posterior is then wider than the fine one and covers
it). Adaptive importance sampling (:func:`~fracid.inverse.sampling.posterior.posterior`) samples the coarse
posterior to an effective sample size of :data:`COARSE_ESS` times the target, in rounds of :data:`COARSE_ROUND`
times ``samples_per_round``. Then rounds of ``samples_per_round`` fine runs at draws resampled from the coarse
weights correct it (:class:`~fracid.inverse.sampling.levels.Levels`: the ratio of the fine and coarse likelihoods
is exact, so the estimate is the fine model's, its Monte-Carlo error stated), until the equivalent independent
draws of every parameter's mean reach ``target_ess`` or ``fine_runs`` fine runs have run.

Single-level sampling of the fine model spends one fine run per draw and gets at most one effective sample per
run; here the fine runs only carry the correction, whose variance is small when the coarse posterior is close to
the fine one (it is measured: the fine weights' effective sample size says how good a screen the coarse mesh was).
"""

from __future__ import annotations

import math

import numpy as np

from fracid.inverse.core.sensitivity import evaluate_points
from fracid.inverse.sampling.levels import Levels, resample_index, subset_probabilities
from fracid.inverse.sampling.posterior import ess_floor, ess_status, log_likelihood, posterior
from fracid.inverse.sampling.posterior_result import PosteriorResult

__all__ = ["COARSE_ESS", "COARSE_ROUND", "COARSE_SHARE", "MAX_COARSE_ESS", "MAX_DRAWS", "POOR_SCREEN", "screened_posterior"]

#: the coarse level samples to this multiple of ``target_ess`` (its error is then a small part of the total)
COARSE_ESS = 2.5
#: a coarse round draws this multiple of ``samples_per_round`` (coarse runs cost a fraction of a fine run)
COARSE_ROUND = 4
#: above this spread of the fine / coarse likelihood ratio (E_c[r^2] / E_c[r]^2), the coarse mesh screened poorly:
#: its draws carry the fine estimate with an efficiency below 1 / POOR_SCREEN
POOR_SCREEN = 3.0
#: the subset's draws at most, as a multiple of ``fine_runs`` (a draw picked again costs no run)
MAX_DRAWS = 4
#: the coarse level's own error may take at most 1 / COARSE_SHARE of the target's variance: after the first fine
#: round, a coarse level that would take more is sampled further (once), to the effective sample size it needs
COARSE_SHARE = 2.0
#: ... to at most this multiple of ``target_ess``
MAX_COARSE_ESS = 20.0


def _normalisation(C, m: int) -> float:
    """1/2 log det(2 pi C) of an m x m covariance: what a Gaussian likelihood's log loses to its normalisation."""
    return 0.5 * (m * np.log(2.0 * np.pi) + C.logdet())


def screened_posterior(fine, coarse, y_exp, C_fine, C_coarse, shift, space, x0, C0, *, settings, executor=None,
                       progress=None, log=None) -> PosteriorResult:
    """The fine model's posterior by coarse-mesh screening and fine-mesh correction (module docstring).

    Parameters
    ----------
    fine, coarse : StoredOperator or callable
        The forward operators on the fine (the configured) and the coarse mesh.
    y_exp : ndarray, shape (m,)
    C_fine, C_coarse : Covariance
        The data covariance, and the one widened by the coarse mesh's error.
    shift : ndarray, shape (m,)
        y_coarse - y_fine at the estimate: subtracted from every coarse run's values.
    space, x0, C0, settings, executor, progress, log
        As :func:`~fracid.inverse.sampling.posterior.posterior`; ``settings.fine_runs`` bounds the fine runs.

    Returns
    -------
    PosteriorResult
        Its draws are the fine runs with their exact weights (plots, the predictive band's runs, the CSV); its
        statistics (mean, covariance, quantiles, predictive band) are the two-level estimator's (``levels``); its
        ``ess`` the smallest number of equivalent independent draws.
    """
    y_exp, shift = np.asarray(y_exp, float), np.asarray(shift, float)
    most = COARSE_ROUND * settings.samples_per_round * settings.max_rounds
    report = None if progress is None else (lambda done, _: progress(done, most + settings.fine_runs))
    coarse_log = None if log is None else (lambda text: log(f"coarse mesh: {text}"))

    def coarse_level(target):
        # the same seed draws the same first rounds: a larger target replays them from the store and goes on
        coarse_settings = settings.replace(target_ess=target, samples_per_round=COARSE_ROUND * settings.samples_per_round)
        return posterior(coarse, y_exp + shift, C_coarse, space, x0, C0, settings=coarse_settings, executor=executor,
                         log=coarse_log, progress=report)

    first = coarse_level(COARSE_ESS * settings.target_ess)
    fine_level = _FineLevel(fine, y_exp, C_fine, C_coarse, shift, settings, executor, progress, log)
    outcome = fine_level.run(first, extend=True)
    if outcome == "extend":  # the coarse level limits the precision: more coarse draws, a new subset
        first = coarse_level(fine_level.needed_coarse_ess)
        outcome = fine_level.run(first, extend=False)
    levels = fine_level.levels
    if outcome == "poor" or float(np.min(levels.equivalent_draws())) < ess_floor(settings.target_ess):
        return _fine_alone(fine, y_exp, C_fine, space, x0, C0, settings, executor, progress, log, levels)
    if progress is not None:
        progress(len(first.x) + levels.fine_runs, len(first.x) + levels.fine_runs)
    return _result(levels, fine_level.loglik, first, space, y_exp, C_fine, x0, C0, settings,
                   [*first.history, *fine_level.history])


class _FineLevel:
    """The fine runs at a subset of the coarse draws, in rounds, and the two-level estimator they give."""

    def __init__(self, fine, y_exp, C_fine, C_coarse, shift, settings, executor, progress, log):
        self.fine, self.y_exp, self.C_fine, self.C_coarse, self.shift = fine, y_exp, C_fine, C_coarse, shift
        self.settings, self.executor, self.progress, self.log = settings, executor, progress, log
        self.levels, self.loglik, self.history, self.needed_coarse_ess = None, np.empty(0), [], 0.0

    def run(self, first, *, extend: bool) -> str:
        """Fine rounds on the coarse level ``first``: "done", "poor" (the coarse mesh screens poorly) or "extend"
        (after the first round, when the coarse level's own error would keep the target out of reach)."""
        settings, m = self.settings, self.y_exp.size
        log_c = first.log_likelihood - _normalisation(self.C_coarse, m)
        rng = np.random.default_rng(settings.seed + 1)
        pick = subset_probabilities(first.weights)
        index, loglik, y_fine, self.history = [], [], [], []
        while len(set(index)) < settings.fine_runs and len(index) < MAX_DRAWS * settings.fine_runs:
            picked = resample_index(pick, min(settings.samples_per_round, settings.fine_runs - len(set(index))), rng)
            ll, y = log_likelihood(evaluate_points(self.fine, first.x[picked], None, self.executor), self.y_exp,
                                    self.C_fine)
            index.extend(picked.tolist())
            loglik.extend(ll.tolist())
            y_fine.extend(y.tolist())
            log_ratio = np.array(loglik) - _normalisation(self.C_fine, m) - log_c[index]
            levels = Levels(first.x, first.weights, first.y - self.shift, np.array(index), log_ratio, np.array(y_fine),
                            first.log_evidence, first.log_evidence_error, pick)
            self.levels, self.loglik = levels, np.array(loglik)
            equivalent = float(np.min(levels.equivalent_draws()))
            self.history.append({"round": 0, "draws": len(picked), "failed": int(np.sum(~np.isfinite(ll))),
                                 "ess": equivalent, "components": 0, "level": "fine"})
            self._said(first, levels, equivalent)
            if levels.spread > POOR_SCREEN:
                return "poor"
            if equivalent >= settings.target_ess:
                return "done"
            coarse_bound = float(np.min(levels.coarse_equivalent_draws()))
            if extend and coarse_bound < COARSE_SHARE * settings.target_ess:
                needed = levels.coarse_ess * COARSE_SHARE * settings.target_ess / max(coarse_bound, 1e-9)
                self.needed_coarse_ess = math.ceil(min(needed, MAX_COARSE_ESS * settings.target_ess))
                return "extend"
            # after the extension, more fine runs still shrink the correction's error: go on to fine_runs
        return "done"

    def _said(self, first, levels, equivalent):
        if self.progress is not None:
            self.progress(len(first.x) + levels.fine_runs, len(first.x) + self.settings.fine_runs)
        if self.log is not None:
            self.log(f"fine mesh: {levels.fine_runs} runs, equivalent draws {equivalent:.0f} (target "
                     f"{self.settings.target_ess:g}), fine/coarse likelihood ratio's spread {levels.spread:.2f}")


def _fine_alone(fine, y_exp, C_fine, space, x0, C0, settings, executor, progress, log, levels) -> PosteriorResult:
    """Single-level sampling on the fine mesh, when the first fine runs show that the coarse mesh screens poorly
    (the coarse posterior is far from the fine one: correcting it would cost more fine runs than sampling anew)."""
    if levels.spread > POOR_SCREEN:
        why = (f"the coarse mesh screened poorly (the spread of the fine / coarse likelihood ratio is "
               f"{levels.spread:.3g} > {POOR_SCREEN:g} after {levels.fine_runs} fine runs): every draw is a fine run")
    else:
        why = (f"the two levels gave only {float(np.min(levels.equivalent_draws())):.0f} equivalent draws after "
               f"{levels.fine_runs} fine runs, below the floor {ess_floor(settings.target_ess):g}: every draw is a "
               "fine run")
    if log is not None:
        log(f"posterior: {why}")
    result = posterior(fine, y_exp, C_fine, space, x0, C0, settings=settings, executor=executor, log=log,
                       progress=progress)
    result.notes = [why]
    return result


def _result(levels: Levels, loglik, first, space, y_exp, C_fine, x0, C0, settings, history) -> PosteriorResult:
    """The result: the fine runs with their weights, the two-level statistics, the status of the two levels."""
    rho = levels.rho
    equivalent = float(np.min(levels.equivalent_draws())) if rho.any() else 0.0
    failed = int(np.sum(~np.isfinite(levels.log_ratio)))
    status = ess_status(equivalent, settings, len(levels.index), len(history))
    if levels.spread > POOR_SCREEN and not status.startswith("failed"):
        status = (f"equivalent draws {equivalent:.0f}, but the coarse mesh screened poorly: the spread of the fine / "
                  f"coarse likelihood ratio is {levels.spread:.2g} (> {POOR_SCREEN:g}), so the stated errors rest on "
                  "few fine runs and the intervals are rough; screen on a finer mesh ([posterior] screening nearer 1) "
                  "or turn screening off (1)")
    log_z, log_z_error = levels.log_evidence()
    result = PosteriorResult(list(space.names), levels.x[levels.index], rho, loglik, levels.y_fine, y_exp,
                             C_fine.std(), equivalent, len(history), failed + first.failed, np.asarray(x0, float),
                             np.asarray(C0, float), (space.lower, space.upper), log=tuple(space.log), status=status,
                             history=history, log_evidence=float(log_z), log_evidence_error=float(log_z_error))
    result.levels = levels
    return result


def screening_setup(evaluate, data, x0, control, C_exp, settings, *, executor=None):
    """What screening needs, or why it cannot screen: (coarse operator, shift, widened covariance, the coarse
    mesh in words), or a sentence.

    The coarse operator is ``evaluate``'s with every specimen ``settings.screening`` times coarser, through the same
    run store (label "screening"); the shift y_coarse - y_fine and the widening come from one run of each at
    ``x0`` (the fine one is the identification's, reused from the store); ``control`` holds the control value of
    every datum (the widening's correlation runs along it).
    """
    from fracid.inverse.core.runs import StoredOperator
    from fracid.inverse.likelihood.discretisation import refined_operator
    from fracid.inverse.likelihood.record import widened
    from fracid.inverse.likelihood.settings import DiscretisationError

    if not isinstance(evaluate, StoredOperator):
        return "the forward operator is not a stored one (no mesh to coarsen)"
    try:
        coarse = StoredOperator(refined_operator(evaluate.operator, 1.0 / settings.screening), evaluate.store,
                                study="screening", retry_failed=evaluate.retry_failed)
    except ValueError as exc:
        return f"the mesh cannot be coarsened ({exc})"
    fine_run, coarse_run = (op.evaluate_many([np.asarray(x0, float)], None, executor)[0] for op in (evaluate, coarse))
    if not (fine_run.ok and coarse_run.ok):
        failed = fine_run if not fine_run.ok else coarse_run
        return f"a run at the estimate failed on the {'fine' if failed is fine_run else 'coarse'} mesh: {failed.error}"
    shift = np.asarray(coarse_run.y, float) - np.asarray(fine_run.y, float)
    C_coarse, _ = widened(C_exp, list(data.blocks), np.asarray(control, float), error=shift,
                          length=DiscretisationError().correlation_length)
    text = coarse.operator.observations[0].specimen.resolution().text
    return coarse, shift, C_coarse, text
