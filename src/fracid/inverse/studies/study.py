"""The identification strategy as one study (docs/theory.md, section 4.4), ending in a verdict per parameter.

The study runs the stages of an inverse method (:class:`~fracid.inverse.methods.registry.StudyMethod`; by default
the registry's :data:`~fracid.inverse.methods.registry.DEFAULT_METHOD`): its global search over a population (overview, prior) ->
sensitivity along the load history at the search's estimate (which stage of the test informs which
parameter) -> its local refinement -> uniqueness (valley of the objective over the population, measured
from the estimate and its objective) -> multi-start check (the local fit from distinct population
points) -> stability under noise (the local fit of noisy replicates) -> prediction of data not used for
calibration -> verdict. The sensitivities need a point, which is why they follow the search rather than
precede it; every other stage runs in the order of the thesis's strategy (docs/theory.md, section 4.4).

When asked (``StudySettings.posterior``), the posterior of the parameters is sampled on the exact model
(:func:`fracid.inverse.sampling.posterior.posterior`, started from the identification's Gaussian) after the checks
and predictions, its runs through the same run store under the label "posterior" (those of ``fracid
posterior`` in the same directory: either reuses the other's runs); the verdict then reads its 90 %
credible intervals instead of the Gaussian std (:mod:`fracid.inverse.studies.verdict`) and says so.
"""

from __future__ import annotations

import dataclasses
import time
from contextlib import contextmanager
from dataclasses import dataclass, field, replace

import numpy as np

from fracid.inverse.core.method import check_problem, identification_bounds
from fracid.inverse.core.method_settings import with_settings
from fracid.inverse.methods.registry import DEFAULT_METHOD, METHODS, StudyMethod
from fracid.inverse.sampling.posterior import PosteriorSettings
from fracid.inverse.sampling.sample import sample_posterior
from fracid.inverse.core.runs import StoredOperator
from fracid.inverse.likelihood.terms import Problem, with_error_terms
from fracid.inverse.core.sensitivity import ForwardRunError, exact_sensitivity, sensitivity_history
from fracid.inverse.studies.stability import stability as stability_check
from fracid.inverse.studies.study_result import Prediction, StudyResult, describe_data, estimate_objective, predict
from fracid.inverse.studies.uniqueness import bounds_covariance, multi_start, objective_maps, starting_points, valley_extent
from fracid.inverse.studies.verdict import parameter_verdicts


#: the values of ``StudySettings.prior``: the search's own prior covariance, or the bounds' uniform one
PRIORS = ("search", "bounds")


