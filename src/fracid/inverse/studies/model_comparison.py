"""Models compared on the same data by their evidence: each identified with its own parameters and bounds, its
posterior sampled on the exact model, and the models ranked by log evidence.

Per model (a :class:`Contender`: a label, its forward operator on the data's observations and its parameter
space):

1. the identification (:func:`fracid.inverse.methods.strategy.identify_data`, the given inverse method);
2. the sensitivities at the estimate (one run with exact derivatives, or central differences): the Laplace
   approximation of the log evidence (:mod:`fracid.inverse.studies.evidence`);
3. the posterior by adaptive importance sampling from the identification's Gaussian
   (:func:`fracid.inverse.sampling.sample.sample_posterior`): the log evidence and its Monte-Carlo error from
   the importance weights, and the verdict per parameter on its credible intervals
   (:func:`fracid.inverse.studies.verdict.parameter_verdicts`; on the Gaussian when the sampling failed).

4. the prior sensitivity: the log evidence with every prior span widened by ``widen``
   (:func:`~fracid.inverse.studies.evidence.widened`, clipped to the parameters' valid ranges) by the closed form
   log Z - log(volume ratio) (:func:`~fracid.inverse.studies.evidence.prior_volume_shift`), with the posterior's
   weight at the bounds that makes it a lower bound. The log evidence is ranked only when the posterior's
   effective sample size reaches the sampler's floor (:attr:`ModelScore.estimated`).

Besides: the RMS misfit [% of the measured peak], the MAP objective of the method (chi^2 plus the term of the
prior its search gave, the objective its local fit minimises), the chi^2, AIC and BIC. The models run side by side
(:func:`fracid.runtime.executors.concurrently`: a thread per model submitting its forward runs to the shared executor)
and every run goes through the run store (the identification's stages under their own labels, the posterior
and the Laplace run under ``compare:<label>``; the keys hold the model, so models never share a run and a
rerun computes nothing). A model that fails is recorded with its reason and the others go on.

Example
-------
>>> from fracid.inverse.studies.model_comparison import compare, contender
>>> from fracid.inverse.studies.model_fit import Candidate
>>> result = compare(data, [contender(Candidate("cohesive", CohesiveCrackModel(), base, ("ft", "Gf"), space),
...                                   data, beam)], posterior=PosteriorSettings(samples_per_round=40))  # doctest: +SKIP
>>> print(result.summary())                                                                           # doctest: +SKIP
"""

from __future__ import annotations

import time
from concurrent.futures import BrokenExecutor
from dataclasses import asdict, dataclass

import numpy as np

from fracid.data.covariance_matrix import as_covariance
from fracid.inverse.core.runs import StoredOperator
from fracid.inverse.core.sensitivity import exact_sensitivity
from fracid.inverse.core.space import ParameterSpace
from fracid.inverse.methods.registry import DEFAULT_METHOD
from fracid.inverse.methods.strategy import identify_data
from fracid.inverse.sampling.posterior import PosteriorSettings
from fracid.inverse.sampling.sample import sample_posterior
from fracid.inverse.studies import evidence
from fracid.inverse.studies.comparison_result import ComparisonResult, ModelScore, map_objective
from fracid.inverse.studies.model_fit import candidate_operator
from fracid.inverse.studies.study_result import describe_data
from fracid.inverse.studies.uniqueness import bounds_covariance
from fracid.inverse.studies.verdict import parameter_verdicts
from fracid.runtime.executors import concurrently

__all__ = ["MODEL_FAILURES", "ComparisonResult", "Contender", "ModelScore", "compare", "contender"]

#: the failures of one model that end its comparison, not the others' (a bad forward run, a fit that
#: gave nothing finite); storage errors, interrupts and bugs elsewhere still stop everything
MODEL_FAILURES = (ArithmeticError, RuntimeError, ValueError, np.linalg.LinAlgError)


