"""``fracid check``'s time estimate: forward runs timed (:func:`timed_runs`) and the plan's wall time from them,
a likely value and an upper one, with the assumptions they rest on (:func:`time_lines`).

The runs: the first at ``[model.parameters]`` (it carries the first call's warm-up: imports, caches; not
counted unless it is the only one), two across the bounds (at 1/4 and 3/4 of the ranges: runs differ across the
box the population covers) and, for a plan with exact sensitivities, one with them at ``[model.parameters]``
(its cost against a plain run is measured, not assumed) and, for a population on a screening mesh
(``[identify.knn] screening``), one on that mesh at ``[model.parameters]``. A first run over :data:`SLOW_RUN` seconds is the only
one. The stages' counts are the method's plan (:class:`~fracid.inverse.core.plans.StagePlan`); the arithmetic
is :func:`~fracid.inverse.core.plans.plan_seconds`.
"""

from __future__ import annotations

import os
import time
from dataclasses import dataclass

import numpy as np

from fracid.cli.common import warn

#: one forward run slower than this [s] is warned about, and is the only one timed
SLOW_RUN = 30.0
#: a whole plan longer than this [s] on the available workers is warned about
SLOW_PLAN = 3600.0
#: a run with exact sensitivities costs this many plain runs when it is not timed (benchmarks/sensitivities.py:
#: 1.65 on the demo beam on a quiet machine; 2.3 measured on a loaded one)
SENSITIVITY_COST = 1.65
#: seconds of ``fracid identify`` besides its forward runs: the start (imports) and the report and figures
#: (3.2 s on the bar and the demo beam, benchmarks/check_estimate.py)
REPORT_SECONDS = 3.0
#: where the runs across the bounds are, in the unit cube of the identified parameters (alternating per parameter)
ACROSS = (0.25, 0.75)


@dataclass(frozen=True)
class Timing:
    """The timed forward runs of ``fracid check`` [s].

    Attributes
    ----------
    first : float
        The run at ``[model.parameters]``, with the first call's warm-up.
    across : tuple of float
        Plain runs across the bounds (empty when not timed); ``failed`` of them failed (their time counts).
    exact : float or None
        The run with exact sensitivities at ``[model.parameters]`` (None: not timed).
    load : float
        The machine's 1-min load average before the runs (``os.getloadavg()``; NaN where unknown).
    screened : float or None
        A plain run on the population's screening mesh at ``[model.parameters]`` (None: not timed).
    """

    first: float
    across: tuple = ()
    failed: int = 0
    exact: float | None = None
    load: float = float("nan")
    screened: float | None = None

    @property
    def plain(self) -> float:
        """A plain run's time: the mean of the runs across the bounds, or the first run alone."""
        return float(np.mean(self.across)) if self.across else self.first

    @property
    def with_sensitivities(self) -> float:
        """A run with exact sensitivities: timed, or :data:`SENSITIVITY_COST` plain runs."""
        return self.exact if self.exact is not None else SENSITIVITY_COST * self.plain


def machine_load() -> float:
    """The 1-min load average (NaN where the OS does not report it)."""
    try:
        return float(os.getloadavg()[0])
    except (AttributeError, OSError):
        return float("nan")


def _seconds(run) -> tuple[float, bool]:
    start = time.perf_counter()
    ok = run()
    return time.perf_counter() - start, ok


def across_points(space) -> np.ndarray:
    """Two points of ``space`` (a :class:`~fracid.inverse.core.space.ParameterSpace`) across its box: at
    :data:`ACROSS` of each range, alternating per parameter (in log where the parameter is log-scaled)."""
    p = len(space.names)
    low, high = ACROSS
    unit = np.array([[low if i % 2 == 0 else high for i in range(p)], [high if i % 2 == 0 else low for i in range(p)]])
    return space.from_unit(unit)


def timed_runs(cfg, model, specimen, params, operator, space=None, exact=False, screening=None) -> Timing:
    """:class:`Timing` of the forward runs: the identification's (``operator``, with ``space`` its bounds;
    ``exact``: its plan has runs with exact sensitivities; ``screening``: the operator of a population on a
    screening mesh, timed too) or, without one, the simulation's one run. A failed run at ``[model.parameters]``
    exits 2 (a usage error); a failed run across the bounds is counted.
    """
    from fracid.config import simulate_settings
    from fracid.runtime.exits import UsageError

    load = machine_load()
    if operator is None:
        settings = simulate_settings(cfg)
        settings.pop("regularization", None)
        return Timing(_seconds(lambda: model.simulate(specimen, params, **settings))[0], load=load)
    x = np.array([getattr(params, name) for name in operator.names])
    record = []
    first, _ = _seconds(lambda: record.append(operator(x)) or True)
    if not record[0].ok:
        raise UsageError(f"{cfg.path}: the forward run at [model.parameters] failed ({record[0].error}); "
                         "set values for which the analysis runs")
    if first > SLOW_RUN:
        return Timing(first, load=load)
    across = [_seconds(lambda: operator(point).ok) for point in (across_points(space) if space is not None else [])]
    with_s = None
    if exact:
        differentiated = operator.differentiated()
        with_s, _ = _seconds(lambda: differentiated(x).ok)
    coarse = _seconds(lambda: screening(x).ok)[0] if screening is not None else None
    return Timing(first, tuple(t for t, _ in across), sum(not ok for _, ok in across), with_s, load, coarse)


