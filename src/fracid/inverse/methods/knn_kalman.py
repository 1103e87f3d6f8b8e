"""The default inverse method: KNN over a population, then the bounded step-by-step Kalman filter
(docs/theory.md, sections 4.2 to 4.4).

:class:`KnnKalman` is a :class:`~fracid.inverse.methods.knn_started.KnnStarted` method whose local fit is the
Kalman filter (:meth:`KnnKalman.local_fit`); it meets :class:`~fracid.inverse.core.method.InverseMethod` and
the study's :class:`~fracid.inverse.methods.registry.StudyMethod`. Its settings are
:class:`~fracid.inverse.methods.knn_settings.KnnSettings` and
:class:`~fracid.inverse.methods.kalman_settings.KalmanSettings`, which :meth:`KnnKalman.from_config` reads (and
checks) from the configuration's ``[identify.knn]`` and ``[identify.kalman]``.
"""

from __future__ import annotations

from contextlib import contextmanager
from dataclasses import dataclass, field, replace
from typing import ClassVar

import numpy as np

from fracid.inverse.core.fit_status import NOT_CONVERGED
from fracid.inverse.core.plans import StagePlan, likely_iterations, plural, runs_per_linearisation
from fracid.inverse.core.sensitivity import sensitivity_label
from fracid.inverse.core.stage_records import PATH, POPULATION
from fracid.inverse.methods.kalman import kalman_filter
from fracid.inverse.methods.kalman_settings import (DEFAULT_GROUPS, KALMAN_KEY_DOCS, KalmanSettings, kalman_from_table,
                                                    named_groups)
from fracid.inverse.methods.kalman_status import restarted
from fracid.inverse.methods.knn_settings import KNN_KEY_DOCS, knn_from_table, knn_template
from fracid.inverse.methods.knn_started import KnnStarted, KnnStartedResult, LocalFit, knn_output, population_plan
from fracid.settings.checks import SettingsContext, toml_line


@dataclass
class IdentificationResult(KnnStartedResult):
    """The result of :class:`KnnKalman`: a :class:`~fracid.inverse.methods.knn_started.KnnStartedResult`
    whose ``history`` holds the Kalman estimate and covariance after every step of every global iteration.

    ``runs`` holds ``knn`` (population), ``knn_failed``, ``knn_computed``, ``knn_reused``,
    ``kalman`` (forward runs of the filter), ``kalman_failed``, ``kalman_run_equivalents``,
    ``kalman_iterations``, ``kalman_computed``, ``kalman_reused`` and ``wall_seconds`` [s].
    """

    method: str = "knn-kalman"
    stages: dict = field(default_factory=lambda: dict(KnnKalman.stages))
    stage_records: dict = field(default_factory=lambda: dict(KnnKalman.stage_records))

    def failed_runs_text(self) -> str:
        runs = self.runs or {}
        return (f"{runs.get('knn_failed', 0)} of {runs.get('knn', 0)} KNN, "
                f"{runs.get('kalman_failed', 0)} in the Kalman stage")