@dataclass(frozen=True)
class StudySettings:
    """What :func:`run_study` computes. Execution (executor, store, progress, log) is not a setting.

    Attributes
    ----------
    method : StudyMethod
        The inverse method whose stages the study runs (:class:`~fracid.inverse.methods.registry.StudyMethod`;
        a key of :data:`~fracid.inverse.methods.registry.METHODS` is its class): its search gives the overview,
        the prior, the objective maps and the starting points of the multi-start check; its refinement
        the identification; its local fit (``fit_from``) every multi-start fit and every noisy replicate.
    prior : {"search", "bounds"}
        Covariance of the refinement's prior (mean: the search's estimate): the search's own (``"search"``: the
        spread of the points its prior is drawn from, the thesis's cascade, docs/theory.md, section 4.4), or the
        bounds' uniform covariance. The search ranked its points with the same data, so "bounds" keeps the
        posterior to what the data say, which comparisons of data sets (twin matrices) need.
    starts : int
        Starting points of the multi-start check (0 or 1: skipped).
    replicates : int
        Noisy replicates of the stability check (0: skipped).
    noise_seed : int
        Seed of the replicates' noise.
    tolerance : float
        Largest relative standard deviation std / ``|estimate|`` called identified [-] (0.1: 10 %).
    posterior : PosteriorSettings or None
        Sample the posterior on the exact model with these settings after the checks, and give the
        verdict from its 90 % credible intervals; None (default): no posterior, the verdict from the
        Gaussian std.
    error_terms : ErrorTerms or None
        The mesh's discretisation error and the model's own error added to the data covariance of the
        refinement (:func:`fracid.inverse.likelihood.terms.with_error_terms`: refined from the same population
        with them, to a fixed point); the verdict and the posterior read the widened result, the multi-start
        and stability checks keep the measurement covariance. None (default): none.
    """

    method: object = field(default_factory=lambda: METHODS[DEFAULT_METHOD]())
    prior: str = "search"
    starts: int = 3
    replicates: int = 5
    noise_seed: int = 0
    tolerance: float = 0.1
    posterior: PosteriorSettings | None = None
    error_terms: object = None

    def __post_init__(self):
        if self.prior == "knn":
            raise ValueError("prior = 'knn' is now called 'search' (the prior the method's search gives); choose "
                             "'search' or 'bounds'")
        if self.prior not in PRIORS:
            raise ValueError(f"prior = {self.prior!r}; choose 'search' or 'bounds'")
        if self.posterior is not None and not isinstance(self.posterior, PosteriorSettings):
            raise TypeError(f"posterior = {self.posterior!r}: give PosteriorSettings(...) or None")
        if not isinstance(self.method, StudyMethod):
            raise TypeError(f"method = {self.method!r}: a study runs the stages of an inverse method with search, "
                            "refine and fit_from (fracid.inverse.methods.registry.StudyMethod), e.g. one of "
                            f"{', '.join(f'{cls.__name__}()' for cls in METHODS.values())}")

    @property
    def identification(self):
        """The inverse method of the identification (``method``)."""
        return self.method

    def replace(self, **changes) -> StudySettings:
        """A copy with ``changes``: fields of this class, fields of the method or fields of the method's
        settings by their own names (:func:`~fracid.inverse.core.method_settings.with_settings`: ``n``, ``k``,
        ``groups``, ``max_iterations``, ... as the method has them).

        Raises
        ------
        TypeError
            For a name that is none of these.
        """
        own = {f.name for f in dataclasses.fields(self)}
        mine = {name: changes.pop(name) for name in list(changes) if name in own}
        try:
            method = with_settings(mine.pop("method", self.method), **changes)
        except TypeError as err:
            raise TypeError(f"{err} (or a study setting: {', '.join(sorted(own))})") from None
        return replace(self, method=method, **mine)


def run_study(operator, data, space, settings: StudySettings = StudySettings(), *, held_out=(), executor=None,
              store=None, progress=None, log=None, retry_failed=False) -> StudyResult:
    """Run the stages of the settings' inverse method with the study's checks and return the verdict.

    Parameters
    ----------
    operator : ForwardOperator
        Computes the calibration data.
    data : ExperimentalData
        Calibration data; its blocks line up with the operator's observations.
    space : ParameterSpace
        Bounds of the population; also the prior of the multi-start fits and the reference of
        the variance removed.
    settings : StudySettings
        The inverse method and the checks to make (``StudySettings().replace(n=32, starts=0)``).
    held_out : sequence of (ForwardOperator, ExperimentalData)
        Data not used for calibration, predicted at the estimate.
    executor, store
        Parallel execution and the persistent run store.
    progress : None, bool
        Progress bars (None: on a terminal).
    log : callable(str), optional
        Receives one line per stage (the command line prints them); silent if None.
    retry_failed : bool
        Run again the runs stored as failed.

    Every forward run goes through ``store`` (when given). A failed forward run never ends the
    study: the stage that met it records it (``StudyResult.runs`` counts the failures of every stage,
    ``notes`` says which checks could not be made). The same holds for the posterior
    (``settings.posterior``): when it cannot be sampled, a note says why and the verdict reads the
    Gaussian std.
    """
    if data.y.size != operator.n_outputs:
        raise ValueError(f"the data hold {data.y.size} values but the observations compute {operator.n_outputs}")
    check_problem(operator, data.y, data.covariance, space)
    study = _Stages(log)
    y, C, method = data.y, data.covariance, settings.method
    search_label, _ = _stage_labels(method)
    C_bounds = bounds_covariance(space)
    # every run after the population carries its sensitivities where the model has them: one stored
    # operator (and its counters) for all stages
    evaluate, _ = exact_sensitivity(StoredOperator(operator, store, retry_failed=retry_failed))
    overview, C0, history, ident = _identification(study, operator, evaluate, data, space, settings, C_bounds,
                                                   executor=executor, store=store, progress=progress,
                                                   retry_failed=retry_failed)
    centre = estimate_objective(ident, y, C)
    maps, extent = objective_maps(overview, centre=centre), valley_extent(overview, centre=centre)
    fit = _local_fit(method, data.blocks)
    bounds = identification_bounds(operator, space)
    ms = _multi_start_check(study, settings, overview, evaluate, y, C, C_bounds, bounds, fit, executor, progress)
    st = _stability_check(study, settings, overview, evaluate, y, C, C0, bounds, fit, executor, progress)
    predictions = [_prediction(study, op, held, ident, executor) for op, held in held_out]
    if held_out:
        study.stage("prediction")
    post = None
    if settings.posterior is not None:
        post = _posterior_stage(operator, data, space, ident, settings.posterior, store=store, executor=executor,
                                progress=progress, log=study.log, retry_failed=retry_failed, runs=study.runs,
                                notes=study.notes)
        study.stage("posterior")
    total, failed = study.runs[search_label]
    if failed:
        study.notes.insert(0, f"{failed} of {total} {search_label} runs failed (they rank last; see population.csv)")
    usable = None if post is None or post.sampling_failed else post  # below the ESS floor: no intervals
    verdict = parameter_verdicts(space.names, ident.x, ident.C, C_bounds, data=describe_data(operator),
                                 tolerance=settings.tolerance, multi_start=ms, stability=st, posterior=usable,
                                 error_terms=getattr(ident, "error_terms", None))
    return StudyResult(ident, history, maps, extent, ms, st, predictions, verdict, study.timings, study.runs,
                       study.notes, posterior=post)