@dataclass(frozen=True)
class Contender:
    """One model of a comparison.

    Parameters
    ----------
    label : str
        Names the model in tables, figures and the run store (unique in a comparison).
    operator : ForwardOperator
        The model on the data's observations (its ``names`` those of ``space``).
    space : ParameterSpace
        Its identified parameters' bounds and log flags: the prior of its evidence.
    """

    label: str
    operator: object
    space: ParameterSpace


def contender(candidate, data, specimen=None, *, control="cmod", steps=None) -> Contender:
    """The :class:`Contender` of a :class:`~fracid.inverse.studies.model_fit.Candidate` on force data (one force
    observation per data block on its specimen, :func:`~fracid.inverse.studies.model_fit.candidate_operator`)."""
    return Contender(candidate.label, candidate_operator(data, candidate, specimen, control=control, steps=steps),
                     candidate.space)


def compare(data, contenders, *, method=None, posterior: PosteriorSettings = PosteriorSettings(), executor=None,
            store=None, progress=False, log=None, retry_failed=False, tolerance=0.1,
            widen: float = evidence.PRIOR_WIDENING, **settings) -> ComparisonResult:
    """Identify every model on ``data``, sample its posterior and rank the models by log evidence.

    Parameters
    ----------
    data : ExperimentalData
        The measured values and their covariance (:mod:`fracid.data`), the same for every model.
    contenders : sequence of Contender
        The models (labels unique).
    method : InverseMethod, str or None
        The inverse method of every identification (None: the registry's default, :data:`~fracid.inverse.methods.registry.DEFAULT_METHOD`).
    posterior : PosteriorSettings
        The sampler's settings, the same for every model.
    executor, store
        The shared executor of the forward runs and the run store.
    progress : bool or None
        Progress bars of the identifications and samplers (False: none; several models run at once).
    log : callable, optional
        ``log(text)``: a line per model and stage, ``"<label>: <stage>"``; the last ``"<label>: done: ..."`` or
        ``"<label>: failed (...)"`` (:class:`fracid.runtime.progress.StageLines` reads them).
    retry_failed : bool
        Run again the runs stored as failed.
    tolerance : float
        Largest relative std a verdict calls identified (:func:`~fracid.inverse.studies.verdict.parameter_verdicts`).
    widen : float
        The factor (>= 1) on every prior span of the prior sensitivity (module docstring).
    **settings
        Settings of the inverse method by name (``n``, ``k``, ``groups``, ...).

    Returns
    -------
    ComparisonResult
        The scores ranked by log evidence, the failures by label, the settings.
    """
    contenders = list(contenders)
    labels = [c.label for c in contenders]
    if len(set(labels)) != len(labels):
        raise ValueError(f"the contenders' labels must be unique, got {labels}")
    job = dict(method=method, posterior=posterior, executor=executor, store=store, progress=progress,
               log=log or (lambda text: None), retry_failed=retry_failed, tolerance=tolerance, widen=widen,
               settings=settings)
    outcomes = concurrently(lambda c: _attempt(data, c, job), contenders, executor)
    scores = [o for o in outcomes if isinstance(o, ModelScore)]
    failures = {c.label: o for c, o in zip(contenders, outcomes) if isinstance(o, str)}
    return ComparisonResult.ranked(data, scores, failures, {"posterior": asdict(posterior), "tolerance": tolerance,
                                                           "widen": widen, "method": getattr(method, "name", method) or DEFAULT_METHOD})


def _attempt(data, contender: Contender, job) -> "ModelScore | str":
    """The model's score, or why it failed (a line of text)."""
    try:
        return _score(data, contender, job)
    except BrokenExecutor:
        raise  # the pool is gone (a worker killed, out of memory): no model can go on
    except MODEL_FAILURES as err:
        reason = f"{type(err).__name__}: {err}"
        job["log"](f"{contender.label}: failed ({reason})")
        return reason


