"""KNN over a population, then bounded Gauss-Newton on the Kalman filter's Bayesian objective.

:class:`KnnGaussNewton` is a :class:`~fracid.inverse.methods.knn_started.KnnStarted` method whose local fit is
Gauss-Newton (:meth:`KnnGaussNewton.local_fit`); it meets :class:`~fracid.inverse.core.method.InverseMethod` and
the study's :class:`~fracid.inverse.methods.registry.StudyMethod` and returns a :class:`GaussNewtonResult`. Its
settings come from the configuration's ``[identify.knn]`` and ``[identify.gauss-newton]``
(:meth:`KnnGaussNewton.from_config`).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import ClassVar

from fracid.inverse.core.plans import StagePlan, likely_iterations, plural, runs_per_linearisation
from fracid.inverse.core.sensitivity import exact_sensitivity, sensitivity_label
from fracid.inverse.core.stage_records import PATH, POPULATION
from fracid.inverse.methods.gauss_newton import gauss_newton
from fracid.inverse.methods.knn_settings import KNN_KEY_DOCS, knn_from_table, knn_template
from fracid.inverse.methods.knn_started import KnnStarted, KnnStartedResult, LocalFit, population_plan
from fracid.settings import checks as settings
from fracid.settings.checks import SettingsContext, toml_line
from fracid.settings.keys import FROM_CLASS, Key, described

#: the table of the Gauss-Newton stage's settings in ``[identify]``, and its keys
GAUSS_NEWTON_TABLE = "gauss-newton"


@dataclass
class GaussNewtonResult(KnnStartedResult):
    """The result of :class:`KnnGaussNewton`: a :class:`~fracid.inverse.methods.knn_started.KnnStartedResult`
    whose ``history`` holds the estimate and covariance at every linearisation (``iteration``, ``x``, ``C``).

    ``runs`` holds ``knn``, ``knn_failed``, ``knn_computed``, ``knn_reused``, ``gauss_newton`` (forward
    runs of the linearisations), ``gauss_newton_failed``, ``gauss_newton_iterations``,
    ``gauss_newton_computed``, ``gauss_newton_reused`` and ``wall_seconds`` [s].
    """

    method: str = "knn-gauss-newton"
    stages: dict = field(default_factory=lambda: dict(KnnGaussNewton.stages))
    stage_records: dict = field(default_factory=lambda: dict(KnnGaussNewton.stage_records))


@dataclass(frozen=True)
class KnnGaussNewton(KnnStarted):
    """KNN over a population for the overview and the prior, then bounded Gauss-Newton
    (:func:`~fracid.inverse.methods.gauss_newton.gauss_newton`: trust region with the bounds) on the same
    Bayesian objective as the Kalman filter: the same MAP point and covariance, found with the
    Jacobian of the runs (exact, by direct differentiation, where the model has it).

    Stages ``"knn"`` (a population) and ``"gauss_newton"`` (a path of estimates).

    Attributes
    ----------
    knn : KnnSettings
    max_iterations : int
        Linearisations at most.
    tol : float
        Convergence: the next step moves no parameter by more than ``tol`` of its standard deviation [-].
    """

    max_iterations: int = 20
    tol: float = 0.01
    name: ClassVar[str] = "knn-gauss-newton"
    stages: ClassVar[dict] = {"knn": "KNN", "gauss_newton": "Gauss-Newton"}
    stage_records: ClassVar[dict] = {"knn": POPULATION, "gauss_newton": PATH}
    result_class: ClassVar[type] = GaussNewtonResult

    #: the tables of [identify] this method reads (:meth:`from_config`)
    config_tables: ClassVar[tuple] = ("knn", GAUSS_NEWTON_TABLE)
    #: their keys, described (set below the class: the meanings of [identify.gauss-newton] are its docstring's)
    config_keys: ClassVar[dict] = {}

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

    def plan(self, operator, n_y: int, p: int, space=None) -> list[StagePlan]:
        """The forward runs of both stages: the population side by side, then at most ``max_iterations``
        linearisations one after another (each a full-curve run, or 2 p + 1 without exact sensitivities)."""
        per_step, how = runs_per_linearisation(operator, p)
        runs = (self.max_iterations + 1) * per_step
        text = (f"at most {self.max_iterations} linearisations and a run at the estimate, {plural(per_step, 'run')} each "
                f"({how}): at most {runs} full-curve runs one after another without backtracking")
        likely = likely_iterations(self.max_iterations)
        return [population_plan(self.knn, p, "knn", "KNN", operator, space),
                StagePlan("gauss_newton", "Gauss-Newton", runs, False, float(runs), text,
                          "[identify.gauss-newton] max_iterations", per_step == 1, likely_full_runs=(likely + 1) * per_step,
                          likely_text=f"{likely} of {self.max_iterations} linearisations")]

    def fit_from(self, evaluate, y_exp, C_exp, x0, C0, *, bounds=None, executor=None, blocks=()):
        """Gauss-Newton alone from the prior (x0, C0) (a multi-start fit or a noisy replicate of the
        study): a fit with ``x``, ``C``, ``std``, ``y``, ``failed``, ``status``, ``converged``."""
        evaluate, sensitivity = exact_sensitivity(evaluate)
        return gauss_newton(evaluate, y_exp, C_exp, x0, C0, sensitivity=sensitivity, executor=executor, bounds=bounds,
                            max_iterations=self.max_iterations, tol=self.tol)

    def local_fit(self, evaluate, sensitivity, y_exp, C_exp, knn, C0, *, bounds, executor=None, blocks=(),
                  progress=False) -> LocalFit:
        """Gauss-Newton from the prior of ``knn`` (covariance ``C0``) inside ``bounds``."""
        fit = gauss_newton(evaluate, y_exp, C_exp, knn.x0, C0, sensitivity=sensitivity, executor=executor,
                           bounds=bounds, max_iterations=self.max_iterations, tol=self.tol)
        note = (f"Gauss-Newton (bounded trust region): {fit.iterations} linearisation(s), tol {self.tol} std, "
                f"sensitivities by {sensitivity_label(sensitivity)}; {fit.status}")
        return LocalFit(x=fit.x, C=fit.C, y=fit.y, history=fit.history, converged=fit.converged, status=fit.status,
                        runs=fit.runs, failed=len(fit.failures), counters={"iterations": fit.iterations}, note=note)


#: the keys of ``[identify.gauss-newton]``, described (defaults and meanings: :class:`KnnGaussNewton`'s)
GAUSS_NEWTON_KEY_DOCS = described({"max_iterations": Key(FROM_CLASS, "", "integer >= 1"),
                                   "tol": Key(FROM_CLASS, "standard deviations", "> 0")}, KnnGaussNewton)
GAUSS_NEWTON_KEYS = tuple(GAUSS_NEWTON_KEY_DOCS)
KnnGaussNewton.config_keys = {"knn": KNN_KEY_DOCS, GAUSS_NEWTON_TABLE: GAUSS_NEWTON_KEY_DOCS}

__all__ = ["GAUSS_NEWTON_KEYS", "GAUSS_NEWTON_KEY_DOCS", "GAUSS_NEWTON_TABLE", "GaussNewtonResult", "KnnGaussNewton"]
