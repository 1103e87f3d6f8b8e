"""The ``fracid`` command: a thin layer over the Python API.

    fracid simulate CONFIG    forward analysis: curve (CSV), plot (PNG), fields (VTK)
    fracid identify CONFIG    the inverse method of [identify] method: result (JSON), fitted curves (CSV), figures,
                              HTML report
    fracid posterior CONFIG   identify, then weighted samples of the parameters given the data (adaptive
                              importance sampling on the exact model): CSV, JSON, figures, HTML page
    fracid compare CONFIG     every model that runs on the specimen identified on the same data and ranked by
                              log evidence (:mod:`fracid.cli.compare`): compare.json, figures, HTML report
    fracid study CONFIG       the whole strategy through the method's stages: search, sensitivity, uniqueness,
                              refinement, multi-start, stability, prediction of held-out data, size effect;
                              a verdict per parameter
    fracid uniqueness CONFIG  search, objective maps and valley, refinement, multi-start (no replicates)
    fracid stability CONFIG   search, refinement, identification on noisy replicates (no multi-start)
    fracid sensitivity CONFIG normalised sensitivities and information along the load history at the
                              configured parameter values
    fracid size-effect CONFIG nominal strength versus size at the configured parameter values, Bazant fit
    fracid demo               identification of the bundled real test (Gregoire et al. 2013 beam)
    fracid init               a commented configuration to start from (:mod:`fracid.cli.init`)
    fracid check CONFIG       validate a configuration and print its plan and cost (:mod:`fracid.cli.check`)
    fracid datasets           the bundled data sets by name; fracid init --dataset NAME writes one's configuration
                              (:mod:`fracid.cli.datasets`)
    fracid --version

Options common to all: --out DIR, --workers N, --scheduler ADDRESS, --quiet, --retry-failed, --debug.
Every expected failure ends with a one-paragraph message and a documented exit status (see
:mod:`fracid.runtime.exits`): 2 bad input, 3 the computation failed, 4 files and storage, 5 out of memory,
130 interrupted; ``--debug`` shows the traceback.
"""

from __future__ import annotations

import argparse
import sys
import time
import traceback
from pathlib import Path

import numpy as np

from fracid.cli.common import (command_executor, demo_config_path, load, out_dir, progress_choice, provenance,
                               say, warn, working_in, wrote)
from fracid.runtime.progress import progress_lines

__all__ = ["demo_config_path", "main", "provenance", "version"]


#: the commands of the loop below that keep a run store (and take --store; demo and compare too)
STORE_COMMANDS = ("identify", "posterior", "study", "uniqueness", "stability")


def _parser() -> argparse.ArgumentParser:
    common = argparse.ArgumentParser(add_help=False)
    common.add_argument("--out", type=Path, help="output directory (default: the config's output.directory)")
    common.add_argument("--workers", type=int, help="parallel forward runs (default: one per core; 1 = serial)")
    common.add_argument("--scheduler", help="address of a Dask scheduler (tcp://host:port) instead of local workers")
    common.add_argument("--quiet", action="store_true", help="no progress bars or summaries")
    common.add_argument("--retry-failed", action="store_true", help="run again the forward runs stored as failed")
    common.add_argument("--debug", action="store_true", help="show the traceback of a failure")
    stored = argparse.ArgumentParser(add_help=False, parents=[common])  # the commands that keep a run store
    stored.add_argument("--store", type=Path, metavar="FILE",
                        help="the run store to read and write instead of OUT/runs.sqlite: commands that share one "
                             "reuse each other's forward runs (same model, specimen, steps and measured controls)")
    parser = argparse.ArgumentParser(prog="fracid", description="Parameter identification for localized-failure models.")
    parser.add_argument("--version", action="version", version=f"fracid {version()}")
    sub = parser.add_subparsers(dest="command", required=True)
    for name, text in (("simulate", "forward analysis of the configured specimen"),
                       ("identify", "identify parameters from measured data ([identify] method)"),
                       ("posterior", "identify, then sample the parameters given the data on the exact model"),
                       ("study", "identification with uniqueness, stability and prediction checks, and a verdict"),
                       ("uniqueness", "the study's uniqueness stages only: objective maps, valley, multi-start"),
                       ("stability", "the study's stability stage only: identification on noisy replicates"),
                       ("sensitivity", "sensitivities and information along the load history"),
                       ("size-effect", "nominal strength versus size and Bazant's size effect law")):
        p = sub.add_parser(name, parents=[stored if name in STORE_COMMANDS else common], help=text)
        p.add_argument("config", type=Path, help="TOML configuration file")
        if name == "size-effect":
            p.add_argument("--sizes", type=float, nargs="+", help="sizes D [mm] (default: those of the experiments)")
    sub.add_parser("demo", parents=[stored], help="identify the bundled real beam test (Gregoire et al. 2013)")
    from fracid.cli import check as cli_check
    from fracid.cli import init as cli_init

    cli_init.add_parser(sub)
    cli_check.add_parser(sub, common)
    from fracid.cli import compare as cli_compare

    cli_compare.add_parser(sub, stored)
    from fracid.cli import datasets as cli_datasets

    cli_datasets.add_parser(sub)  # `fracid datasets` and `fracid init --dataset NAME`
    return parser


