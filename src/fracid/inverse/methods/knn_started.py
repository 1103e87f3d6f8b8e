"""The KNN-started methods' common frame: a KNN population search for the overview and the prior, then a local
fit from that prior (the thesis's cascade, docs/theory.md, section 4.4).

:class:`KnnStarted` is the base of :class:`~fracid.inverse.methods.knn_kalman.KnnKalman` and
:class:`~fracid.inverse.methods.knn_gauss_newton.KnnGaussNewton`: it runs the search (:meth:`KnnStarted.search`),
the local fit from its prior (:meth:`KnnStarted.refine`), counts both stages' runs and builds the result
(:class:`KnnStartedResult`). The variant is the local fit alone: a subclass gives ``local_fit`` (the fit from
the prior, a :class:`LocalFit`), ``fit_from`` (the fit alone, for the study's checks), ``plan`` and its
settings' ``from_config`` / ``config_template``.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field, replace
from typing import ClassVar

import numpy as np

from fracid.inverse.core.method import (MethodResult, check_problem, estimate_curves, identification_bounds,
                                        result_fields)
from fracid.inverse.core.plans import StagePlan
from fracid.inverse.core.runs import StoredOperator
from fracid.inverse.core.sensitivity import exact_sensitivity
from fracid.inverse.core.space import ParameterSpace
from fracid.inverse.core.stage_records import PATH, POPULATION
from fracid.inverse.methods.knn import knn_search
from fracid.inverse.methods.knn_screening import screened
from fracid.inverse.methods.knn_settings import KnnSettings
from fracid.runtime.batch import BatchStats


@dataclass
class KnnStartedResult(MethodResult):
    """The result of a :class:`KnnStarted` method: a :class:`~fracid.inverse.core.method.MethodResult` with the
    records of its two stages, kept under the keys of ``result.json`` they always had.

    Attributes
    ----------
    knn : dict
        The search's population record (:data:`~fracid.inverse.core.stage_records.POPULATION`): points,
        objective values, statuses, ranking, k, the prior x0 and C0, the design and its seed.
    history : list of dict
        The local fit's path of estimates (:data:`~fracid.inverse.core.stage_records.PATH`): ``x``, ``C`` and
        ``iteration`` after every step.
    """

    history: list = field(default_factory=list)
    knn: dict = field(default_factory=dict)

    def record(self, stage: str):
        """The stage's record: the population (``knn``) of the search stage, the path (``history``) of the
        local one, ``records[stage]`` for any other."""
        kinds = {POPULATION: self.knn, PATH: self.history}
        own = super().record(stage)
        return own if own is not None else kinds.get(self.record_kind(stage))


@dataclass(frozen=True)
class LocalFit:
    """What the local stage of a :class:`KnnStarted` method gives back.

    Attributes
    ----------
    x, C : ndarray
        Estimate and covariance (units of the parameters).
    y : ndarray
        Computed observations at the estimate (NaN where the run failed).
    history : list of dict
        The path of estimates (``x``, ``C``, ``iteration``).
    converged : bool
    status : str
    runs, failed : int
        Forward runs asked for, and how many failed.
    counters : dict
        Further counters of the stage, by name (``iterations``, ...): ``runs["<stage>_<name>"]``.
    note : str
        The stage's line in the result's notes.
    """

    x: np.ndarray
    C: np.ndarray
    y: np.ndarray
    history: list
    converged: bool
    status: str
    runs: int
    failed: int
    counters: dict
    note: str


@dataclass(frozen=True)
class KnnStarted:
    """Base of the KNN-started methods: the search with the settings ``knn``, then the subclass's local fit.

    Subclasses set ``name``, ``stages`` (the search stage first, then the local one: name -> label),
    ``stage_records`` (the search leaves a population, the local fit a path of estimates), ``result_class``
    and ``local_fit``.

    Attributes
    ----------
    knn : KnnSettings
    """

    knn: KnnSettings = KnnSettings()
    name: ClassVar[str] = ""
    stages: ClassVar[dict] = {}
    stage_records: ClassVar[dict] = {}
    result_class: ClassVar[type] = KnnStartedResult

    def search(self, operator, y_exp, C_exp, space: ParameterSpace, *, executor=None, store=None, progress=None,
               stats=None, retry_failed=False):
        """The search stage: a :class:`~fracid.inverse.methods.knn.KnnResult` (population, ranking, prior x0, C0)."""
        return population_search(self.knn, operator, y_exp, C_exp, space, executor=executor, store=store,
                                 progress=progress, stats=stats, retry_failed=retry_failed)

    def local_fit(self, evaluate, sensitivity, y_exp, C_exp, knn, C0, *, bounds, executor=None, blocks=(),
                  progress=False) -> LocalFit:
        """The local stage from the prior of ``knn`` (covariance ``C0``) inside ``bounds``: the variant."""
        raise NotImplementedError

    def refine(self, operator, y_exp, C_exp, knn, *, C0=None, executor=None, blocks=(), notes=(), started=None,
               progress=False, mesh="") -> KnnStartedResult:
        """The local stage from the prior of ``knn`` (``C0`` replaces its covariance when given, e.g. the
        bounds', so that the posterior holds the information of the data alone; ``mesh``: the population's mesh
        in words, :class:`~fracid.inverse.methods.knn_screening.Screening`, "" when not said). ``operator`` may be a
        :class:`~fracid.inverse.core.runs.StoredOperator` (its runs are then stored and counted); the stage
        stays inside the space's bounds and does not raise on failed forward runs."""
        start = time.perf_counter() if started is None else started
        if self.knn.start is not None:  # a given start (the error terms' loops) replaces the neighbours' mean
            knn = replace(knn, x0=np.clip(np.asarray(self.knn.start, float), knn.space.lower, knn.space.upper))
        evaluate, sensitivity = exact_sensitivity(operator)
        before = _counters(evaluate)
        bounds = identification_bounds(operator, knn.space)
        fit = self.local_fit(evaluate, sensitivity, y_exp, C_exp, knn, knn.C0 if C0 is None else np.asarray(C0, float),
                             bounds=bounds, executor=executor, blocks=blocks, progress=progress)
        search, local = self.stages
        runs = {search: len(knn.points), f"{search}_failed": knn.n_failed, local: fit.runs, f"{local}_failed": fit.failed,
                **{f"{local}_{name}": value for name, value in fit.counters.items()}}
        curves = estimate_curves(evaluate, fit.x)  # the estimate's run, already made: its own curve
        after = _counters(evaluate)
        if after is not None:
            runs.update({f"{local}_computed": after[0] - before[0], f"{local}_reused": after[1] - before[1]})
        runs["wall_seconds"] = time.perf_counter() - start
        notes = list(notes) + [f"KNN: {self.knn.method} population of {len(knn.points)}, k = {knn.k}"
                               + (f", {mesh}" if mesh else ""), fit.note]
        return self.result_class(
            x=fit.x, C=fit.C, y_fit=fit.y, history=fit.history,
            knn=knn_record(knn, self.knn.method, self.knn.seed, mesh),
            runs=runs, converged=fit.converged, status=fit.status, method=self.name, stages=dict(self.stages),
            stage_records=dict(self.stage_records), curves=curves,
            **result_fields(operator, knn.space, fit.x, y_exp, C_exp, blocks=blocks, notes=notes))

    def __call__(self, operator, y_exp, C_exp, space: ParameterSpace, *, executor=None, store=None, progress=None,
                 retry_failed=False, blocks=(), notes=()) -> KnnStartedResult:
        """Both stages (see :class:`~fracid.inverse.core.method.InverseMethod`): the search (its population
        through ``store``), then the local fit with its runs stored too; the result counts the population's
        computed and reused runs and the wall time of both.

        Raises
        ------
        AllRunsFailed
            When fewer than k population runs succeeded. A failed run of the local stage never raises.
        """
        start = time.perf_counter()
        y_exp, C_exp = check_problem(operator, y_exp, C_exp, space)
        stats = BatchStats()
        mesh = screened(operator, self.knn.screening, space)  # the population on a screening mesh, or said why not
        knn = self.search(mesh.operator, y_exp, C_exp, space, executor=executor, store=store, progress=progress,
                          stats=stats, retry_failed=retry_failed)
        evaluate = StoredOperator(operator, store, retry_failed=retry_failed)
        result = self.refine(evaluate, y_exp, C_exp, knn, executor=executor, blocks=blocks, notes=notes,
                             started=start, progress=progress, mesh=mesh.text)
        search = next(iter(self.stages))
        result.runs.update({f"{search}_computed": stats.computed, f"{search}_reused": stats.reused})
        return result


