"""``fracid simulate CONFIG``: the forward analysis of the configured specimen: the curve (CSV), its plot (PNG)
and the fields (VTK)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from fracid.cli.common import load, out_dir, progress_choice, say, warn, working_in, wrote


def add_parser(sub, parents) -> None:
    """The ``simulate`` subcommand's arguments (``parents.common``: the options every command takes)."""
    p = sub.add_parser("simulate", parents=[parents.common], help="forward analysis of the configured specimen")
    p.add_argument("config", type=Path, help="TOML configuration file")
    p.set_defaults(run=run_simulate)


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