def version() -> str:
    """The installed fracid's version (:func:`fracid.store.provenance.fracid_version`)."""
    from fracid.store.provenance import fracid_version

    return fracid_version()


def run_simulate(args) -> int:
    from fracid.config import build_model, build_parameters, build_specimen, simulate_settings
    from fracid.runtime.progress import progress_bar
    from fracid.report.figures import curve_figure, to_png

    cfg = load(args, args.config, "simulate")
    model, specimen, params = build_model(cfg), build_specimen(cfg), build_parameters(cfg)
    settings = simulate_settings(cfg)
    settings.pop("regularization", None)  # the model carries its own
    if settings.get("target") is None:
        settings["target"] = model.default_target(specimen, params)
    out = out_dir(args, cfg)
    with (working_in(args, out),
          progress_bar(settings["target"], "forward analysis", progress_choice(args), unit="mm") as bar):
        result = model.simulate(specimen, params, callback=lambda step, tau, force: bar.update(tau - bar.n),
                                **settings)
    columns = {result.control_name: result.control, "force_N": result.force, **result.observables}
    names = list(dict.fromkeys(columns))
    np.savetxt(out / "curve.csv", np.column_stack([columns[n] for n in names]), delimiter=",", header=",".join(names),
               comments="")
    (out / "curve.png").write_bytes(to_png(curve_figure(result)))
    written = ["curve.csv", "curve.png"]
    try:
        from fracid.report.vtk import write_result_vtk

        written += [p.relative_to(out).as_posix() for p in write_result_vtk(out / "vtk", specimen, result)]
    except ImportError as err:
        if cfg.output.vtk_steps:  # asked for; the last step alone is a bonus, skipped silently
            warn(f"[output] vtk_steps: VTK output skipped: {err}")
    say(args, f"peak force {result.peak_force:.6g} N; {result.status}; {result.stats.steps} steps, "
              f"{result.stats.time_total:.1f} s")
    wrote(args, out, written)
    return 0


def _identify_job(args, config_path):
    """The configuration and what the identification is built of: data, operator, space, settings."""
    from types import SimpleNamespace

    from fracid.config import build_data, build_method, build_operator, build_space

    cfg = load(args, config_path, "identify")
    data = build_data(cfg)
    return SimpleNamespace(cfg=cfg, data=data, operator=build_operator(cfg, data), space=build_space(cfg),
                           method=build_method(cfg))  # [identify] method, from fracid.inverse.methods.registry.METHODS


def _identification(args, job, store, executor):
    """The identification of ``fracid identify`` (its runs through ``store``), timed."""
    from fracid.config import error_terms
    from fracid.inverse.methods.strategy import identify_data

    for line in _stage_plans(job.method, job.operator, job.data.n_y, len(job.space.names)):
        say(args, line)
    start = time.perf_counter()
    result = identify_data(job.operator, job.data, job.space, method=job.method, executor=executor, store=store,
                           progress=progress_choice(args), retry_failed=args.retry_failed,
                           **error_terms(job.cfg))  # [identify] discretisation_error, model_error
    result.runs["wall_seconds"] = time.perf_counter() - start
    result.provenance = provenance(args, job.cfg, job.operator, job.space, store)
    return result


def _write_identification(args, job, out, result) -> None:
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
        _write_figures(out / "figures", result, data.control, views=views)
    say(args, result.summary())
    stages = " + ".join(f"{c['runs']} {result.stages[stage]} ({c['failed']} failed, {c.get('computed', c['runs'])} computed)"
                        for stage, c in result.stage_runs().items())
    say(args, f"fit: RMS error {result.rms_percent:.3g} % of the measured peak; forward runs: {stages}; "
              f"{result.runs['wall_seconds']:.0f} s")
    figures_written = sorted(p.relative_to(out).as_posix() for p in (out / "figures").glob("*.png"))
    wrote(args, out, ["result.json", "fit.csv", "report.html", *figures_written, "runs.sqlite"])
    for text in result.warnings():
        warn(text)


def run_identify(args, config_path=None) -> int:
    job = _identify_job(args, config_path or args.config)
    out = out_dir(args, job.cfg)
    with working_in(args, out, store=True) as store, command_executor(args) as executor:
        result = _identification(args, job, store, executor)
    _write_identification(args, job, out, result)
    if not np.all(np.isfinite(result.x)) or not np.all(np.isfinite(result.y_fit)):
        print(f"fracid: the identification gave no finite result ({result.status}); see {out / 'report.html'}",
              file=sys.stderr)
        return 3
    return 0


