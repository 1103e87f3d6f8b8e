"""The default inverse method: KNN over a population, then the bounded step-by-step Kalman filter
(docs/theory.md, sections 4.2 to 4.4).

:class:`KnnKalman` meets :class:`~fracid.inverse.core.method.InverseMethod` and the study's
:class:`~fracid.inverse.methods.registry.StudyMethod` (``search``, ``refine``, ``fit_from``); its settings are
:class:`~fracid.inverse.methods.knn_settings.KnnSettings` and :class:`KalmanSettings`, which
:meth:`KnnKalman.from_config` reads (and checks) from the configuration's ``[identify.knn]`` and
``[identify.kalman]``.
"""

from __future__ import annotations

import time
from contextlib import contextmanager
from dataclasses import dataclass, field, replace
from typing import ClassVar

import numpy as np

from fracid.inverse.methods.kalman import kalman_filter
from fracid.inverse.methods.kalman_status import DEFAULT_MAX_STARTS, restarted
from fracid.inverse.methods.knn import knn_search
from fracid.inverse.methods.knn_settings import KnnSettings, knn_from_table, knn_template
from fracid.inverse.core.method import MethodResult, check_problem, identification_bounds, result_fields
from fracid.inverse.core.plans import StagePlan, plural, population_plan, runs_per_linearisation
from fracid.settings import checks as settings
from fracid.inverse.core.runs import StoredOperator
from fracid.inverse.core.sensitivity import exact_sensitivity, sensitivity_label
from fracid.settings.checks import SettingsContext, toml_line
from fracid.inverse.core.space import ParameterSpace
from fracid.runtime.batch import BatchStats


def _knn_kalman_stages() -> dict:
    return dict(KnnKalman.stages)


@dataclass
class IdentificationResult(MethodResult):
    """The result of :class:`KnnKalman`: a :class:`~fracid.inverse.core.method.MethodResult` with the
    records of its two stages.

    Attributes
    ----------
    history : list of dict
        Kalman estimate and covariance after every step of every global iteration.
    knn : dict
        Population, objective values, statuses, ranking, k, x0, C0.

    ``runs`` holds ``knn`` (population), ``knn_failed``, ``knn_computed``, ``knn_reused``,
    ``kalman`` (forward runs of the filter), ``kalman_failed``, ``kalman_computed``,
    ``kalman_reused``, ``kalman_run_equivalents``, ``kalman_iterations`` and ``wall_seconds`` [s].
    """

    history: list = field(default_factory=list)
    knn: dict = field(default_factory=dict)
    method: str = "knn-kalman"
    stages: dict = field(default_factory=_knn_kalman_stages)

    def failed_runs_text(self) -> str:
        runs = self.runs or {}
        return (f"{runs.get('knn_failed', 0)} of {runs.get('knn', 0)} KNN, "
                f"{runs.get('kalman_failed', 0)} in the Kalman stage")


#: Kalman steps per pass when [identify.kalman] groups is not given. A step costs one run (with exact
#: sensitivities) up to its observations: a few steps are as informative as one per observation and cost less
DEFAULT_GROUPS = 4


@dataclass(frozen=True)
class KalmanSettings:
    """The Kalman filter (:func:`~fracid.inverse.methods.kalman.kalman_filter`).

    Attributes
    ----------
    groups : None, sequence of index arrays, "blocks" or "all"
        The observation sequence: one observation per step (None), the given index arrays, one
        step per data block (``"blocks"``) or one step with every observation (``"all"``: the batch
        filter).
    max_iterations : int
        Global iterations (passes over the observations) at most.
    tol : float
        Convergence: no parameter moves by more than ``tol`` of its standard deviation [-].
    restart : {"linearize", "prior-mean"}
        How a global iteration starts again (see :func:`~fracid.inverse.methods.kalman.kalman_filter`).
    max_starts : int
        Starts of the filter at most: when it ends at a poor point from the KNN prior, it starts again
        from the next-best population points (:func:`~fracid.inverse.methods.kalman_status.restarted`). Not part
        of :meth:`options` (the filters of the study's checks start once).
    """

    groups: object = None
    max_iterations: int = 10
    tol: float = 0.01
    restart: str = "linearize"
    max_starts: int = DEFAULT_MAX_STARTS

    def options(self, n_y: int, blocks=()) -> dict:
        """Keyword arguments of :func:`~fracid.inverse.methods.kalman.kalman_filter` for ``n_y`` observations in
        ``blocks`` (``(name, start, stop)``; a named ``groups`` is resolved with them)."""
        return {"groups": named_groups(self.groups, n_y, blocks), "max_iterations": self.max_iterations,
                "tol": self.tol, "restart": self.restart}


