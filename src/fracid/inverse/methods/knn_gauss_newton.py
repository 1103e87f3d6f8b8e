"""KNN over a population, then bounded Gauss-Newton on the Kalman filter's Bayesian objective.

:class:`KnnGaussNewton` meets :class:`~fracid.inverse.core.method.InverseMethod` and the study's
:class:`~fracid.inverse.methods.registry.StudyMethod`; it returns a :class:`GaussNewtonResult`. Its settings
come from the configuration's ``[identify.knn]`` and ``[identify.gauss-newton]`` (:meth:`KnnGaussNewton.from_config`).
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np

from fracid.inverse.methods.gauss_newton import gauss_newton
from fracid.inverse.methods.knn_kalman import knn_record, population_search, search_then_refine
from fracid.inverse.methods.knn_settings import KnnSettings, knn_from_table, knn_template
from fracid.inverse.core.method import MethodResult, identification_bounds, result_fields
from fracid.inverse.core.plans import StagePlan, plural, population_plan, runs_per_linearisation
from fracid.inverse.core.sensitivity import exact_sensitivity, sensitivity_label
from fracid.settings import checks as settings
from fracid.settings.checks import SettingsContext, toml_line
from fracid.inverse.core.space import ParameterSpace

#: the table of the Gauss-Newton stage's settings in ``[identify]``, and its keys
GAUSS_NEWTON_TABLE = "gauss-newton"
GAUSS_NEWTON_KEYS = ("max_iterations", "tol")


def _stages() -> dict:
    return dict(KnnGaussNewton.stages)


@dataclass
class GaussNewtonResult(MethodResult):
    """The result of :class:`KnnGaussNewton`: a :class:`~fracid.inverse.core.method.MethodResult` with the
    records of its two stages.

    Attributes
    ----------
    history : list of dict
        Estimate and covariance at every linearisation (``iteration``, ``x``, ``C``).
    knn : dict
        Population, objective values, statuses, ranking, k, x0, C0 (as
        :class:`~fracid.inverse.methods.knn_kalman.IdentificationResult`'s).

    ``runs`` holds ``knn``, ``knn_failed``, ``knn_computed``, ``knn_reused``, ``gauss_newton`` (forward
    runs of the linearisations), ``gauss_newton_failed``, ``gauss_newton_iterations``,
    ``gauss_newton_computed``, ``gauss_newton_reused`` and ``wall_seconds`` [s].
    """

    history: list = field(default_factory=list)
    knn: dict = field(default_factory=dict)
    method: str = "knn-gauss-newton"
    stages: dict = field(default_factory=_stages)


@dataclass(frozen=True)
class KnnGaussNewton:
    """KNN over a population for the overview and the prior, then bounded Gauss-Newton
    (:func:`~fracid.inverse.methods.gauss_newton.gauss_newton`: trust region with the bounds) on the same
    Bayesian objective as the Kalman filter: the same MAP point and covariance, found with the
    Jacobian of the runs (exact, by direct differentiation, where the model has it).

    Stages ``"knn"`` and ``"gauss_newton"``.

    Attributes
    ----------
    knn : KnnSettings
    max_iterations : int
        Linearisations at most.
    tol : float
        Convergence: the next step moves no parameter by more than ``tol`` of its standard deviation [-].
    """

    knn: KnnSettings = KnnSettings()
    max_iterations: int = 20
    tol: float = 0.01
    name: ClassVar[str] = "knn-gauss-newton"
    stages: ClassVar[dict] = {"knn": "KNN", "gauss_newton": "Gauss-Newton"}

    #: the tables of [identify] this method reads (:meth:`from_config`)
    config_tables: ClassVar[tuple] = ("knn", GAUSS_NEWTON_TABLE)

    @classmethod
    def from_config(cls, tables: dict, context: SettingsContext) -> KnnGaussNewton:
        """The method of the configuration's tables ``[identify.knn]`` (:func:`~fracid.inverse.methods.knn_settings.
        knn_from_table`) and ``[identify.gauss-newton]`` (``max_iterations``: integer >= 1, default 20; ``tol``:
        > 0 standard deviations, default 0.01), ``tables`` by name (empty when absent).

        Raises
        ------
        fracid.settings.checks.SettingError
            A key or value refused (named relative to ``[identify]``: ``gauss-newton.tol``).
        """
        knn = knn_from_table(tables.get("knn", {}), context)
        raw = settings.table(GAUSS_NEWTON_TABLE, tables.get(GAUSS_NEWTON_TABLE, {}), GAUSS_NEWTON_KEYS)
        return cls(knn, max_iterations=settings.integer(
            "gauss-newton.max_iterations", raw.get("max_iterations", 20),
            "must be an integer >= 1 (linearisations at most)", lambda v: v >= 1),
            tol=settings.number("gauss-newton.tol", raw.get("tol", 0.01), "must be a number > 0 [standard deviations]",
                                lambda v: v > 0))

    @classmethod
    def config_template(cls, tables: dict) -> list[str]:
        """The ``[identify.knn]`` and ``[identify.gauss-newton]`` lines of a configuration ``fracid init``
        writes, with the values of ``tables`` (by table name; a first run's where absent)."""
        gn = tables.get(GAUSS_NEWTON_TABLE, {})
        return knn_template(tables.get("knn", {}), "the prior") + [
            f"[identify.{GAUSS_NEWTON_TABLE}]",
            toml_line("max_iterations", gn.get("max_iterations", 20), "linearisations at most"),
            toml_line("tol", gn.get("tol", 0.01), "convergence: the largest step in standard deviations")]

    def plan(self, operator, n_y: int, p: int) -> list[StagePlan]:
        """The forward runs of both stages: the population side by side, then at most ``max_iterations``
        linearisations one after another (each a full-curve run, or 2 p + 1 without exact sensitivities)."""
        per_step, how = runs_per_linearisation(operator, p)
        runs = (self.max_iterations + 1) * per_step
        text = (f"at most {self.max_iterations} linearisations and a run at the estimate, {plural(per_step, 'run')} each "
                f"({how}): at most {runs} full-curve runs one after another without backtracking")
        return [population_plan(self.knn, p), StagePlan("gauss_newton", "Gauss-Newton", runs, False, float(runs), text,
                                                        "[identify.gauss-newton] max_iterations", per_step == 1)]

    def search(self, operator, y_exp, C_exp, space: ParameterSpace, *, executor=None, store=None, progress=None,
               stats=None, retry_failed=False):
        """The KNN stage (:func:`~fracid.inverse.methods.knn_kalman.population_search`)."""
        return population_search(self.knn, operator, y_exp, C_exp, space, executor=executor, store=store,
                                 progress=progress, stats=stats, retry_failed=retry_failed)

    def fit_from(self, evaluate, y_exp, C_exp, x0, C0, *, bounds=None, executor=None, blocks=()):
        """Gauss-Newton alone from the prior (x0, C0) (a multi-start fit or a noisy replicate of the
        study): a fit with ``x``, ``C``, ``std``, ``y``, ``failed``, ``status``, ``converged``."""
        evaluate, sensitivity = exact_sensitivity(evaluate)
        return gauss_newton(evaluate, y_exp, C_exp, x0, C0, sensitivity=sensitivity, executor=executor, bounds=bounds,
                            max_iterations=self.max_iterations, tol=self.tol)

    def refine(self, operator, y_exp, C_exp, knn, *, C0=None, executor=None, blocks=(), notes=(), started=None,
               progress=False) -> GaussNewtonResult:
        """The Gauss-Newton stage from the prior of ``knn`` (``C0`` replaces its covariance when given).
        ``operator`` may be a :class:`~fracid.inverse.core.runs.StoredOperator` (its runs are then counted)."""
        start = time.perf_counter() if started is None else started
        evaluate, sensitivity = exact_sensitivity(operator)
        before = (getattr(evaluate, "computed", 0), getattr(evaluate, "reused", 0))
        bounds = identification_bounds(operator, knn.space)
        fit = gauss_newton(evaluate, y_exp, C_exp, knn.x0, knn.C0 if C0 is None else np.asarray(C0, float),
                           sensitivity=sensitivity, executor=executor, bounds=bounds,
                           max_iterations=self.max_iterations, tol=self.tol)
        runs = {"knn": len(knn.points), "knn_failed": knn.n_failed, "gauss_newton": fit.runs,
                "gauss_newton_failed": len(fit.failures), "gauss_newton_iterations": fit.iterations,
                "gauss_newton_computed": getattr(evaluate, "computed", 0) - before[0],
                "gauss_newton_reused": getattr(evaluate, "reused", 0) - before[1],
                "wall_seconds": time.perf_counter() - start}
        notes = list(notes) + [f"KNN: {self.knn.method} population of {len(knn.points)}, k = {knn.k}",
                               f"Gauss-Newton (bounded trust region): {fit.iterations} linearisation(s), tol "
                               f"{self.tol} std, sensitivities by {sensitivity_label(sensitivity)}; {fit.status}"]
        return GaussNewtonResult(
            x=fit.x, C=fit.C, y_fit=fit.y, history=fit.history, knn=knn_record(knn, self.knn.method, self.knn.seed),
            runs=runs, converged=fit.converged, status=fit.status,
            **result_fields(operator, knn.space, fit.x, y_exp, C_exp, blocks=blocks, notes=notes))

    def __call__(self, operator, y_exp, C_exp, space: ParameterSpace, *, executor=None, store=None, progress=None,
                 retry_failed=False, blocks=(), notes=()) -> GaussNewtonResult:
        """Both stages (see :class:`~fracid.inverse.core.method.InverseMethod`)."""
        return search_then_refine(self, operator, y_exp, C_exp, space, executor=executor, store=store,
                                  progress=progress, retry_failed=retry_failed, blocks=blocks, notes=notes)


__all__ = ["GAUSS_NEWTON_KEYS", "GAUSS_NEWTON_TABLE", "GaussNewtonResult", "KnnGaussNewton"]
