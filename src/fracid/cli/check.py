"""``fracid check CONFIG``: validate a configuration and print what running it would do, without doing it.

The plan: the specimen and its mesh (nodes, elements, unknowns, element sizes), the model and its
parameters, the data blocks, the identified parameters and their bounds, the stages with their forward
runs, and (unless ``--no-time``) a time estimate from timed forward runs, likely and at most, with its
assumptions (:mod:`fracid.cli.check_time`). A warning names the key that makes a run slow (more than
:data:`~fracid.cli.check_time.SLOW_RUN` seconds) or the whole plan long (more than
:data:`~fracid.cli.check_time.SLOW_PLAN` seconds on the available workers).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from fracid.cli.check_time import time_lines, timed_runs
from fracid.cli.common import load, output_path, run_inputs



def add_parser(sub, parents) -> None:
    """The ``check`` subcommand's arguments (the common options: ``--workers`` sizes the time estimate)."""
    p = sub.add_parser("check", parents=[parents.common], help="validate a configuration and print its plan and cost")
    p.add_argument("config", type=Path, help="TOML configuration file")
    p.add_argument("--no-time", action="store_true", help="do not time a forward run (no time estimate)")
    p.set_defaults(run=run_check)


def mesh_key(cfg) -> str:
    """The key that sets the mesh's size, as the specimen declares it (its
    :meth:`~fracid.specimens.protocol.Specimen.resolution`): ``specimen.h_fine = 1``, ``specimen.n_elements
    = 200``, ``specimen.file (the mesh)``."""
    from fracid.config import build_specimen

    field = build_specimen(cfg).resolution()
    if field.field is None:
        return "[specimen] (its mesh)"
    if isinstance(field.value, (int, float)):
        return f"specimen.{field.field} = {field.value:g}"
    return f"specimen.{field.field} (the mesh)"


def specimen_lines(cfg, model, params) -> list:
    """The specimen, its control and its mesh: nodes, elements, unknowns (of this model), element sizes."""
    from fracid.config import build_specimen
    from fracid.specimens.protocol import element_sides

    specimen = build_specimen(cfg)
    description = specimen.describe()
    unknowns = model.build(description, params).n_free
    smallest, largest = element_sides(description)
    options = specimen.options_text(dict(cfg.specimen.options))
    return [f"specimen: {cfg.specimen.type} ({type(specimen).__name__}; {options}), control {cfg.specimen.control}",
            f"mesh: {len(description.nodes):,} nodes, {len(description.cells):,} elements, "
            f"{unknowns:,} unknowns; element sides {smallest:.3g} to {largest:.3g} mm ({mesh_key(cfg)})"]


def model_lines(cfg, params) -> list:
    """The model type and every parameter value with its unit."""
    units = params.units()
    values = ", ".join(f"{name} = {getattr(params, name):g}{'' if units[name] == '-' else ' ' + units[name]}"
                       for name in params.names())
    return [f"model: {cfg.model.type}; [model.parameters]: {values}"]


def data_lines(data, cfg=None) -> list:
    """Every data block: points, control range, largest value, std in the block's unit; a block whose kind
    describes itself (``check_lines``: a field's frames, points, noise and placement) in its own words."""
    kinds = {getattr(exp, "name", None): exp for exp in (cfg.experiments if cfg is not None else ())}
    lines = []
    for name, a, b in data.blocks:
        exp = kinds.get(name)
        if hasattr(exp, "check_lines"):
            from fracid.config import build_specimen

            lines += exp.check_lines(build_specimen(cfg))
            continue
        lines.append(curve_block_line(name, exp, data.control[a:b], data.y[a:b], data.std[a:b]))
    return lines


def curve_block_line(name: str, exp, control, y, std) -> str:
    """A block of values over the control: points, control range, largest value, std, in the units the block
    gives (``given_units``: its control and value units; mm and N or mm when it gives none), the control also
    in mm when given in another unit. ``control`` [mm], ``y`` and ``std`` [N or mm] as the data holds them."""
    internal = "N" if getattr(exp, "measures_force", True) else "mm"
    (c_unit, c_scale), (unit, scale) = exp.given_units() if hasattr(exp, "given_units") else (("mm", 1.0),
                                                                                               (internal, 1.0))
    c, y, s = control / c_scale, y / scale, std / scale
    in_mm = "" if c_unit == "mm" else f" ({control.min():.4g} to {control.max():.4g} mm)"
    return (f"data block {name!r}: {len(y)} points, control {c.min():.4g} to {c.max():.4g} {c_unit}{in_mm}, "
            f"peak {np.max(np.abs(y)):.4g} {unit}, std {s.min():.3g} to {s.max():.3g} {unit} (mean {s.mean():.3g})")


def identify_lines(cfg) -> list:
    """The identified parameters with their bounds (and log scale)."""
    ident = cfg.identify
    bounds = ", ".join(f"{name} in [{lo:g}, {hi:g}]{' (log)' if name in ident.log else ''}"
                       for name, lo, hi in zip(ident.parameters, ident.lower, ident.upper))
    return [f"identified: {bounds}; the others fixed at [model.parameters]"]


