"""What an inverse method's stages will cost, said before the work starts: a :class:`StagePlan` per
stage (``method.plan(operator, n_y, n_parameters)``), printed by ``fracid identify`` and ``fracid check``, and
their wall time from timed runs (:func:`stage_seconds`, :func:`plan_seconds`: a likely value and an upper one).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from fracid.inverse.core.forward_operator import RETRY_STEP_DIVISOR

#: The upper value of an estimate assumes that up to this share of the runs fail (or, in a filter, are
#: stepped back from): a share, not a bound, which the estimate states (7 of 64 population runs failed on a
#: real beam test, issue 38)
FAILED_SHARE = 0.25
#: A failed run is run again with steps :data:`RETRY_STEP_DIVISOR` times smaller: with the first attempt it
#: costs up to this many runs (each attempt to the end of the curve at worst)
FAILED_RUN_COST = 1 + RETRY_STEP_DIVISOR


@dataclass(frozen=True)
class StagePlan:
    """The forward runs of one stage of an inverse method.

    Attributes
    ----------
    stage, label : str
        The stage's name and its label in text (``"kalman"``, ``"Kalman filter"``).
    runs : int
        Forward runs at most (without backtracking over failed or worse points).
    side_by_side : bool
        Whether the runs are independent (they run in parallel on the workers) or one after another.
    full_runs : float
        The runs in full-curve equivalents (a run that stops early at the data it needs costs less).
    text : str
        How the count comes about, in words.
    keys : str
        The settings that set the count, as the configuration names them (``"[identify.knn] n"``).
    exact : bool
        Whether its runs carry exact sensitivities (a run then costs more than a plain one).
    starts : int
        Starts of the stage at most (a filter started again from other points when it ends at a poor one):
        ``runs`` and ``full_runs`` are of one start.
    starts_key : str
        The setting of ``starts`` (``"[identify.kalman] max_starts"``).
    likely_full_runs : float or None
        The full-curve runs of one start as they usually go (fewer passes than the most); None: ``full_runs``.
    likely_text : str
        How ``likely_full_runs`` comes about, in words (``"5 passes: half the most"``).
    operator : ForwardOperator or None
        The operator of the stage's runs when it is not the identification's (a KNN population on a screening
        mesh, :mod:`fracid.inverse.methods.knn_screening`): its runs cost :attr:`RunTimes.screened` each.
    """

    stage: str
    label: str
    runs: int
    side_by_side: bool
    full_runs: float
    text: str
    keys: str = ""
    exact: bool = False
    starts: int = 1
    starts_key: str = ""
    likely_full_runs: float | None = None
    likely_text: str = ""
    operator: object = None

    def line(self) -> str:
        """``"stage <label>: <text> (<keys>)"``, and its starts when it may start more than once."""
        starts = (f"; up to {plural(self.starts, 'start')} in all when it ends at a poor point ({self.starts_key}): "
                  f"at most {self.runs * self.starts} runs" if self.starts > 1 else "")
        return f"stage {self.label}: {self.text}" + (f" ({self.keys})" if self.keys else "") + starts


@dataclass(frozen=True)
class RunTimes:
    """What the wall time of a plan is computed from: timed forward runs and the workers.

    Attributes
    ----------
    plain : float
        Seconds of a plain forward run to the end of the curve (the mean of the timed ones, warm).
    exact : float
        Seconds of a run with exact sensitivities (``plain`` times the measured ratio).
    workers : int
        Workers sharing the side-by-side runs.
    cores : int
        Cores of the machine: more workers than cores do not run faster.
    screened : float or None
        Seconds of a plain run of a stage's own operator (a population on a screening mesh, timed); None: as
        ``plain``.
    """

    plain: float
    exact: float
    workers: int
    cores: int
    screened: float | None = None

    def run(self, stage: StagePlan) -> float:
        """Seconds of one full-curve run of ``stage``."""
        if stage.operator is not None and self.screened is not None:
            return self.screened
        return self.exact if stage.exact else self.plain


def stage_seconds(stage: StagePlan, times: RunTimes, upper: bool = False) -> float:
    """Wall time [s] of a stage: its side-by-side runs in rounds on the workers, its other runs one after
    another.

    The likely value: one start, ``likely_full_runs``, no failed run. The upper one: every start, every
    run of the plan, and :data:`FAILED_SHARE` of the runs failing at :data:`FAILED_RUN_COST` runs each.
    More workers than cores share the cores (a round then lasts ``workers / cores`` runs).
    """
    run = times.run(stage)
    failures = 1.0 + (FAILED_SHARE * (FAILED_RUN_COST - 1) if upper else 0.0)
    if stage.side_by_side:
        workers = max(int(times.workers), 1)
        crowding = max(1.0, workers / max(int(times.cores), 1))
        return math.ceil(stage.runs / workers) * run * crowding * failures
    one = stage.full_runs if upper or stage.likely_full_runs is None else stage.likely_full_runs
    return one * run * (stage.starts if upper else 1) * failures


def plan_seconds(plan, times: RunTimes, refits: tuple = (0, 0)) -> tuple[float, float]:
    """(likely, upper) wall time [s] of the plan's stages; ``refits`` (likely, most): how many times the
    identification runs again after the first (the error terms' loops), each time its stages that are not
    side by side (the population is reused from the run store)."""
    likely = upper = 0.0
    for stage in plan:
        again = (0, 0) if stage.side_by_side else refits
        likely += stage_seconds(stage, times) * (1 + again[0])
        upper += stage_seconds(stage, times, upper=True) * (1 + again[1])
    return likely, upper


def method_plan(method, operator, n_y: int, p: int, space=None) -> list:
    """The stages of ``method`` and their forward runs (its ``plan``, a :class:`StagePlan` per stage; empty for a
    method without one), given ``space`` (the identification's bounds) when its ``plan`` takes it."""
    import inspect

    plan = getattr(method, "plan", None)  # an optional capability of an inverse method
    if plan is None:
        return []
    takes_space = "space" in inspect.signature(plan).parameters
    return list(plan(operator, n_y, p, space=space) if takes_space else plan(operator, n_y, p))


def plural(count, noun: str) -> str:
    """``"1 run"``, ``"2 runs"``."""
    return f"{count} {noun}{'' if count == 1 else 's'}"


def likely_iterations(most: int) -> int:
    """Iterations (a filter's passes, linearisations) of a local fit as it usually goes, for the likely value of a
    time estimate: half of ``most``, at least 2 (convergence is judged from the second on). The Kalman filters of
    benchmarks/check_estimate.py took 3 of 3, 4, 6 and 10 of 10 passes."""
    return min(most, max(2, math.ceil(most / 2)))


def runs_per_linearisation(operator, p: int) -> tuple[int, str]:
    """Forward runs of one linearisation at a point: 1 when the model differentiates its runs exactly
    (:func:`~fracid.inverse.core.sensitivity.exact_sensitivity`), else the run and 2 per parameter (central
    differences); and the words for it."""
    from fracid.inverse.core.sensitivity import DirectDifferentiation, exact_sensitivity

    if operator is not None and isinstance(exact_sensitivity(operator)[1], DirectDifferentiation):
        return 1, "the run with its exact sensitivities"
    return 2 * p + 1, "the run and 2 per parameter: central differences"


__all__ = ["FAILED_RUN_COST", "FAILED_SHARE", "RunTimes", "StagePlan", "likely_iterations", "method_plan", "plan_seconds", "plural", "runs_per_linearisation",
           "stage_seconds"]