def _identification(study, operator, evaluate, data, space, settings, C_bounds, *, executor, store, progress,
                    retry_failed):
    """The method's search, the sensitivity at its estimate and the refinement from its prior (with the error
    terms when asked): ``(overview, C0, sensitivity history, identification)``."""
    y, C, method = data.y, data.covariance, settings.method
    search_label, refine_label = _stage_labels(method)
    study.log(f"{search_label}: population search")
    overview = method.search(operator, y, C, space, executor=executor, store=store, progress=progress,
                             retry_failed=retry_failed)
    study.runs[search_label] = (len(overview.points), overview.n_failed)
    study.stage("search")
    C0 = overview.C0 if settings.prior == "search" else C_bounds
    history = _sensitivity_stage(study, evaluate, overview, data, C_bounds, space, search_label, executor)
    with study.counting(refine_label, evaluate, f"{refine_label} from the {search_label} prior"):
        ident = method.refine(evaluate, y, C, overview, executor=executor, blocks=list(data.blocks),
                              notes=list(data.notes), C0=C0, progress=progress)
    if settings.error_terms is not None:
        with study.counting("error terms", evaluate, "error terms: the refinement again with them"):
            def fit(inverse, covariance):
                return inverse.refine(evaluate, y, covariance, overview, executor=executor, blocks=list(data.blocks),
                                      notes=list(data.notes), C0=C0, progress=progress)

            ident = with_error_terms(method, fit, Problem.of(operator, y, C, space, data.blocks), settings.error_terms,
                                     ident, store=store, executor=executor, retry_failed=retry_failed)
    return overview, C0, history, ident


def _sensitivity_stage(study, evaluate, overview, data, C_bounds, space, search_label, executor):
    """The sensitivity along the load history at the search's estimate (None, with a note, when a run fails)."""
    history = None
    with study.counting("sensitivity", evaluate, f"sensitivity along the load history at the {search_label} estimate"):
        try:
            history = sensitivity_history(evaluate, overview.x0, data.covariance, C_bounds, names=space.names,
                                          blocks=data.blocks, executor=executor)
        except ForwardRunError as err:
            study.notes.append(f"sensitivity history skipped: {err}")
    return history


def _stage_labels(method) -> tuple[str, str]:
    """Labels of the method's first (search) and last (refinement) stages (its ``stages``; its name without)."""
    labels = list(dict(method.stages).values()) or [method.name]
    return labels[0], labels[-1]


def _local_fit(method, blocks):
    """The method's local fit from a prior, with the data's blocks (a multi-start fit, a replicate)."""
    def fit(evaluate, y, C, x0, C0, *, bounds=None, executor=None):
        return method.fit_from(evaluate, y, C, x0, C0, bounds=bounds, executor=executor, blocks=list(blocks))

    return fit