def identify_plan(method, operator, n_y: int, p: int, space=None) -> list:
    """The stages of the configured inverse method and their forward runs (its ``plan``:
    :class:`~fracid.inverse.core.plans.StagePlan` per stage; empty for a method without one)."""
    from fracid.inverse.core.plans import method_plan

    return method_plan(method, operator, n_y, p, space)


def plan_lines(cfg, method, plan) -> list:
    """The stages of the identification and their forward runs; what ``fracid posterior`` adds."""
    lines = [stage.line() for stage in plan] or [f"stages of {method.name}: no plan of their forward runs"]
    post = cfg.posterior
    if post.screening > 1:
        from fracid.inverse.sampling.screened import COARSE_ROUND

        lines.append(f"fracid posterior adds at most {COARSE_ROUND * post.samples_per_round * post.max_rounds} runs "
                     f"on a mesh {post.screening:g} times coarser ({COARSE_ROUND} x [posterior] samples_per_round x "
                     f"max_rounds) and at most {post.fine_runs} fine runs ([posterior] screening, fine_runs)")
    else:
        lines.append(f"fracid posterior adds at most {post.samples_per_round * post.max_rounds} runs "
                     f"([posterior] samples_per_round x max_rounds)")
    return lines + error_terms_lines(cfg)


def error_terms_lines(cfg) -> list:
    """What ``[identify] discretisation_error`` and ``model_error`` add: the refinement again with them (its
    population reused from the run store) and a run on a refined mesh; none when both are off."""
    terms = error_terms_of(cfg)
    if terms is None:
        return []
    parts = []
    if terms.discretisation is not None:
        disc = terms.discretisation
        parts.append(f"a run at the estimate on a mesh {disc.refinement:g} times finer"
                     + (" and one as much coarser" if disc.observed_order else "")
                     + (", at every loop" if disc.iterations > 1 else ", once"))
    if terms.model_error is not None:
        parts.append("the model error's std at every estimate (from the stored run there)")
    return [f"error terms: the identification again with them, at most {terms.loops} time(s), its population "
            f"reused from the run store; {'; '.join(parts)} (the refined mesh's runs are not in the time estimate)"]


def error_terms_of(cfg):
    """The configuration's :class:`~fracid.inverse.likelihood.terms.ErrorTerms`; None when both are off."""
    from fracid.inverse.likelihood.terms import ErrorTerms

    terms = ErrorTerms(cfg.identify.discretisation_error, cfg.identify.model_error)
    return None if terms.discretisation is None and terms.model_error is None else terms


def refits(cfg) -> tuple:
    """(likely, most) identifications after the first, for the error terms: (1, their loops), (0, 0) without."""
    terms = error_terms_of(cfg) if cfg.identify is not None else None
    return (0, 0) if terms is None else (1, terms.loops)





def run_check(args) -> int:
    """``fracid check``: print the plan of the configuration; exit 2 (with the message) if it is invalid."""
    from fracid.config import (build_data, build_method, build_model, build_operator, build_parameters, build_space,
                               build_specimen)
    from fracid.runtime.executors import available_cores
    from fracid.store.outputs import check_outputs

    cfg = load(args, args.config, "simulate")  # [[experiments]] and [identify] validated when present
    purpose = "identify" if cfg.experiments and cfg.identify is not None else "simulate"
    check_outputs(output_path(args, cfg), purpose, run_inputs(cfg))  # refused here as the run would refuse it
    model, params = build_model(cfg), build_parameters(cfg)
    lines = [f"configuration {cfg.path}: valid (for fracid {purpose}{' and simulate' if purpose == 'identify' else ''})"]
    lines += specimen_lines(cfg, model, params) + model_lines(cfg, params)
    operator = plan = None
    if purpose == "identify":
        data = build_data(cfg)
        operator = build_operator(cfg, data)
        method = build_method(cfg)
        plan = identify_plan(method, operator, data.n_y, len(cfg.identify.parameters), build_space(cfg))
        lines += data_lines(data, cfg) + identify_lines(cfg) + plan_lines(cfg, method, plan)
        from fracid.cli.check_figures import check_figure_lines

        lines += check_figure_lines(cfg, output_path(args, cfg), list(run_inputs(cfg)))
    else:
        lines.append("plan: fracid simulate, one forward run (no [[experiments]] and [identify]: nothing to identify)")
    print("\n".join(lines), flush=True)
    if args.no_time:
        print("time: not measured (--no-time)")
        if operator is not None:
            from fracid.cli.check_frames import skipped_ranking_lines

            print("\n".join(skipped_ranking_lines(cfg, data)))
        return 0
    space = build_space(cfg) if operator is not None else None
    screening = next((s.operator for s in plan or [] if s.operator is not None), None)  # a population's coarse mesh
    timing = timed_runs(cfg, model, build_specimen(cfg), params, operator, space, any(s.exact for s in plan or []),
                        screening)
    workers = args.workers or (1 if args.scheduler else available_cores())
    cores = workers if args.scheduler else available_cores()  # a cluster's cores are its own
    refit = refits(cfg) if operator is not None else (0, 0)
    print("\n".join(time_lines(cfg, timing, plan, workers, cores, refit, mesh_key)))
    if operator is not None:
        from fracid.cli.check_frames import frame_ranking_lines

        print("\n".join(frame_ranking_lines(cfg, data, operator, space)), flush=True)
    return 0