#: the keys of ``[identify.kalman]`` and the values of its ``restart``
KALMAN_KEYS = ("groups", "max_iterations", "tol", "restart", "max_starts")
RESTARTS = ("linearize", "prior-mean")


def kalman_from_table(raw, n_y: int | None) -> KalmanSettings:
    """The :class:`KalmanSettings` of the table ``[identify.kalman]`` (``raw``, a dict; empty: the defaults),
    ``groups`` still a count (or None): ``1 <= groups <= n_y`` (the total data values, when known).

    Raises
    ------
    fracid.settings.checks.SettingError
        Naming ``kalman.<key>``, the value and what is allowed.
    """
    raw = settings.table("kalman", raw, KALMAN_KEYS)
    groups = None
    if "groups" in raw:
        top = n_y if n_y else None
        allowed = (f"must be an integer with 1 <= groups <= n_y = {top} (the total n_points of the experiments)"
                   if top else "must be an integer >= 1")
        groups = settings.integer("kalman.groups", raw["groups"], allowed, lambda v: v >= 1 and (top is None or v <= top))
    return KalmanSettings(
        groups=groups,
        max_iterations=settings.integer("kalman.max_iterations", raw.get("max_iterations", 10),
                                        "must be an integer >= 1", lambda v: v >= 1),
        tol=settings.number("kalman.tol", raw.get("tol", 0.01), "must be a number > 0 [standard deviations]",
                            lambda v: v > 0),
        restart=settings.choice("kalman.restart", raw.get("restart", "linearize"), RESTARTS),
        max_starts=settings.integer("kalman.max_starts", raw.get("max_starts", DEFAULT_MAX_STARTS),
                                    "must be an integer >= 1 (starts of the filter in all)", lambda v: v >= 1))


def named_groups(groups, n_y: int, blocks=()):
    """``groups`` as index arrays: ``"all"`` is one group of the ``n_y`` observations, ``"blocks"`` one per
    data block ``(name, start, stop)``; anything else is returned as it is."""
    if not isinstance(groups, str):
        return groups
    if groups == "all":
        return [np.arange(n_y)]
    if groups == "blocks":
        return [np.arange(start, stop) for _, start, stop in blocks or [("all", 0, n_y)]]
    raise ValueError(f"groups = {groups!r}; give index arrays, None, 'blocks' or 'all'")


