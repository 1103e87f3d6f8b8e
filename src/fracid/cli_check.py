"""``fracid check CONFIG``: validate a configuration and print what running it would do, without doing it.

The plan: the specimen and its mesh (nodes, elements, unknowns, element sizes), the model and its
parameters, the data blocks, the identified parameters and their bounds, the stages with their forward
runs, and (unless ``--no-time``) a time estimate from one timed forward run at ``[model.parameters]``.
A warning names the key that makes a run slow (more than :data:`SLOW_RUN` seconds) or the whole plan
long (more than :data:`SLOW_PLAN` seconds on the available workers).
"""

from __future__ import annotations

import math
import time
from pathlib import Path

import numpy as np

from fracid.cli_common import load, plural, warn

#: one forward run slower than this [s] is warned about
SLOW_RUN = 30.0
#: a whole plan longer than this [s] on the available workers is warned about
SLOW_PLAN = 3600.0
#: a run with exact sensitivities costs this many plain runs (benchmarks/sensitivities.py: 1.65 on the demo beam)
SENSITIVITY_COST = 1.65


def add_parser(sub, common) -> None:
    """The ``check`` subcommand's arguments (the common options: ``--workers`` sizes the time estimate)."""
    p = sub.add_parser("check", parents=[common], help="validate a configuration and print its plan and cost")
    p.add_argument("config", type=Path, help="TOML configuration file")
    p.add_argument("--no-time", action="store_true", help="do not time a forward run (no time estimate)")


def kalman_cost(operator, settings, n_y, p) -> dict:
    """The Kalman stage's cost: ``steps`` per pass, ``per_step`` runs per step (1 when the model
    differentiates its runs exactly, :func:`fracid.inverse.sensitivity.exact_sensitivity`; else the run
    and 2 per parameter, central differences), ``first`` (the first pass in full-curve runs: step t runs
    up to observation t/steps of the curve), ``later`` (runs of each later pass: one linearisation,
    :func:`fracid.inverse.kalman.kalman_filter`), ``passes`` at most, ``final`` (the run at the estimate)
    and ``how`` (the words for ``per_step``). Backtracking over failed or worse points adds runs."""
    from fracid.inverse.sensitivity import DirectDifferentiation, exact_sensitivity

    groups = settings.get("groups")
    steps = n_y if groups is None else len(groups)
    exact = isinstance(exact_sensitivity(operator)[1], DirectDifferentiation)
    per_step = 1 if exact else 2 * p + 1
    how = ("the run with its exact sensitivities" if exact else
           "the run and 2 per parameter: central differences")
    return {"steps": steps, "per_step": per_step, "first": per_step * (steps + 1) / 2, "later": per_step,
            "passes": settings["max_iterations"], "final": per_step, "how": how}


def _mesh_sizes(description) -> tuple:
    """(smallest, largest) element side [mm]: corner to corner (2D), element length (bar)."""
    cells = description.cells
    if cells.shape[1] == 2:  # a bar: vertex i is node 2 i
        lengths = np.abs(np.diff(description.nodes[2 * cells][..., 0], axis=1))
    else:
        corners = description.nodes[cells[:, :(3 if cells.shape[1] == 6 else 4)]]
        lengths = np.linalg.norm(corners - np.roll(corners, -1, axis=1), axis=-1)
    return float(lengths.min()), float(lengths.max())


def mesh_key(cfg) -> str:
    """The key that sets the mesh's size: ``specimen.h_fine``, ``specimen.n_elements`` or the mesh file."""
    from fracid.config import build_specimen

    specimen = build_specimen(cfg)
    for name in ("h_fine", "n_elements"):
        if hasattr(specimen, name):
            return f"specimen.{name} = {getattr(specimen, name):g}"
    return "specimen.file (the mesh)"


def specimen_lines(cfg, model, params) -> list:
    """The specimen, its control and its mesh: nodes, elements, unknowns (of this model), element sizes."""
    from fracid.config import build_specimen

    specimen = build_specimen(cfg)
    description = specimen.describe()
    unknowns = getattr(model.build(description, params), "n_free", None)
    smallest, largest = _mesh_sizes(description)
    options = dict(cfg.specimen.options)
    options = (f"file {options['path']}" if cfg.specimen.type == "mesh" else
               ", ".join(f"{k} = {v}" for k, v in options.items()) or "defaults")
    return [f"specimen: {cfg.specimen.type} ({type(specimen).__name__}; {options}), control {cfg.specimen.control}",
            f"mesh: {len(description.nodes):,} nodes, {len(description.cells):,} elements, "
            f"{'?' if unknowns is None else f'{unknowns:,}'} unknowns; element sides {smallest:.3g} to {largest:.3g} mm "
            f"({mesh_key(cfg)})"]


def model_lines(cfg, params) -> list:
    """The model type and every parameter value with its unit."""
    units = params.units()
    values = ", ".join(f"{name} = {getattr(params, name):g}{'' if units[name] == '-' else ' ' + units[name]}"
                       for name in params.names())
    return [f"model: {cfg.model.type}; [model.parameters]: {values}"]


def data_lines(data) -> list:
    """Every data block: points, control range, largest value, std."""
    lines = []
    for name, a, b in data.blocks:
        c, y, s = data.control[a:b], data.y[a:b], data.std[a:b]
        lines.append(f"data block {name!r}: {b - a} points, control {c.min():.4g} to {c.max():.4g} mm, "
                     f"peak {np.max(np.abs(y)):.4g}, std {s.min():.3g} to {s.max():.3g} (mean {s.mean():.3g})")
    return lines


def identify_lines(cfg) -> list:
    """The identified parameters with their bounds (and log scale)."""
    ident = cfg.identify
    bounds = ", ".join(f"{name} in [{lo:g}, {hi:g}]{' (log)' if name in ident.log else ''}"
                       for name, lo, hi in zip(ident.parameters, ident.lower, ident.upper))
    return [f"identified: {bounds}; the others fixed at [model.parameters]"]


