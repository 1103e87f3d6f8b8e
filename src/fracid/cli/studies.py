"""The ``fracid`` commands that study the identification rather than make it: ``study`` (and its parts
``uniqueness`` and ``stability``), ``sensitivity`` and ``size-effect``. :func:`fracid.cli.dispatch.main` dispatches
here; the shared plumbing (loading, output directory and run store, executor, messages) is in
:mod:`fracid.cli.common`.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

from fracid.cli.common import (command_executor, load, out_dir, progress_choice, provenance, say, warn, working_in,
                               wrote)


def add_parser(sub, parents) -> None:
    """The study commands' arguments: ``study``, ``uniqueness`` and ``stability`` keep a run store."""
    for name, text, parent in (
            ("study", "identification with uniqueness, stability and prediction checks, and a verdict", parents.stored),
            ("uniqueness", "the study's uniqueness stages only: objective maps, valley, multi-start", parents.stored),
            ("stability", "the study's stability stage only: identification on noisy replicates", parents.stored),
            ("sensitivity", "sensitivities and information along the load history", parents.common),
            ("size-effect", "nominal strength versus size and Bazant's size effect law", parents.common)):
        p = sub.add_parser(name, parents=[parent], help=text)
        p.add_argument("config", type=Path, help="TOML configuration file")
        if name == "size-effect":
            p.add_argument("--sizes", type=float, nargs="+", help="sizes D [mm] (default: those of the experiments)")
        p.set_defaults(run=run)


def run(args) -> int:
    """Run the study command ``args.command``; its exit status."""
    if args.command in _STUDY_PARTS:
        return run_study_command(args)
    if args.command == "sensitivity":
        return run_sensitivity_command(args)
    return run_size_effect_command(args)


def _size_effect(cfg, params, executor, sizes=(), quiet=True):
    """:func:`~fracid.inverse.studies.size_effect.compare_size_effect` over the sizes of the force experiments
    (and ``sizes``) with the measured nominal strength of those experiments; None below three sizes."""
    from dataclasses import replace

    from fracid.config import build_experiment_data, build_model, build_specimen
    from fracid.inverse.studies.size_effect import compare_size_effect, nominal_strength, specimen_size

    specimens, measured, calibrated = {}, {}, set()
    for exp in cfg.experiments:
        if not exp.measures_force:
            continue
        specimen = build_specimen(cfg, exp)
        D = specimen_size(specimen)
        specimens[D] = specimen
        measured.setdefault(D, []).append(nominal_strength(specimen, float(np.max(build_experiment_data(cfg, exp).y))))
        if exp.role == "calibration":
            calibrated.add(D)
    base = next(iter(specimens.values()), None) or build_specimen(cfg)
    size_field = base.size_field
    if size_field is None:
        from fracid.runtime.exits import UsageError

        raise UsageError(f"the specimen {type(base).__name__} declares no size_field: a size-effect series cannot "
                         "scale it")
    for D in sizes or ():
        try:
            specimens.setdefault(float(D), replace(base, **{size_field: float(D)}))
        except ValueError as err:
            from fracid.runtime.exits import UsageError

            raise UsageError(f"--sizes {D:g}: not a valid {type(base).__name__}.{size_field} ({err})") from None
    return compare_size_effect(params, specimens, measured, calibrated, model=build_model(cfg), executor=executor,
                               progress=False if quiet else None)


def _has_size(cfg) -> bool:
    from fracid.config import build_specimen
    from fracid.inverse.studies.size_effect import has_nominal_strength

    return has_nominal_strength(build_specimen(cfg))


#: subcommands that run part of the study: [study] settings they override (only the full study samples
#: the posterior of [study] posterior = true)
_STUDY_PARTS = {"study": {}, "uniqueness": {"replicates": 0, "posterior": None},
                "stability": {"starts": 0, "posterior": None}}


def _study_settings(cfg, command):
    """The :class:`~fracid.inverse.studies.study.StudySettings` of ``[study]`` with the configured inverse method; a
    method that cannot run the study's stages is the configuration's error (exit 2)."""
    from fracid.config import ConfigError, build_method, study_settings
    from fracid.inverse.methods.registry import StudyMethod
    from fracid.inverse.studies.study import StudySettings

    method = build_method(cfg)
    if not isinstance(method, StudyMethod):
        raise ConfigError(f"{cfg.path}: identify.method = {method.name!r}: `fracid {command}` runs the stages of an "
                          "inverse method (a search over a population, a refinement, a local fit from a point: "
                          "fracid.inverse.methods.registry.StudyMethod), which this method does not declare; use it with "
                          "`fracid identify`")
    return StudySettings(method=method).replace(**{**study_settings(cfg), **_STUDY_PARTS[command]})