@dataclass(frozen=True)
class KnnKalman:
    """The default inverse method: KNN over a population for a global overview and the prior, then
    the bounded step-by-step Kalman filter from that prior (the thesis's cascade, docs/theory.md, section 4.4).

    Its stages are ``"knn"`` and ``"kalman"`` (the keys of their counters in ``runs``); it returns an
    :class:`IdentificationResult`.

    Attributes
    ----------
    knn : KnnSettings
    kalman : KalmanSettings
    """

    knn: KnnSettings = KnnSettings()
    kalman: KalmanSettings = KalmanSettings()
    name: ClassVar[str] = "knn-kalman"
    stages: ClassVar[dict] = {"knn": "KNN", "kalman": "Kalman filter"}

    def search(self, operator, y_exp, C_exp, space: ParameterSpace, *, executor=None, store=None, progress=None,
               stats=None, retry_failed=False):
        """The KNN stage: a :class:`~fracid.inverse.methods.knn.KnnResult` (population, ranking, prior x0, C0)."""
        return population_search(self.knn, operator, y_exp, C_exp, space, executor=executor, store=store,
                                 progress=progress, stats=stats, retry_failed=retry_failed)

    #: the tables of [identify] this method reads (:meth:`from_config`)
    config_tables: ClassVar[tuple] = ("knn", "kalman")

    @classmethod
    def from_config(cls, tables: dict, context: SettingsContext) -> KnnKalman:
        """The method of the configuration's tables ``[identify.knn]`` (:func:`~fracid.inverse.methods.knn_settings.
        knn_from_table`) and ``[identify.kalman]`` (:func:`kalman_from_table`), ``tables`` by name (empty when
        absent). ``groups`` (a count) becomes that many consecutive index arrays over the ``context.n_y``
        observations, :data:`DEFAULT_GROUPS` when not given.

        Raises
        ------
        fracid.settings.checks.SettingError
            A key or value refused (named relative to ``[identify]``: ``kalman.groups``).
        """
        knn = knn_from_table(tables.get("knn", {}), context)
        kalman = kalman_from_table(tables.get("kalman", {}), context.n_y)
        n_y = max(int(context.n_y or 1), 1)
        count = kalman.groups if kalman.groups is not None else min(DEFAULT_GROUPS, n_y)
        groups = [np.asarray(g) for g in np.array_split(np.arange(n_y), count)]
        return cls(knn, replace(kalman, groups=groups))

    @classmethod
    def config_template(cls, tables: dict) -> list[str]:
        """The ``[identify.knn]`` and ``[identify.kalman]`` lines of a configuration ``fracid init`` writes,
        with the values of ``tables`` (by table name; a first run's where absent: n 32, k 5, groups 4)."""
        kalman = tables.get("kalman", {})
        return knn_template(tables.get("knn", {}), "the Kalman prior") + [
            "[identify.kalman]", toml_line("groups", kalman.get("groups", DEFAULT_GROUPS),
                                           "filter steps per pass (one run each with exact sensitivities)"),
            toml_line("max_iterations", kalman.get("max_iterations", 10), "passes at most")]

    def plan(self, operator, n_y: int, p: int) -> list[StagePlan]:
        """The forward runs of both stages (:class:`~fracid.inverse.core.plans.StagePlan`): the population side by
        side; the filter's steps one after another (a step of the first pass runs up to its observations, each
        later pass is one linearisation), at most ``max_iterations`` passes and a run at the estimate."""
        per_step, how = runs_per_linearisation(operator, p)
        groups = named_groups(self.kalman.groups, n_y)
        steps = n_y if groups is None else len(groups)
        passes = self.kalman.max_iterations
        later = (passes - 1) * per_step + per_step
        runs, full = steps * per_step + later, per_step * (steps + 1) / 2 + later
        text = (f"{steps} steps per pass, {plural(per_step, 'run')} per step ({how}), at most {passes} passes and a run at "
                f"the estimate: at most {runs} runs one after another without backtracking, about {full:.0f} "
                "full-curve runs")
        return [population_plan(self.knn, p), StagePlan("kalman", "Kalman filter", runs, False, full, text,
                                                        "[identify.kalman] groups and max_iterations", per_step == 1)]

    def fit_from(self, evaluate, y_exp, C_exp, x0, C0, *, bounds=None, executor=None, blocks=()):
        """The Kalman filter alone from the prior (x0, C0), started once (a multi-start filter or a noisy
        replicate of the study): a :class:`~fracid.inverse.methods.kalman.KalmanResult` (``x``, ``std``, ``y``,
        ``failed``, ``status``)."""
        return kalman_filter(evaluate, y_exp, C_exp, x0, C0, bounds=bounds, executor=executor,
                             **self.kalman.options(np.size(y_exp), blocks))

    def refine(self, operator, y_exp, C_exp, knn, *, C0=None, executor=None, blocks=(), notes=(), started=None,
               progress=False) -> IdentificationResult:
        """The Kalman stage from the prior of ``knn``: :func:`refine` with these settings."""
        return refine(operator, y_exp, C_exp, knn, executor=executor, blocks=blocks, notes=notes,
                      method=self.knn.method, seed=self.knn.seed, started=started, C0=C0, progress=progress,
                      max_starts=self.kalman.max_starts, **self.kalman.options(np.size(y_exp), blocks))

    def __call__(self, operator, y_exp, C_exp, space: ParameterSpace, *, executor=None, store=None, progress=None,
                 retry_failed=False, blocks=(), notes=()) -> IdentificationResult:
        """Both stages (see :class:`~fracid.inverse.core.method.InverseMethod`).

        Raises
        ------
        AllRunsFailed
            When fewer than k population runs succeeded. A failed run of the Kalman stage never
            raises: see :func:`refine`.
        """
        return search_then_refine(self, operator, y_exp, C_exp, space, executor=executor, store=store,
                                  progress=progress, retry_failed=retry_failed, blocks=blocks, notes=notes)


