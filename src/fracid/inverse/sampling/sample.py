"""The posterior of an identification's parameters given its data: single-level sampling on the configured mesh
(:func:`~fracid.inverse.sampling.posterior.posterior`) or, where the mesh can be coarsened, coarse-mesh screening
corrected by fine runs (:func:`~fracid.inverse.sampling.screened.screened_posterior`); what ``fracid posterior``,
``fracid compare`` and the study's posterior stage call (:func:`sample_posterior`)."""

from __future__ import annotations

import numpy as np

from fracid.inverse.sampling.posterior import posterior
from fracid.inverse.sampling.screened import COARSE_ROUND, screened_posterior, screening_setup

__all__ = ["sample_posterior"]


def sample_posterior(evaluate, data, space, identification, settings, *, executor=None, progress=None, log=None):
    """The posterior of the identified parameters given ``data``, started from the identification's Gaussian.

    Parameters
    ----------
    evaluate : StoredOperator or callable
        The forward operator (through the run store: every draw is stored and reused by a rerun).
    data : ExperimentalData
        Measured values ``y`` and their ``covariance``.
    space : ParameterSpace
        Names and bounds: the prior is uniform (log-uniform where configured) between the bounds.
    identification : IdentificationResult
        Its ``x`` and ``C`` seed the sampler; its ``units`` label the result.
    settings : PosteriorSettings
    executor : Executor, optional
    progress : bool or None
        Progress bar: None on a terminal only, False never.
    log : callable, optional
        ``log(text)``: a line before the sampler starts and one per round.

    Returns and raises as :func:`posterior`; the result carries the identification's units. With the
    identification's error terms (``error_terms``), the likelihood is theirs: the data covariance with the mesh's
    error, and the model error's std integrated out per draw (:func:`~fracid.inverse.likelihood.record.
    error_likelihood`).
    """
    from fracid.inverse.likelihood.record import error_likelihood
    from fracid.runtime.progress import batch_progress, progress_bar

    C_exp, marginal = data.covariance, None
    if getattr(identification, "error_terms", None):
        control = identification.control if identification.control is not None else np.arange(data.y.size)
        C_exp, marginal = error_likelihood(identification.error_terms, data.covariance, data.y, control,
                                           identification.quantities)
    setup, notes = _screening(evaluate, data, identification, C_exp, marginal, settings, executor)
    if not isinstance(setup, str):
        coarse, shift, C_coarse, mesh = setup
        if log is not None:
            log(f"posterior: screened on a mesh {settings.screening:g} times coarser ({mesh}) and corrected by at most "
                f"{settings.fine_runs} fine runs, until the posterior means are as precise as {settings.target_ess:g} "
                "independent draws ([posterior] screening, fine_runs, target_ess)")
        most = COARSE_ROUND * settings.samples_per_round * settings.max_rounds + settings.fine_runs
        with progress_bar(most, "posterior (coarse and fine runs)", progress) as bar:
            result = screened_posterior(evaluate, coarse, data.y, C_exp, C_coarse, shift, space, identification.x,
                                        identification.C, settings=settings, executor=executor,
                                        progress=batch_progress(bar), log=log)
    else:
        total = settings.samples_per_round * settings.max_rounds
        if log is not None:
            log(f"posterior: at most {total} forward runs ({settings.max_rounds} rounds of "
                f"{settings.samples_per_round}), until the effective sample size reaches {settings.target_ess:g} "
                "([posterior] settings)")
        with progress_bar(total, "posterior", progress) as bar:
            result = posterior(evaluate, data.y, C_exp, space, identification.x, identification.C, settings=settings,
                               executor=executor, progress=batch_progress(bar), log=log, marginal=marginal)
    result.notes = [*notes, *getattr(result, "notes", [])]
    result.units = dict(identification.units or {})
    result.std_exp = data.covariance.std()  # the measurement's, as the identification's std_exp
    return result


def _screening(evaluate, data, identification, C_exp, marginal, settings, executor):
    """(the screening's setup or why not, the notes to keep): screening asked (``settings.screening`` > 1) but not
    possible is said, never silent."""
    if settings.screening <= 1.0:
        return "off", []
    if marginal is not None:
        why = "the model error is marginalised per draw (screening does not carry it yet)"
    else:
        control = getattr(identification, "control", None)
        control = control if control is not None else np.arange(data.y.size)
        why = screening_setup(evaluate, data, identification.x, control, C_exp, settings, executor=executor)
    if not isinstance(why, str):
        return why, []
    return why, [f"no coarse-mesh screening ([posterior] screening = {settings.screening:g}): {why}; every draw is a "
                 "fine run"]