def identify_plan(cfg, operator, settings, n_y) -> dict:
    """Forward runs of the identification's stages: ``knn`` runs (side by side), Kalman ``kalman`` runs
    at most and ``kalman_full`` full-curve equivalents (one after another), and the cost dict."""
    p = len(cfg.identify.parameters)
    cost = kalman_cost(operator, settings, n_y, p)
    knn = cfg.identify.knn.population(p)
    later = (cost["passes"] - 1) * cost["later"] + cost["final"]
    return {"knn": knn, "kalman": cost["steps"] * cost["per_step"] + later, "kalman_full": cost["first"] + later,
            "cost": cost}


def plan_lines(cfg, plan) -> list:
    """The stages of the identification and their forward runs; what ``fracid posterior`` adds."""
    cost, knn = plan["cost"], cfg.identify.knn
    lines = [f"stage KNN: {plan['knn']} forward runs side by side ({knn.method}, k = {knn.k}; [identify.knn] n)",
             f"stage Kalman filter: {cost['steps']} steps per pass, {plural(cost['per_step'], 'run')} per step "
             f"({cost['how']}), at most {cost['passes']} passes and a run at the estimate: at most "
             f"{plural(plan['kalman'], 'run')} one after another without backtracking, "
             f"about {plan['kalman_full']:.0f} full-curve runs ([identify.kalman] groups, max_iterations)"]
    post = cfg.posterior
    lines.append(f"fracid posterior adds at most {post.samples_per_round * post.max_rounds} runs "
                 f"([posterior] samples_per_round x max_rounds)")
    return lines


def _timed_run(cfg, model, specimen, params, operator) -> float:
    """Seconds of one forward run at [model.parameters]: the identification's (``operator``) or the
    simulation's. A failed run raises (a ConvergenceError: exit 3)."""
    from fracid.config import simulate_settings
    from fracid.exits import UsageError

    start = time.perf_counter()
    if operator is None:
        settings = simulate_settings(cfg)
        settings.pop("regularization", None)
        model.simulate(specimen, params, **settings)
        return time.perf_counter() - start
    record = operator(np.array([getattr(params, name) for name in operator.names]))
    if not record.ok:
        raise UsageError(f"{cfg.path}: the forward run at [model.parameters] failed ({record.error}); "
                         "set values for which the analysis runs")
    return time.perf_counter() - start


def time_lines(cfg, seconds, plan, workers) -> list:
    """The time estimate, and a warning for a slow run or plan naming the key that makes it so."""
    lines = [f"time: one forward run at [model.parameters] took {seconds:.1f} s"]
    if seconds > SLOW_RUN:
        warn(f"one forward run takes {seconds:.0f} s (over {SLOW_RUN:.0f} s): the mesh makes it so "
             f"({mesh_key(cfg)}); a coarser mesh runs faster, if it still resolves the process zone")
    if plan is None:
        return lines
    knn_s = math.ceil(plan["knn"] / workers) * seconds
    kalman_s = plan["kalman_full"] * seconds * (SENSITIVITY_COST if plan["cost"]["per_step"] == 1 else 1.0)
    total = knn_s + kalman_s
    lines.append(f"estimate for fracid identify on {workers} worker(s): KNN {_duration(knn_s)}, Kalman filter at most "
                 f"{_duration(kalman_s)}: at most {_duration(total)}")
    if total > SLOW_PLAN:
        key = (f"[identify.knn] n = {cfg.identify.knn.n}" if knn_s >= kalman_s else
               "[identify.kalman] groups and max_iterations")
        warn(f"the identification may take {_duration(total)} (over {_duration(SLOW_PLAN)}) on {workers} worker(s): "
             f"mostly because of {key}, with each run taking {seconds:.1f} s ({mesh_key(cfg)}); --workers or a "
             "Dask cluster (--scheduler) shares the KNN stage")
    return lines


def _duration(seconds: float) -> str:
    if seconds < 90:
        return f"{seconds:.0f} s"
    if seconds < 5400:
        return f"{seconds / 60:.0f} min"
    return f"{seconds / 3600:.1f} h"


def run_check(args) -> int:
    """``fracid check``: print the plan of the configuration; exit 2 (with the message) if it is invalid."""
    from fracid.config import build_data, build_model, build_operator, build_parameters, build_specimen
    from fracid.config import identify_settings
    from fracid.parallel import available_cores

    cfg = load(args, args.config, "simulate")  # [[experiments]] and [identify] validated when present
    purpose = "identify" if cfg.experiments and cfg.identify is not None else "simulate"
    model, params = build_model(cfg), build_parameters(cfg)
    lines = [f"configuration {cfg.path}: valid (for fracid {purpose}{' and simulate' if purpose == 'identify' else ''})"]
    lines += specimen_lines(cfg, model, params) + model_lines(cfg, params)
    operator = plan = None
    if purpose == "identify":
        data = build_data(cfg)
        operator = build_operator(cfg, data)
        plan = identify_plan(cfg, operator, identify_settings(cfg), data.n_y)
        lines += data_lines(data) + identify_lines(cfg) + plan_lines(cfg, plan)
    else:
        lines.append("plan: fracid simulate, one forward run (no [[experiments]] and [identify]: nothing to identify)")
    print("\n".join(lines), flush=True)
    if args.no_time:
        print("time: not measured (--no-time)")
        return 0
    seconds = _timed_run(cfg, model, build_specimen(cfg), params, operator)
    workers = args.workers or (1 if args.scheduler else available_cores())
    print("\n".join(time_lines(cfg, seconds, plan, workers)))
    return 0