def refine(operator, y_exp, C_exp, knn, *, groups=None, max_iterations=10, tol=0.01, restart="linearize",
           executor=None, blocks=(), notes=(), method="", seed=0, started=None, C0=None,
           progress=False, max_starts=DEFAULT_MAX_STARTS) -> IdentificationResult:
    """The Kalman filter from the prior of a KNN search (x0, C0): the second stage of :class:`KnnKalman`.

    ``C0`` replaces the KNN covariance as the prior's (e.g. the bounds' covariance, so that the
    posterior holds the information of the data alone). ``operator`` may be a
    :class:`~fracid.inverse.core.runs.StoredOperator` (its runs are then stored and counted). ``method``
    and ``seed`` are the population's design, recorded in the result.

    When the filter from the KNN prior ends at a poor point, it starts again from the next-best population
    points, ``max_starts`` starts in all (:func:`~fracid.inverse.methods.kalman_status.restarted`: the status says
    how many were tried and which won; the winner's ``history``, the runs of all).

    The filter stays inside the KNN space's bounds and does not raise on failed forward runs. When
    it could not evaluate any estimate of its own (every run near its points failed), the result is
    the best point of the population, with the KNN prior covariance, and the status says so.
    """
    start = time.perf_counter() if started is None else started
    bounds = identification_bounds(operator, knn.space)
    C0 = knn.C0 if C0 is None else np.asarray(C0, float)
    evaluate, sensitivity = exact_sensitivity(operator)
    before = _counters(evaluate)
    with kalman_progress(progress, groups, y_exp.size, max_iterations) as callback:
        def run(x0):
            return kalman_filter(evaluate, y_exp, C_exp, x0, C0, groups=groups, max_iterations=max_iterations,
                                 tol=tol, restart=restart, executor=executor, bounds=bounds, callback=callback,
                                 sensitivity=sensitivity, names=knn.space.names)

        kalman = restarted(run, run(knn.x0), knn, y_exp, C_exp, max_starts)
    x, C, y_fit, status = kalman.x, kalman.C, kalman.y, kalman.status
    if kalman.failed and np.isfinite(knn.f[knn.order[0]]):
        best = knn.order[0]
        x, C = knn.points[best], knn.C0
        y_fit = np.asarray(knn_output(knn, best, y_exp.size))
        status = f"{kalman.status}; the result is the best point of the KNN population"
    after = _counters(evaluate)
    knn_summary = knn_record(knn, method, seed)
    runs = {"knn": len(knn.points), "knn_failed": knn.n_failed, "kalman": kalman.runs,
            "kalman_failed": len(kalman.failures), "kalman_run_equivalents": kalman.run_equivalents,
            "kalman_iterations": kalman.iterations, "wall_seconds": time.perf_counter() - start}
    if after is not None:
        runs.update(kalman_computed=after[0] - before[0], kalman_reused=after[1] - before[1])
    notes = list(notes) + [f"KNN: {method} population of {len(knn.points)}, k = {knn.k}",
                           f"Kalman filter: step by step, {kalman.iterations} global iteration(s), tol {tol} std, "
                           f"sensitivities by {sensitivity_label(sensitivity)}; "
                           f"{status}"]
    return IdentificationResult(
        x=x, C=C, y_fit=y_fit, history=kalman.history, knn=knn_summary, runs=runs, converged=kalman.converged,
        status=status, **result_fields(operator, knn.space, x, y_exp, C_exp, blocks=blocks, notes=notes),
    )