def _score(data, contender: Contender, job) -> ModelScore:
    start, label, say = time.perf_counter(), contender.label, job["log"]
    say(f"{label}: identifying {', '.join(contender.space.names)}")
    result = identify_data(contender.operator, data, contender.space, method=job["method"], executor=job["executor"],
                           store=job["store"], progress=job["progress"], retry_failed=job["retry_failed"],
                           **job["settings"])
    if not (np.all(np.isfinite(result.x)) and np.all(np.isfinite(result.C))):
        raise ArithmeticError(f"the identification gave no finite estimate and covariance ({result.status})")
    stored = StoredOperator(contender.operator, job["store"], study=f"compare:{label}", retry_failed=job["retry_failed"])
    chi2, log_l = _fit_likelihood(data, result)
    laplace = _laplace(stored, data, contender.space, result, log_l, job["executor"])
    say(f"{label}: {result.status}; RMS {result.rms_percent:.3g} %; sampling the posterior")
    post, post_error = _posterior(label, stored, data, contender.space, result, job)
    verdict = parameter_verdicts(contender.space.names, result.x, result.C, bounds_covariance(contender.space),
                                 data=describe_data(contender.operator), tolerance=job["tolerance"],
                                 posterior=post if post is not None and not post.sampling_failed else None)
    score = _numbers(label, contender, data, result, (chi2, log_l, laplace), post, post_error, verdict)
    score.log_evidence_wider, score.at_bounds = _sensitivity(contender, post, job["widen"])
    score.seconds = time.perf_counter() - start
    say(f"{label}: done: {score.line()}")
    return score


def _laplace(stored, data, space, result, log_l, executor) -> float:
    """The Laplace log evidence at the estimate (NaN when its run with sensitivities fails)."""
    evaluate, sensitivity = exact_sensitivity(stored)
    try:
        _, S, _ = sensitivity(evaluate, result.x, executor=executor)
    except MODEL_FAILURES:
        return float("nan")
    return evidence.laplace_log_evidence(log_l, result.x, S, as_covariance(data.covariance, data.y.size), space)


def _fit_likelihood(data, result) -> tuple[float, float]:
    """chi^2 of the fit at the estimate and the Gaussian log-likelihood there [-]."""
    C_exp = as_covariance(data.covariance, data.y.size)
    chi2 = float(C_exp.quadratic(np.asarray(result.y_fit, float) - data.y))
    return chi2, evidence.gaussian_log_likelihood(chi2, C_exp.logdet(), data.y.size)


def _posterior(label, stored, data, space, result, job):
    """The sampled posterior, or (None, why not) when every draw failed."""
    try:
        return sample_posterior(stored, data, space, result, job["posterior"], executor=job["executor"],
                                progress=job["progress"], log=lambda text: job["log"](f"{label}: {text}")), ""
    except MODEL_FAILURES as err:
        return None, f"{type(err).__name__}: {err}"


def _sensitivity(contender: Contender, post, factor: float) -> tuple[float, float]:
    """(log Z with every prior span times ``factor``, the posterior's weight at the bounds); NaN without a posterior."""
    if post is None:
        return float("nan"), float("nan")
    space = contender.space
    wider = evidence.widened(space, factor, contender.operator.valid_bounds())
    return (post.log_evidence + evidence.prior_volume_shift(space, wider),
            evidence.bound_share(space.to_unit(post.x), post.weights))


def _numbers(label, contender, data, result, fit, post, post_error, verdict) -> ModelScore:
    """The score of a model from its identification, ``fit`` = (chi^2, log L, Laplace log Z) and its posterior."""
    (chi2, log_l, laplace), n = fit, data.y.size
    aic, bic = evidence.information_criteria(log_l, len(contender.space.names), n)
    return ModelScore(
        label=label, model=contender.operator.model.key, names=list(contender.space.names), identification=result,
        posterior=post, verdict=verdict, n=n, chi2=chi2, map_objective=map_objective(result, chi2),
        log_likelihood=log_l, aic=aic, bic=bic, log_evidence_laplace=laplace,
        log_evidence=post.log_evidence if post is not None else float("nan"),
        log_evidence_error=post.log_evidence_error if post is not None else float("nan"),
        posterior_status=post.status if post is not None else f"not sampled: {post_error}",
        bounds=(contender.space.lower.tolist(), contender.space.upper.tolist()), log=list(contender.space.log))
