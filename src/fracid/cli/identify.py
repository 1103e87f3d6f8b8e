"""``fracid identify CONFIG`` and ``fracid demo``: the inverse method of ``[identify] method`` on the configured
data: result (JSON), fitted curves (CSV), figures and the HTML report. :func:`identify_job`,
:func:`identification` and :func:`write_identification` are shared with ``fracid posterior``."""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np

from fracid.cli.common import (command_executor, demo_config_path, load, out_dir, progress_choice, provenance, say,
                               warn, working_in, wrote)


def add_parser(sub, parents) -> None:
    """The ``identify`` and ``demo`` subcommands' arguments (``parents.stored``: the common options and
    ``--store``)."""
    p = sub.add_parser("identify", parents=[parents.stored],
                       help="identify parameters from measured data ([identify] method)")
    p.add_argument("config", type=Path, help="TOML configuration file")
    p.set_defaults(run=run_identify)


def add_demo_parser(sub, parents) -> None:
    """The ``demo`` subcommand: ``identify`` on the bundled real beam test."""
    sub.add_parser("demo", parents=[parents.stored], help="identify the bundled real beam test (Gregoire et al. 2013)"
                   ).set_defaults(run=run_demo)


def run_demo(args) -> int:
    """``fracid demo``: the identification of the bundled configuration, into ./fracid-demo by default."""
    if args.out is None:  # not next to the bundled config inside the installation
        args.out = Path.cwd() / "fracid-demo"
    return run_identify(args, demo_config_path())


def identify_job(args, config_path):
    """The configuration and what the identification is built of: data, operator, space, settings."""
    from types import SimpleNamespace

    from fracid.config import build_data, build_method, build_operator, build_space

    cfg = load(args, config_path, "identify")
    data = build_data(cfg)
    return SimpleNamespace(cfg=cfg, data=data, operator=build_operator(cfg, data), space=build_space(cfg),
                           method=build_method(cfg))  # [identify] method, from fracid.inverse.methods.registry.METHODS


def identification(args, job, store, executor):
    """The identification of ``fracid identify`` (its runs through ``store``), timed."""
    from fracid.config import error_terms
    from fracid.inverse.methods.strategy import identify_data

    for line in stage_plans(job.method, job.operator, job.data.n_y, len(job.space.names), job.space):
        say(args, line)
    start = time.perf_counter()
    result = identify_data(job.operator, job.data, job.space, method=job.method, executor=executor, store=store,
                           progress=progress_choice(args), retry_failed=args.retry_failed,
                           **error_terms(job.cfg))  # [identify] discretisation_error, model_error
    result.runs["wall_seconds"] = time.perf_counter() - start
    result.provenance = provenance(args, job.cfg, job.operator, job.space, store)
    return result


def write_identification(args, job, out, result) -> None:
    """What ``fracid identify`` writes and prints: result.json, fit.csv, report.html, figures, summary, warnings."""
    from fracid.config import build_view_coordinates
    from fracid.report.views import block_views
    from fracid.report.figures import rendered_once
    from fracid.report.html import write_report
    from fracid.store.tables import write_csv_table

    data = job.data
    result.save(out / "result.json")
    block_of = np.empty(data.y.size, dtype=object)
    for name, a, b in data.blocks:
        block_of[a:b] = name
    write_csv_table(out / "fit.csv", ("control_mm", "measured", "std", "computed", "block"),
                    zip(data.control.tolist(), data.y.tolist(), data.std.tolist(), result.y_fit.tolist(), block_of))
    views = block_views(result, build_view_coordinates(job.cfg, job.operator, job.data))
    with rendered_once():  # the report's figures are figures/'s
        write_report(out / "report.html", result, control=data.control,
                     title=f"fracid identification: {Path(job.cfg.path).name}", data_notes=data.notes, views=views)
        write_figures(out / "figures", result, data.control, views=views)
    say(args, result.summary())
    stages = " + ".join(f"{c['runs']} {result.stages[stage]} ({c['failed']} failed, {c.get('computed', c['runs'])} computed)"
                        for stage, c in result.stage_runs().items())
    say(args, f"fit: {result.rms_text()}; forward runs: {stages}; "
              f"{result.runs['wall_seconds']:.0f} s")
    figures_written = sorted(p.relative_to(out).as_posix() for p in (out / "figures").glob("*.png"))
    wrote(args, out, ["result.json", "fit.csv", "report.html", *figures_written, "runs.sqlite"])
    for text in result.warnings():
        warn(text)


def run_identify(args, config_path=None) -> int:
    job = identify_job(args, config_path or args.config)
    out = out_dir(args, job.cfg)
    with working_in(args, out, store=True) as store, command_executor(args) as executor:
        result = identification(args, job, store, executor)
    write_identification(args, job, out, result)
    if not np.all(np.isfinite(result.x)) or not np.all(np.isfinite(result.y_fit)):
        print(f"fracid: the identification gave no finite result ({result.status}); see {out / 'report.html'}",
              file=sys.stderr)
        return 3
    return 0


def stage_plans(method, operator, n_y: int, p: int, space=None) -> list[str]:
    """What the method's stages will cost (its ``plan``, :class:`~fracid.inverse.core.plans.StagePlan`; ``space``:
    the identification's bounds), said before the work starts; its stages' names for a method that has no plan."""
    from fracid.inverse.core.plans import method_plan

    if getattr(method, "plan", None) is None:  # an optional capability of an inverse method
        return [f"{method.name}: stages {', '.join(dict(getattr(method, 'stages', {}) or {}).values()) or method.name}"]
    return [stage.line() for stage in method_plan(method, operator, n_y, p, space)]


def write_figures(directory: Path, result, control, fields=None, views=None) -> None:
    """The report's figures as PNG files too; a block view's under the stems of its figures (a displacement
    field's ``field_<name>_summary.png`` and ``field_<name>_frame<k>.png``; ``fields``: the coordinates of the
    blocks that have a view, or ``views``: the views built from them)."""
    from fracid.report import figures
    from fracid.report.views import block_views_and_skipped
    from fracid.report.stage_figures import stage_figures

    directory.mkdir(parents=True, exist_ok=True)
    views, skip = block_views_and_skipped(result, fields, views)
    drawn = {"fit": figures.fit_figure(result, control, skip=skip), **stage_figures(result),
             "correlation": figures.correlation_figure(result)}
    for name, fig in drawn.items():
        if fig is not None:
            (directory / f"{name}.png").write_bytes(figures.to_png(fig, stem=name))
    for view in views:
        for stem in view.figures:
            (directory / f"{stem}.png").write_bytes(view.png(stem))