def run_study_command(args) -> int:
    from fracid.config import build_data, build_held_out, build_operator, build_space
    from fracid.inverse.studies.study import run_study
    from fracid.report.study import write_study

    cfg = load(args, args.config, "identify")
    data = build_data(cfg)
    operator, space = build_operator(cfg, data), build_space(cfg)
    settings = _study_settings(cfg, args.command)
    if cfg.study.posterior and settings.posterior is None:
        say(args, f"posterior: skipped ([study] posterior = true is for `fracid study`, not `fracid {args.command}`)")
    held_out = build_held_out(cfg) if args.command == "study" else []
    out = out_dir(args, cfg)
    with working_in(args, out, store=True) as store, command_executor(args) as executor:
        study = run_study(operator, data, space, settings, held_out=held_out, executor=executor, store=store,
                          progress=progress_choice(args), log=lambda text: say(args, text),
                          retry_failed=args.retry_failed)
        size = None
        if args.command == "study" and not _has_size(cfg):
            say(args, f"size effect: skipped (the specimen {cfg.specimen.type!r} declares no characteristic size "
                      "and nominal section)")
        elif args.command == "study":
            size = _size_effect(cfg, operator.parameters(study.identification.x), executor, quiet=args.quiet)
        record = provenance(args, cfg, operator, space, store)
    if size is not None:
        size.save(out)
    written = write_study(out, study, data, title=f"fracid study: {Path(cfg.path).name}", provenance=record,
                          size_effect=size.figure_arguments() if size is not None else None)
    say(args, study.summary())
    wrote(args, out, [p if isinstance(p, str) else Path(p).relative_to(out).as_posix() for p in written])
    for text in study.identification.warnings():
        warn(text)
    if study.posterior is not None and not study.posterior.converged:
        warn(f"posterior: {study.posterior.status}")
    elif settings.posterior is not None and study.posterior is None:
        warn("posterior: not sampled (see the notes of verdict.txt); the verdict reads the Gaussian std")
    return 0


def run_sensitivity_command(args) -> int:
    from fracid.config import build_data, build_operator, build_parameters, build_space
    from fracid.inverse.core.sensitivity import sensitivity_history
    from fracid.inverse.core.runs import StoredOperator
    from fracid.inverse.studies.uniqueness import bounds_covariance
    from fracid.report.figures import sensitivity_figure, to_png

    cfg = load(args, args.config, "identify")
    data = build_data(cfg)
    operator, space = build_operator(cfg, data), build_space(cfg)
    params = build_parameters(cfg)
    x = np.array([getattr(params, n) for n in space.names])
    out = out_dir(args, cfg)
    with working_in(args, out, store=True) as store, command_executor(args) as executor:
        history = sensitivity_history(StoredOperator(operator, store, retry_failed=args.retry_failed), x,
                                      data.covariance, bounds_covariance(space), names=space.names,
                                      blocks=data.blocks, executor=executor)
    columns = ["control_mm", "y"] + [f"S_{n}" for n in space.names] + [f"variance_removed_{n}" for n in space.names]
    np.savetxt(out / "sensitivity.csv", np.column_stack([data.control, history.y, history.normalised,
                                                         history.variance_share]),
               delimiter=",", header=",".join(columns), comments="")
    (out / "sensitivity.png").write_bytes(to_png(sensitivity_figure(history, data.control)))
    final = ", ".join(f"{n} {v:.0%}" for n, v in zip(space.names, history.variance_share[-1]))
    say(args, f"sensitivities at {dict(zip(space.names, x.tolist()))}; share of the prior (bounds) variance removed "
              f"by all data: {final}")
    wrote(args, out, ["sensitivity.csv", "sensitivity.png", "runs.sqlite"])
    return 0


def run_size_effect_command(args) -> int:
    from fracid.config import build_parameters, build_specimen
    from fracid.report.figures import to_png
    from fracid.report.size_effect_figure import size_effect_figure

    cfg = load(args, args.config, "simulate")
    if not _has_size(cfg):
        print(f"fracid: size-effect: the specimen {type(build_specimen(cfg)).__name__} declares no characteristic size "
              "and nominal section (a Gmsh mesh or the wedge-splitting test has none): use a notched beam, a dog-bone or "
              "a bar", file=sys.stderr)
        return 2
    out = out_dir(args, cfg)
    with working_in(args, out), command_executor(args) as executor:
        size = _size_effect(cfg, build_parameters(cfg), executor, sizes=args.sizes or (), quiet=args.quiet)
    if size is None:
        print("fracid: size-effect needs at least three sizes: give --sizes or experiments with "
              "[experiments.specimen] sizes", file=sys.stderr)
        return 2
    size.save(out)
    (out / "size_effect.png").write_bytes(to_png(size_effect_figure(**size.figure_arguments())))
    fit, series = size.computed, size.series
    text = "" if fit is None else f"; Bazant fit B f_t = {fit.B_ft:.4g} MPa, D0 = {fit.D0:.4g} mm"
    say(args, "nominal strength [MPa]: " + ", ".join(f"D {D:g}: {s:.4g}" for D, s in zip(series.sizes, series.sigma_N))
        + text)
    wrote(args, out, ["size_effect.csv", "size_effect.json", "size_effect.png"])
    return 0