def run_posterior_command(args) -> int:
    """``fracid identify``, then the posterior of the parameters sampled from its Gaussian on the exact model."""
    from fracid.config import posterior_settings
    from fracid.runtime.exits import FAILED
    from fracid.inverse.core.runs import StoredOperator
    from fracid.inverse.sampling.posterior import sample_posterior
    from fracid.report.posterior import write_posterior

    job = _identify_job(args, args.config)
    settings = posterior_settings(job.cfg)
    out = out_dir(args, job.cfg)
    with working_in(args, out, store=True) as store, command_executor(args) as executor:
        result = _identification(args, job, store, executor)
        _write_identification(args, job, out, result)
        if not (np.all(np.isfinite(result.x)) and np.all(np.isfinite(result.C))):
            print(f"fracid: posterior: the identification gave no finite estimate and covariance ({result.status}), "
                  f"and the sampler starts from them; see {out / 'report.html'}", file=sys.stderr)
            return FAILED
        evaluate = StoredOperator(job.operator, store, study="posterior", retry_failed=args.retry_failed)
        post = sample_posterior(evaluate, job.data, job.space, result, settings, executor=executor,
                                progress=progress_choice(args), log=lambda text: say(args, text))
    written = write_posterior(out, post, data=job.data, fit=result.y_fit, provenance=result.provenance,
                              title=f"fracid posterior: {Path(job.cfg.path).name}")
    say(args, post.summary())
    say(args, f"posterior forward runs: {len(post.x)} ({evaluate.computed} computed, {evaluate.reused} reused from "
              f"the run store, {post.failed} failed)")
    wrote(args, out, written)
    if post.sampling_failed:
        print(f"fracid: posterior {post.status}. The draws are in {out / 'posterior.csv'}, without credible "
              "intervals.", file=sys.stderr)
        return FAILED
    if not post.converged:
        warn(f"posterior: {post.status}")
    return 0


def _stage_plans(method, operator, n_y: int, p: int) -> list[str]:
    """What the method's stages will cost (its ``plan``, :class:`~fracid.inverse.core.plans.StagePlan`), said before
    the work starts; its stages' names for a method that has no plan."""
    plan = getattr(method, "plan", None)  # an optional capability of an inverse method
    if plan is None:
        return [f"{method.name}: stages {', '.join(dict(getattr(method, 'stages', {}) or {}).values()) or method.name}"]
    return [stage.line() for stage in plan(operator, n_y, p)]


def _write_figures(directory: Path, result, control, fields=None, views=None) -> None:
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


def main(argv=None) -> int:
    """Run the command; returns its exit status (see :mod:`fracid.runtime.exits`), never raises."""
    from fracid.runtime import exits

    args = None
    with exits.stop_signals():
        try:
            args = _parser().parse_args(argv)
            args.argv = ["fracid", *(sys.argv[1:] if argv is None else argv)]
            if getattr(args, "workers", None) is not None and args.workers < 1:
                print(f"fracid: --workers = {args.workers}: it must be at least 1", file=sys.stderr)
                return exits.INPUT
            args.store_path = args.out_dir = None
            with progress_lines(not getattr(args, "quiet", False)):
                return _dispatch(args)
        except SystemExit:
            raise
        except BaseException as err:  # noqa: BLE001 -- every failure becomes a message and an exit status
            if not isinstance(err, KeyboardInterrupt) and exits.stopped_by() is not None:
                err = exits.stopped_by()  # the signal, seen through the code it struck
            status, text = exits.describe(err, store_path=getattr(args, "store_path", None),
                                          out=getattr(args, "out_dir", None))
            if getattr(args, "debug", False):
                traceback.print_exc()
            print(f"fracid: {text}", file=sys.stderr)
            return status


def _dispatch(args) -> int:
    if args.command == "datasets" or getattr(args, "dataset", None) is not None:
        from fracid.cli import datasets as cli_datasets

        return cli_datasets.run(args)
    if args.command in ("init", "check"):
        from fracid.cli import check as cli_check
        from fracid.cli import init as cli_init

        return cli_init.run_init(args) if args.command == "init" else cli_check.run_check(args)
    if args.command == "simulate":
        return run_simulate(args)
    if args.command == "identify":
        return run_identify(args)
    if args.command == "posterior":
        return run_posterior_command(args)
    if args.command == "compare":
        from fracid.cli import compare as cli_compare

        return cli_compare.run_compare(args)
    if args.command in ("study", "uniqueness", "stability", "sensitivity", "size-effect"):
        from fracid.cli import studies as cli_studies

        return cli_studies.run(args)
    if args.out is None:  # not next to the bundled config inside the installation
        args.out = Path.cwd() / "fracid-demo"
    return run_identify(args, demo_config_path())


if __name__ == "__main__":
    sys.exit(main())