def timing_line(timing: Timing) -> str:
    """``"time: ..."``: what was timed and how long it took."""
    if not timing.across:
        slow = f" (over {SLOW_RUN:.0f} s: the only run timed, its warm-up included)" if timing.first > SLOW_RUN else ""
        return f"time: one forward run at [model.parameters] took {_secs(timing.first)} s{slow}"
    low, high = ACROSS
    failed = f", {timing.failed} of them failed" if timing.failed else ""
    text = (f"time: one forward run took {_secs(timing.plain)} s (the mean of {len(timing.across)} runs across the bounds, "
            f"at {low:g} and {high:g} of the ranges: {', '.join(_secs(t) for t in timing.across)} s{failed}; "
            f"the first, at [model.parameters], took {timing.first:.1f} s with its warm-up and is not counted)")
    if timing.exact is not None:
        text += (f"; with exact sensitivities {_secs(timing.exact)} s at [model.parameters] "
                 f"({timing.exact / timing.plain:.2f} times a plain run)")
    if timing.screened is not None:
        text += (f"; on the population's screening mesh {_secs(timing.screened)} s at [model.parameters] "
                 f"({timing.screened / timing.plain:.2f} times a plain run on the configured mesh)")
    return text


def time_lines(cfg, timing: Timing, plan, workers: int, cores: int, refits=(0, 0), mesh_key=str) -> list:
    """The time estimate: its likely and upper values, per stage, and what they assume; a warning for a slow
    run or plan naming the key that makes it so (``mesh_key(cfg)``: the key of the mesh's size)."""
    from fracid.inverse.core.plans import FAILED_RUN_COST, FAILED_SHARE, RunTimes, plan_seconds, stage_seconds

    lines = [timing_line(timing)]
    if timing.plain > SLOW_RUN:
        warn(f"one forward run takes {timing.plain:.0f} s (over {SLOW_RUN:.0f} s): the mesh makes it so "
             f"({mesh_key(cfg)}); a coarser mesh runs faster, if it still resolves the process zone")
    if not plan:
        return lines
    times = RunTimes(timing.plain, timing.with_sensitivities, workers, cores, timing.screened)
    likely, upper = (t + REPORT_SECONDS for t in plan_seconds(plan, times, refits))
    lines.append(f"estimate for fracid identify on {workers} worker(s): about {_duration(likely)}, "
                 f"at most {_duration(upper)}")
    lines.append("  likely: " + ", ".join(f"{s.label} {_duration(stage_seconds(s, times))}"
                                          + (f" ({s.likely_text})" if s.likely_text and not s.side_by_side else "")
                                          for s in plan) + ", no failed run" + _refits_text(refits[0]))
    lines.append("  at most: " + ", ".join(f"{s.label} {_duration(stage_seconds(s, times, upper=True))}"
                                           + (f" ({s.starts} starts: {s.starts_key})" if s.starts > 1 else "")
                                           for s in plan)
                 + f", if up to 1 in {round(1 / FAILED_SHARE)} runs fail (a failed run is run again with smaller steps: "
                 f"up to {FAILED_RUN_COST} runs' time)" + _refits_text(refits[1]))
    lines.append("  assumes: " + assumptions(timing, times))
    if upper > SLOW_PLAN:
        slowest = max(plan, key=lambda s: stage_seconds(s, times, upper=True))
        warn(f"the identification may take {_duration(upper)} (over {_duration(SLOW_PLAN)}) on {workers} worker(s): "
             f"mostly because of {slowest.keys or slowest.label}, with each run taking {times.run(slowest):.1f} s "
             f"({mesh_key(cfg)}); --workers or a Dask cluster (--scheduler) shares the stages whose runs are side "
             "by side")
    return lines


def assumptions(timing: Timing, times) -> str:
    """What the estimate assumes: the workers and cores, the runs' time, the load when timed, the start and report."""
    cores = f"{times.cores} core(s)" + (f": {times.workers} workers share them" if times.workers > times.cores else "")
    exact = ("" if timing.exact is not None else
             f"; a run with exact sensitivities as {SENSITIVITY_COST:g} plain runs (not timed)")
    load = ("the machine's load unknown when timed" if not np.isfinite(timing.load) else
            f"the machine's load {timing.load:.2f} (1-min average) on {times.cores} core(s) when timed"
            + (" (busy: on a quiet machine the runs are faster)" if timing.load >= times.cores else ""))
    return (f"{times.workers} worker(s) on {cores}; every run as long as the timed ones{exact}; {load}: a machine "
            f"busier during the identification makes it longer; {REPORT_SECONDS:.0f} s to start and write the report")


def _refits_text(count: int) -> str:
    return f"; the local stages {count} more time(s) for the error terms" if count else ""


def _secs(seconds: float) -> str:
    """A run's seconds to 3 digits (a whole number from 100 s)."""
    return f"{seconds:.3g}" if seconds < 100 else f"{seconds:.0f}"


def _duration(seconds: float) -> str:
    if seconds < 10:
        return f"{seconds:.1f} s"
    if seconds < 90:
        return f"{seconds:.0f} s"
    if seconds < 5400:
        return f"{seconds / 60:.1f} min" if seconds < 600 else f"{seconds / 60:.0f} min"
    return f"{seconds / 3600:.1f} h"


__all__ = ["REPORT_SECONDS", "SENSITIVITY_COST", "SLOW_PLAN", "SLOW_RUN", "Timing", "across_points", "machine_load",
           "time_lines", "timed_runs", "timing_line"]