def population_search(knn: KnnSettings, operator, y_exp, C_exp, space: ParameterSpace, *, executor=None, store=None,
                      progress=None, stats=None, retry_failed=False):
    """The KNN search with ``knn``'s settings: a :class:`~fracid.inverse.methods.knn.KnnResult` (population,
    ranking, prior x0, C0); the first stage of every KNN-started method."""
    return knn_search(operator, y_exp, C_exp, space, n=knn.n, method=knn.method, seed=knn.seed, k=knn.k,
                      executor=executor, store=store, progress=progress, stats=stats, retry_failed=retry_failed)


def population_plan(knn: KnnSettings, p: int, stage: str, label: str, operator=None, space=None) -> StagePlan:
    """The forward runs of a KNN search with the settings ``knn`` (n, method, k, screening) for ``p`` parameters,
    as the stage ``stage`` (its ``label``); with ``operator`` and ``space``, on the mesh :func:`screened` gives
    (its operator is the plan's when it is a screening one, so that ``fracid check`` times a run of it)."""
    runs = knn.population(p)
    mesh = screened(operator, knn.screening, space) if operator is not None and space is not None else None
    where = f" {mesh.text}" if mesh is not None and (mesh.coarse or mesh.fallback) else ""
    return StagePlan(stage, label, runs, True, float(runs), f"{runs} forward runs side by side ({knn.method}, "
                     f"k = {knn.k}){where}", f"[identify.knn] n = {knn.n}",
                     operator=mesh.operator if mesh is not None and mesh.coarse else None)


def knn_record(knn, method, seed, mesh="") -> dict:
    """What a result keeps of the search (its population record): population, objective, statuses, ranking, k,
    prior, design and the mesh it ran on in words (``mesh``, kept as ``screening``; "" when not said)."""
    return {"points": knn.points, "f": knn.f, "status": knn.status, "errors": knn.errors, "order": knn.order,
            "k": knn.k, "x0": knn.x0, "C0": knn.C0, "method": method, "seed": seed, "screening": mesh}


def knn_output(knn, index, size):
    """The computed values of a population point (NaN when the population did not keep them)."""
    Y = getattr(knn, "Y", None)
    return Y[index] if Y is not None else np.full(size, np.nan)


def _counters(operator):
    """Computed and reused runs of a stored operator so far (None for another)."""
    if isinstance(operator, StoredOperator):
        return operator.computed, operator.reused
    return None


__all__ = ["KnnStarted", "KnnStartedResult", "LocalFit", "knn_output", "knn_record", "population_plan",
           "population_search"]
