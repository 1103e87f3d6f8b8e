"""The ``fracid`` command: a thin layer over the Python API.

    fracid simulate CONFIG    forward analysis: curve (CSV), plot (PNG), fields (VTK)
    fracid identify CONFIG    KNN + Kalman filter: result (JSON), fitted curves (CSV), figures, HTML report
    fracid demo               identification of the bundled real test (Gregoire et al. 2013 beam)

Options common to all: --out DIR, --workers N, --scheduler ADDRESS, --quiet. Configuration errors
end with exit status 2 and a one-paragraph message naming the file, the key and the value.
"""

from __future__ import annotations

import argparse
import sys
import time
from importlib import resources
from pathlib import Path

import numpy as np


def _parser() -> argparse.ArgumentParser:
    common = argparse.ArgumentParser(add_help=False)
    common.add_argument("--out", type=Path, help="output directory (default: the config's output.directory)")
    common.add_argument("--workers", type=int, help="parallel forward runs (default: one per core; 1 = serial)")
    common.add_argument("--scheduler", help="address of a Dask scheduler (tcp://host:port) instead of local workers")
    common.add_argument("--quiet", action="store_true", help="no progress bars or summaries")
    parser = argparse.ArgumentParser(prog="fracid", description="Parameter identification for localized-failure models.")
    sub = parser.add_subparsers(dest="command", required=True)
    for name, text in (("simulate", "forward analysis of the configured specimen"),
                       ("identify", "identify parameters from measured data (KNN + Kalman filter)")):
        p = sub.add_parser(name, parents=[common], help=text)
        p.add_argument("config", type=Path, help="TOML configuration file")
    sub.add_parser("demo", parents=[common], help="identify the bundled real beam test (Gregoire et al. 2013)")
    return parser


def demo_config_path() -> Path:
    """The bundled demo configuration (next to the Gregoire data)."""
    return Path(str(resources.files("fracid.data") / "gregoire2013_beam4" / "demo.toml"))


def _say(args, text):
    if not args.quiet:
        print(text)


def _out_dir(args, cfg) -> Path:
    out = args.out if args.out is not None else Path(cfg.output.directory)
    out.mkdir(parents=True, exist_ok=True)
    return out


def run_simulate(args) -> int:
    from fracid.config import build_parameters, build_specimen, load_config, simulate_settings
    from fracid.forward import simulate
    from fracid.progress import progress_bar
    from fracid.report.figures import curve_figure, to_png

    cfg = load_config(args.config, purpose="simulate")
    specimen, params = build_specimen(cfg), build_parameters(cfg)
    settings = simulate_settings(cfg)
    if settings.get("target") is None:
        settings["target"] = specimen.default_target(params)
    out = _out_dir(args, cfg)
    with progress_bar(settings["target"], "forward analysis", False if args.quiet else None, unit="mm") as bar:
        result = simulate(specimen, params, callback=lambda step, tau, force: bar.update(tau - bar.n), **settings)
    columns = {result.control_name: result.control, "force_N": result.force, **result.observables}
    names = list(dict.fromkeys(columns))
    np.savetxt(out / "curve.csv", np.column_stack([columns[n] for n in names]), delimiter=",", header=",".join(names),
               comments="")
    (out / "curve.png").write_bytes(to_png(curve_figure(result)))
    written = ["curve.csv", "curve.png"]
    try:
        from fracid.report.vtk import write_result_vtk

        written += [str(p.relative_to(out)) for p in write_result_vtk(out / "vtk", specimen, result)]
    except ImportError as err:
        _say(args, f"VTK output skipped: {err}")
    _say(args, f"peak force {result.peak_force:.6g} N; {result.status}; {result.stats.steps} steps, "
               f"{result.stats.time_total:.1f} s\nwrote in {out}: " + ", ".join(written))
    return 0


def run_identify(args, config_path=None) -> int:
    from fracid.config import build_data, build_operator, build_space, identify_settings, load_config
    from fracid.inverse.strategy import identify_data
    from fracid.parallel import make_executor
    from fracid.report.html import write_report
    from fracid.store import RunStore

    cfg = load_config(config_path or args.config, purpose="identify")
    data = build_data(cfg)
    operator, space, settings = build_operator(cfg, data), build_space(cfg), identify_settings(cfg)
    out = _out_dir(args, cfg)
    start = time.perf_counter()
    with RunStore(out / "runs.sqlite") as store, make_executor(args.workers, args.scheduler) as executor:
        result = identify_data(operator, data, space, executor=executor, store=store,
                               progress=None if not args.quiet else False, **settings)
    result.runs["wall_seconds"] = time.perf_counter() - start
    result.save(out / "result.json")
    header = "control_mm,measured,std,computed,block"
    block_of = np.empty(data.y.size, dtype=object)
    for name, a, b in data.blocks:
        block_of[a:b] = name
    rows = [f"{c:.9g},{y:.9g},{s:.9g},{f:.9g},{blk}" for c, y, s, f, blk in
            zip(data.control, data.y, data.std, result.y_fit, block_of)]
    (out / "fit.csv").write_text("\n".join([header, *rows]) + "\n")
    write_report(out / "report.html", result, control=data.control, title=f"fracid identification: {Path(cfg.path).name}",
                 data_notes=data.notes)
    _write_figures(out / "figures", result, data.control)
    _say(args, result.summary())
    rms = float(np.sqrt(np.mean((result.y_fit - data.y) ** 2)))
    _say(args, f"fit: RMS error {rms:.4g} ({100 * rms / np.max(np.abs(data.y)):.2f} % of the measured peak); "
               f"forward runs: {result.runs['knn']} KNN ({result.runs['knn_failed']} failed) + {result.runs['kalman']} "
               f"Kalman; {result.runs['wall_seconds']:.0f} s\nwrote in {out}: result.json, fit.csv, report.html, figures/*.png")
    return 0


def _write_figures(directory: Path, result, control) -> None:
    """The report's figures as PNG files too."""
    from fracid.report import figures

    directory.mkdir(parents=True, exist_ok=True)
    drawn = {"fit": figures.fit_figure(result, control), "kalman": figures.kalman_figure(result),
             "knn_objective": figures.knn_objective_figure(result), "knn_map": figures.knn_map_figure(result),
             "correlation": figures.correlation_figure(result)}
    for name, fig in drawn.items():
        if fig is not None:
            (directory / f"{name}.png").write_bytes(figures.to_png(fig))


def main(argv=None) -> int:
    args = _parser().parse_args(argv)
    from fracid.config import ConfigError

    if args.workers is not None and args.workers < 1:
        print(f"fracid: --workers = {args.workers}: it must be at least 1", file=sys.stderr)
        return 2
    try:
        if args.command == "simulate":
            return run_simulate(args)
        if args.command == "identify":
            return run_identify(args)
        if args.out is None:  # not next to the bundled config inside the installation
            args.out = Path.cwd() / "fracid-demo"
        return run_identify(args, demo_config_path())
    except ConfigError as err:
        print(f"fracid: {err}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