class _Stages:
    """The study's clock, forward-run counters and notes, stage by stage."""

    def __init__(self, log):
        self.log = log or (lambda text: None)
        self.timings, self.runs, self.notes = {}, {}, []
        self.clock = time.perf_counter()

    def stage(self, name):
        now = time.perf_counter()
        self.timings[name] = now - self.clock
        self.clock = now

    @contextmanager
    def counting(self, name, evaluate, line=None):
        """Log ``line``, then count the runs of ``evaluate`` (total, failed) and the time of the block as ``name``."""
        if line:
            self.log(line)
        mark = (evaluate.computed + evaluate.reused, evaluate.failed)
        yield
        self.runs[name] = (evaluate.computed + evaluate.reused - mark[0], evaluate.failed - mark[1])
        self.stage(name)


def _multi_start_check(study, settings, overview, evaluate, y, C, C_bounds, bounds, fit, executor, progress):
    """The local fit from distinct population points (None when skipped or impossible, with a note)."""
    if settings.starts <= 1:
        return None
    points = starting_points(overview, settings.starts)
    ms = None
    with study.counting("multi-start", evaluate, f"multi-start check from {len(points)} starting points"):
        if len(points) > 1:
            try:
                with stage_bar(progress, len(points), "multi-start fits") as tick:
                    ms = multi_start(evaluate, y, C, points, C_bounds, bounds=bounds, executor=executor,
                                     progress=tick, fit=fit)
            except ForwardRunError as err:
                study.notes.append(f"multi-start check skipped: {err}")
            if ms is not None and ms.failed:
                study.notes.append(f"multi-start: {len(ms.failed)} of {len(points)} fits failed")
    return ms


def _stability_check(study, settings, overview, evaluate, y, C, C0, bounds, fit, executor, progress):
    """The local fit of noisy replicates of the data from the search's prior (None when skipped)."""
    replicates = settings.replicates
    if not replicates:
        return None
    with study.counting("stability", evaluate, f"stability check: {replicates} noisy replicates"):
        with stage_bar(progress, replicates, "noisy replicates") as tick:
            st = stability_check(evaluate, y, C, overview.x0, C0, replicates=replicates, seed=settings.noise_seed,
                                 bounds=bounds, executor=executor, progress=tick, fit=fit)
        failed = sum(bool(e) for e in st.errors)
        if failed:
            study.notes.append(f"stability: {failed} of {replicates} replicates failed")
    return st


def _prediction(study, operator, held, ident, executor) -> Prediction:
    name = ", ".join(b[0] for b in held.blocks)
    study.log(f"prediction of {name}")
    return predict(operator, held, ident.x, ident.C, executor=executor, name=name)


def _posterior_stage(operator, data, space, ident, settings, *, store, executor, progress, log, retry_failed, runs,
                     notes):
    """The posterior sampled from the identification's Gaussian (runs stored under the label "posterior"),
    or None with a note when there is no finite Gaussian to start from or every run failed; a note too
    when its effective sample size is below the floor (the verdict then reads the Gaussian std)."""
    if not (np.all(np.isfinite(ident.x)) and np.all(np.isfinite(ident.C))):
        notes.append("posterior skipped: the identification gave no finite estimate and covariance to start the "
                     "sampler from; the verdict reads the Gaussian std")
        return None
    evaluate = StoredOperator(operator, store, study="posterior", retry_failed=retry_failed)
    try:
        post = sample_posterior(evaluate, data, space, ident, settings, executor=executor, progress=progress, log=log)
    except ForwardRunError as err:
        runs["posterior"] = (evaluate.computed + evaluate.reused, evaluate.failed)
        notes.append(f"posterior skipped: {err}; the verdict reads the Gaussian std")
        return None
    runs["posterior"] = (len(post.x), post.failed)
    if post.sampling_failed:
        notes.append(f"posterior {post.status}; the verdict reads the Gaussian std")
    elif not post.converged:
        notes.append(f"posterior: {post.status}")
    return post


@contextmanager
def stage_bar(progress, total, description):
    """A progress bar over the filters of a study stage; yields its ``progress(done, total)`` callable."""
    from fracid.runtime.progress import batch_progress, progress_bar

    with progress_bar(total, description, progress, unit="filter") as bar:
        yield batch_progress(bar)


__all__ = ["PRIORS", "Prediction", "StudyResult", "StudySettings", "describe_data", "estimate_objective", "predict", "run_study"]