def knn_record(knn, method, seed) -> dict:
    """What a result keeps of the KNN stage: population, objective, statuses, ranking, k, prior and design."""
    return {"points": knn.points, "f": knn.f, "status": knn.status, "errors": knn.errors, "order": knn.order,
            "k": knn.k, "x0": knn.x0, "C0": knn.C0, "method": method, "seed": seed}


def knn_output(knn, index, size):
    """The computed values of a population point (NaN when the population did not keep them)."""
    Y = getattr(knn, "Y", None)
    return Y[index] if Y is not None else np.full(size, np.nan)


def _counters(operator):
    if isinstance(operator, StoredOperator):
        return operator.computed, operator.reused
    return None


@contextmanager
def kalman_progress(progress, groups, n_outputs, max_iterations):
    """A progress bar of the Kalman stage (linearisations: the first pass's steps, then one per pass);
    yields the filter's callback."""
    from fracid.runtime.progress import progress_bar

    steps = n_outputs if groups is None else len(groups)
    total = steps + max_iterations - 1
    with progress_bar(total, "Kalman filter", progress, unit="step") as bar:
        def callback(iteration, step, x, C):
            if iteration == 1 or step == 1:
                bar.update(1)
            bar.set_postfix_str(f"iteration {iteration}, x = " + ", ".join(f"{v:.4g}" for v in x))

        yield callback
        bar.n = bar.total
        bar.refresh()


def search_then_refine(method, operator, y_exp, C_exp, space: ParameterSpace, *, executor=None, store=None,
                       progress=None, retry_failed=False, blocks=(), notes=()):
    """A KNN-started method's call: its ``search`` (the population through ``store``), then its ``refine``
    from that prior with the runs stored too; the result counts the population's computed and reused runs
    and the wall time of both."""
    start = time.perf_counter()
    y_exp, C_exp = check_problem(operator, y_exp, C_exp, space)
    stats = BatchStats()
    knn = method.search(operator, y_exp, C_exp, space, executor=executor, store=store, progress=progress,
                        stats=stats, retry_failed=retry_failed)
    evaluate = StoredOperator(operator, store, retry_failed=retry_failed)
    result = method.refine(evaluate, y_exp, C_exp, knn, executor=executor, blocks=blocks, notes=notes, started=start,
                           progress=progress)
    result.runs.update(knn_computed=stats.computed, knn_reused=stats.reused)
    return result


def population_search(knn: KnnSettings, operator, y_exp, C_exp, space: ParameterSpace, *, executor=None, store=None,
                      progress=None, stats=None, retry_failed=False):
    """The KNN stage with ``knn``'s settings: a :class:`~fracid.inverse.methods.knn.KnnResult` (population,
    ranking, prior x0, C0); the first stage of every KNN-started method."""
    return knn_search(operator, y_exp, C_exp, space, n=knn.n, method=knn.method, seed=knn.seed, k=knn.k,
                      executor=executor, store=store, progress=progress, stats=stats, retry_failed=retry_failed)


__all__ = ["DEFAULT_GROUPS", "KALMAN_KEYS", "RESTARTS", "IdentificationResult", "KalmanSettings", "KnnKalman",
           "KnnSettings", "kalman_from_table", "kalman_progress", "knn_output", "knn_record", "named_groups",
           "population_search", "refine", "search_then_refine"]