@dataclass(frozen=True)
class KnnKalman(KnnStarted):
    """The default inverse method: KNN over a population for a global overview and the prior, then
    the bounded step-by-step Kalman filter from that prior (the thesis's cascade, docs/theory.md, section 4.4).

    Its stages are ``"knn"`` (a population) and ``"kalman"`` (a path of estimates); it returns an
    :class:`IdentificationResult`.

    Attributes
    ----------
    knn : KnnSettings
    kalman : KalmanSettings
    """

    kalman: KalmanSettings = KalmanSettings()
    name: ClassVar[str] = "knn-kalman"
    stages: ClassVar[dict] = {"knn": "KNN", "kalman": "Kalman filter"}
    stage_records: ClassVar[dict] = {"knn": POPULATION, "kalman": PATH}
    result_class: ClassVar[type] = IdentificationResult

    #: the tables of [identify] this method reads (:meth:`from_config`)
    config_tables: ClassVar[tuple] = ("knn", "kalman")
    #: their keys, described (:data:`~fracid.inverse.methods.knn_settings.KNN_KEY_DOCS`, :data:`KALMAN_KEY_DOCS`)
    config_keys: ClassVar[dict] = {"knn": KNN_KEY_DOCS, "kalman": KALMAN_KEY_DOCS}

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

    def plan(self, operator, n_y: int, p: int, space=None) -> list[StagePlan]:
        """The forward runs of both stages (:class:`~fracid.inverse.core.plans.StagePlan`): the population side by
        side; the filter's steps one after another (a step of the first pass runs up to its observations, each
        later pass is one linearisation), at most ``max_iterations`` passes and a run at the estimate, and up to
        ``max_starts`` starts (:func:`~fracid.inverse.methods.kalman_status.restarted`). As it usually goes: one
        start and :func:`~fracid.inverse.core.plans.likely_iterations` passes."""
        per_step, how = runs_per_linearisation(operator, p)
        groups = named_groups(self.kalman.groups, n_y)
        steps = n_y if groups is None else len(groups)
        passes, likely = self.kalman.max_iterations, likely_iterations(self.kalman.max_iterations)
        first = per_step * (steps + 1) / 2  # a step of the first pass runs up to its observations
        runs, full = steps * per_step + passes * per_step, first + passes * per_step
        text = (f"{steps} steps per pass, {plural(per_step, 'run')} per step ({how}), at most {passes} passes and a run at "
                f"the estimate: at most {runs} runs one after another without backtracking, about {full:.0f} "
                "full-curve runs")
        return [population_plan(self.knn, p, "knn", "KNN", operator, space),
                StagePlan("kalman", "Kalman filter", runs, False, full, text, "[identify.kalman] groups and max_iterations",
                          per_step == 1, starts=self.kalman.max_starts, starts_key="[identify.kalman] max_starts",
                          likely_full_runs=first + likely * per_step,
                          likely_text=f"one start, {likely} of {passes} passes")]

    def fit_from(self, evaluate, y_exp, C_exp, x0, C0, *, bounds=None, executor=None, blocks=()):
        """The Kalman filter alone from the prior (x0, C0), started once (a multi-start filter or a noisy
        replicate of the study): a :class:`~fracid.inverse.methods.kalman.KalmanResult` (``x``, ``std``, ``y``,
        ``failed``, ``status``)."""
        return kalman_filter(evaluate, y_exp, C_exp, x0, C0, bounds=bounds, executor=executor,
                             **self.kalman.options(np.size(y_exp), blocks))

    def local_fit(self, evaluate, sensitivity, y_exp, C_exp, knn, C0, *, bounds, executor=None, blocks=(),
                  progress=False) -> LocalFit:
        """The Kalman filter from the prior of ``knn`` (covariance ``C0``), restarted from the next-best
        population points while it ends at a poor point, ``max_starts`` starts in all
        (:func:`~fracid.inverse.methods.kalman_status.restarted`: the status says how many were tried and which
        won; the winner's ``history``, the runs of all). When it could not evaluate any estimate of its own
        (every run near its points failed), the fit is the best point of the population with the KNN prior
        covariance, and the status says so."""
        options = self.kalman.options(np.size(y_exp), blocks)
        with kalman_progress(progress, options["groups"], y_exp.size, self.kalman.max_iterations,
                             self.kalman.max_starts) as shown:
            def run(x0):
                return kalman_filter(evaluate, y_exp, C_exp, x0, C0, executor=executor, bounds=bounds,
                                     callback=shown.start(), sensitivity=sensitivity, names=knn.space.names, **options)

            kalman = restarted(run, run(knn.x0), knn, y_exp, C_exp, self.kalman.max_starts)
            x, C, y_fit, status = kalman.x, kalman.C, kalman.y, kalman.status
            if kalman.failed and np.isfinite(knn.f[knn.order[0]]):
                best = knn.order[0]
                x, C = knn.points[best], knn.C0
                y_fit = np.asarray(knn_output(knn, best, y_exp.size))
                status = f"{NOT_CONVERGED}: the result is the best point of the KNN population; the filter {kalman.status}"
            shown.returned(x)
        note = (f"Kalman filter: step by step, {kalman.iterations} global iteration(s), tol {self.kalman.tol} std, "
                f"sensitivities by {sensitivity_label(sensitivity)}; {status}")
        return LocalFit(x=x, C=C, y=y_fit, history=kalman.history, converged=kalman.converged, status=status,
                        runs=kalman.runs, failed=len(kalman.failures), note=note,
                        counters={"run_equivalents": kalman.run_equivalents, "iterations": kalman.iterations})


class KalmanProgress:
    """The Kalman stage's progress bar over its starts: each start (:meth:`start`) adds its linearisations to the
    total (the first pass's steps, then one per pass), so the count never passes the total; the bar's note is the
    running estimate, and at the end the returned one (:meth:`returned`)."""

    def __init__(self, bar, per_start: int, max_starts: int):
        self.bar, self.per_start, self.max_starts, self.starts = bar, per_start, max_starts, 0

    def start(self):
        """The filter's callback for the next start."""
        self.starts += 1
        if self.starts > 1:
            self.bar.total += self.per_start
        label = f"start {self.starts}/{self.max_starts}, " if self.max_starts > 1 else ""

        def callback(iteration, step, x, C):
            if iteration == 1 or step == 1:
                self.bar.update(1)
            self.bar.set_postfix_str(f"{label}iteration {iteration}, x = " + _values(x))

        return callback

    def returned(self, x):
        """The note of the last line: the estimate the stage returns."""
        self.bar.n = self.bar.total
        self.bar.set_postfix_str("returned x = " + _values(x))


def _values(x) -> str:
    return ", ".join(f"{v:.4g}" for v in np.asarray(x, float))


@contextmanager
def kalman_progress(progress, groups, n_outputs, max_iterations, max_starts=1):
    """A progress bar of the Kalman stage (:class:`KalmanProgress`; ``max_starts``: the filter's starts at most)."""
    from fracid.runtime.progress import progress_bar

    steps = n_outputs if groups is None else len(groups)
    per_start = steps + max_iterations - 1
    with progress_bar(per_start, "Kalman filter", progress, unit="step") as bar:
        shown = KalmanProgress(bar, per_start, max_starts)
        yield shown
        bar.n = bar.total
        bar.refresh()


__all__ = ["IdentificationResult", "KalmanProgress", "KnnKalman", "kalman_progress"]
