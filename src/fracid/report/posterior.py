"""The posterior of ``fracid posterior``: the sampler run from an identification, its figures (corner
plot, posterior predictive band), its JSON, and a self-contained HTML page setting the identification's
Gaussian beside the sampled posterior.

The sampler itself is :func:`fracid.inverse.sampling.posterior.posterior`; here it is only started from an
identification (:func:`fracid.inverse.sampling.sample.sample_posterior`) and written out (:func:`write_posterior`).

Units: control [mm], force [N], parameters in the units of the result (``PosteriorResult.units``).
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.patches import Patch

from fracid.inverse.studies.verdict import Z_90
from fracid.store.tables import without_nan
from fracid.report.figures import (
    COMPUTED,
    MEASURED,
    covariance_ellipse,
    new_figure,
    block_panels,
    block_run_curve,
    draw_computed,
    finish_block_panel,
    parameter_units,
    to_png,
)

__all__ = ["GAUSSIAN_90", "comparison_table", "corner_figure", "posterior_dict", "predictive_figure", "statistics_table",
           "write_posterior", "write_posterior_page"]

#: half-width of the Gaussian 90 % interval in standard deviations (the 95 % quantile of the normal)
GAUSSIAN_90 = Z_90

_POSTERIOR = "#1f77b4"
_GAUSSIAN = COMPUTED
_MEAN = "#ff7f0e"

#: what each interval is, as the JSON and the page label them
GAUSSIAN_INTERVAL = "identification: Gaussian 90 % interval, estimate +- 1.645 std"
POSTERIOR_INTERVAL = ("posterior: equal-tailed 90 % credible interval (weighted 5 % and 95 % quantiles of the "
                      "importance-weighted draws)")


# ------------------------------------------------------------------------------------ helpers


def _label(result, name: str) -> str:
    unit = (getattr(result, "units", None) or {}).get(name) or parameter_units().get(name)
    return f"{name} [{unit}]" if unit else str(name)


def _log_flags(result, log_axes, p: int) -> tuple:
    """Per parameter: a log axis (its bounds log-scaled), from ``log_axes`` or the result's ``log``
    if it has one; linear otherwise."""
    flags = log_axes if log_axes is not None else getattr(result, "log", None)
    if flags is None or len(flags) != p:
        return (False,) * p
    return tuple(bool(v) for v in flags)


def _usable(result):
    """The draws with a positive weight (finite), their normalised weights."""
    x, w = np.asarray(result.x, float), np.asarray(result.weights, float)
    ok = (w > 0) & np.all(np.isfinite(x), axis=1)
    return x[ok], w[ok] / w[ok].sum()


def _limits(values, weights, centre, std, lower, upper, log: bool) -> tuple[float, float]:
    """Axis range of one parameter: the weighted draws' 0.1 % to 99.9 % quantiles and the Gaussian's
    +- 3 std, within the bounds, with a margin."""
    from fracid.inverse.sampling.mixture import weighted_quantile

    lo, hi = weighted_quantile(values, weights, [0.001, 0.999])
    if math.isfinite(centre) and math.isfinite(std):
        lo, hi = min(lo, centre - 3 * std), max(hi, centre + 3 * std)
    lo, hi = max(lo, lower), min(hi, upper)
    if log:
        lo = max(lo, lower if lower > 0 else hi * 1e-6)
        a, b = math.log(lo), math.log(hi)
        pad = 0.05 * (b - a) if b > a else 0.1
        return math.exp(a - pad), math.exp(b + pad)
    if not hi > lo:
        lo, hi = lower, upper
    pad = 0.05 * (hi - lo)
    return lo - pad, hi + pad


def _edges(lo: float, hi: float, n: int, log: bool) -> np.ndarray:
    return np.geomspace(lo, hi, n + 1) if log else np.linspace(lo, hi, n + 1)


def _scale(ax, axis: str, log: bool) -> None:
    if log:
        (ax.set_xscale if axis == "x" else ax.set_yscale)("log")
    else:
        ax.ticklabel_format(axis=axis, style="sci", scilimits=(-3, 4), useMathText=True)


# ------------------------------------------------------------------------------------ figures


def corner_figure(result, log_axes=None) -> Figure:
    """Pairs of the weighted draws, with the identification's Gaussian over them.

    Diagonal: the weighted histogram of each parameter (density), the normal curve of the Gaussian
    estimate (``estimate``, ``estimate_cov``) and the posterior's 90 % credible interval (dotted).
    Below it: the weighted 2D histogram of each pair with the Gaussian's 1-std and 2-std ellipses,
    the posterior mean (+) and the Gaussian estimate (x).

    Parameters
    ----------
    result : PosteriorResult
    log_axes : sequence of bool, optional
        Per parameter: a log axis (e.g. ``ParameterSpace.log``: the bounds log-scaled); linear if not given.
    """
    names = list(result.names)
    p = len(names)
    x, w = _usable(result)
    mu = np.asarray(result.estimate, float)
    cov = np.asarray(result.estimate_cov, float)
    std = np.sqrt(np.maximum(np.diag(cov), 0.0))
    lower, upper = (np.asarray(b, float) for b in result.bounds)
    log = _log_flags(result, log_axes, p)
    limits = [_limits(x[:, j], w, mu[j], std[j], lower[j], upper[j], log[j]) for j in range(p)]
    ess = float(1.0 / np.sum(w**2))
    bins = int(np.clip(2.0 * math.sqrt(ess), 10, 40))
    edges = [_edges(*limits[j], bins, log[j]) for j in range(p)]
    mean = w @ x
    intervals = result.credible_intervals(0.9)

    side = min(2.6, 10.0 / max(p, 1)) * p + 0.8
    fig = new_figure(6.4, 4.0) if p == 1 else new_figure(side, side)
    axes = fig.subplots(p, p, squeeze=False)
    for i in range(p):
        for j in range(p):
            ax = axes[i, j]
            if j > i:
                ax.set_axis_off()
                continue
            if i == j:
                _marginal(ax, x[:, j], w, edges[j], mu[j], std[j], intervals[j], log[j])
            else:
                _pair(ax, x[:, j], x[:, i], w, edges[j], edges[i], mu[[j, i]], cov[np.ix_([j, i], [j, i])],
                      mean[[j, i]], (log[j], log[i]))
                ax.set_ylim(*limits[i])
                _scale(ax, "y", log[i])
            ax.set_xlim(*limits[j])
            _scale(ax, "x", log[j])
            if i == p - 1:
                ax.set_xlabel(_label(result, names[j]))
            else:
                ax.tick_params(labelbottom=False)
            if j == 0 and i > 0:
                ax.set_ylabel(_label(result, names[i]))
            elif j > 0:
                ax.tick_params(labelleft=False)
            ax.grid(True, alpha=0.25)
    handles = [Patch(color=_POSTERIOR, alpha=0.5, label="posterior (weighted draws)"),
               Line2D([], [], color=_POSTERIOR, ls=":", label="posterior 90 % credible interval"),
               Line2D([], [], color=_GAUSSIAN, label="identification's Gaussian (1 and 2 std)"),
               Line2D([], [], color=_MEAN, marker="+", ls="", ms=9, mew=1.8, label="posterior mean"),
               Line2D([], [], color=_GAUSSIAN, marker="x", ls="", ms=7, mew=1.8, label="identification's estimate")]
    holder = axes[0, p - 1] if p > 1 else axes[0, 0]
    holder.legend(handles=handles if p > 1 else handles[:3], loc="upper right", fontsize="small",
                  framealpha=0.9 if p > 1 else 0.6)
    fig.suptitle(f"posterior: {len(result.x)} draws, ESS {result.ess:.0f}; the identification's Gaussian in red",
                 fontsize="medium")
    return fig


def _marginal(ax, values, weights, edges, centre, std, interval, log: bool) -> None:
    ax.hist(values, bins=edges, weights=weights, density=True, histtype="stepfilled", color=_POSTERIOR, alpha=0.5)
    if math.isfinite(centre) and std > 0:
        t = np.geomspace(edges[0], edges[-1], 300) if log else np.linspace(edges[0], edges[-1], 300)
        ax.plot(t, np.exp(-0.5 * ((t - centre) / std) ** 2) / (std * math.sqrt(2 * math.pi)), color=_GAUSSIAN, lw=1.4)
    for value in interval:
        ax.axvline(value, color=_POSTERIOR, ls=":", lw=1.2)
    ax.set_yticks([])


def _pair(ax, xv, yv, weights, x_edges, y_edges, centre, cov, mean, log) -> None:
    counts, _, _ = np.histogram2d(xv, yv, bins=[x_edges, y_edges], weights=weights)
    ax.pcolormesh(x_edges, y_edges, np.ma.masked_equal(counts.T, 0.0), cmap="Blues", shading="flat")
    if np.all(np.isfinite(centre)) and np.all(np.isfinite(cov)):
        for n_std, style in ((1.0, "-"), (2.0, "--")):
            ring = covariance_ellipse(centre, cov, n_std)
            if log[0] or log[1]:  # points below zero have no place on a log axis
                keep = ((ring[:, 0] > 0) | (not log[0])) & ((ring[:, 1] > 0) | (not log[1]))
                ring = np.where(keep[:, None], ring, np.nan)
            ax.plot(ring[:, 0], ring[:, 1], style, color=_GAUSSIAN, lw=1.2)
        ax.plot(*centre, "x", color=_GAUSSIAN, ms=8, mew=1.8, zorder=4)
    ax.plot(*mean, "+", color=_MEAN, ms=11, mew=1.8, zorder=4)


def predictive_figure(result, control=None, blocks=None, fit=None) -> Figure:
    """Per data block: the measured points with +- 1 std error bars, the posterior 90 % band of the
    computed curve (:meth:`PosteriorResult.predictive_band`, without measurement noise), its median,
    and the identification's fit when given.

    Parameters
    ----------
    result : PosteriorResult
    control : array_like, optional
        Control value [mm] of every measured value; the point index without it.
    blocks : sequence of (name, start, stop), optional
        Data blocks of y (``ExperimentalData.blocks``); one block without them.
    fit : MethodResult or array_like, optional
        The identification: its curve at the estimate is drawn (the run's own, ``curves``,
        :func:`~fracid.report.figures.draw_computed`); or only its values at the data's points (``y_fit``), drawn
        as the line through them.
    """
    y_exp = np.asarray(result.y_exp, float)
    std = np.asarray(result.std_exp, float)
    lower, median, upper = result.predictive_band(0.9)
    identification = fit if hasattr(fit, "y_fit") else None
    fit = None if fit is None else np.asarray(fit.y_fit if identification is not None else fit, float)
    blocks = [(str(b[0]), int(b[1]), int(b[2])) for b in (blocks or [])] or [("data", 0, y_exp.size)]
    fig, panels = block_panels(blocks, None if control is None else np.asarray(control, float), y_exp.size)
    for k, (ax, name, part, xs) in enumerate(panels):
        order = np.argsort(xs, kind="stable")
        ax.fill_between(xs[order], lower[part][order], upper[part][order], color=_POSTERIOR, alpha=0.25, lw=0,
                        label="posterior 90 % band of the computed curve")
        ax.plot(xs[order], median[part][order], "-", color=_POSTERIOR, lw=1.6, label="posterior median")
        if fit is not None and np.any(np.isfinite(fit[part])):
            curve = None if identification is None else block_run_curve(identification, k, control is not None)
            draw_computed(ax, xs, fit[part], curve, "identification's fit", colour=_GAUSSIAN, style="--", lw=1.4)
        ax.errorbar(xs, y_exp[part], yerr=std[part], fmt="o", color=MEASURED, ms=3.5, capsize=2, lw=1,
                    label="measured +- std", zorder=3)
        finish_block_panel(ax, name, control is not None)
    return fig


# ------------------------------------------------------------------------------------ output


def posterior_dict(result) -> dict:
    """:meth:`PosteriorResult.to_dict` with the identification's estimate, std and Gaussian 90 % interval,
    and per parameter both estimates and both intervals, labelled."""
    out = result.to_dict()
    names = list(result.names)
    estimate = np.asarray(result.estimate, float)
    kf_std = np.sqrt(np.maximum(np.diag(np.asarray(result.estimate_cov, float)), 0.0))
    kf_interval = np.column_stack([estimate - GAUSSIAN_90 * kf_std, estimate + GAUSSIAN_90 * kf_std])
    intervals = np.asarray(out["interval_90"], float)
    out["interval_90_label"] = POSTERIOR_INTERVAL
    out["gaussian"] = {"estimate": estimate.tolist(), "std": kf_std.tolist(), "interval_90": kf_interval.tolist(),
                            "interval_90_label": GAUSSIAN_INTERVAL}
    out["parameters"] = {
        name: {"unit": result.units.get(name, ""),
               "gaussian": {"estimate": float(estimate[j]), "std": float(kf_std[j]),
                                 "interval_90": kf_interval[j].tolist()},
               "posterior": {"mean": float(out["mean"][j]), "std": float(out["std"][j]),
                             "interval_90": intervals[j].tolist()}}
        for j, name in enumerate(names)}
    return out


def write_posterior(out, result, *, data=None, fit=None, log_axes=None, title: str = "fracid posterior",
                    provenance=None) -> list[str]:
    """Write the posterior in the directory ``out``.

    Files: ``posterior.csv`` (the draws, their weights and log-likelihoods), ``posterior.json``
    (:func:`posterior_dict`), ``posterior.nc`` (ArviZ InferenceData of resampled draws, when ArviZ
    is installed), ``figures/corner.png``, ``figures/posterior_predictive.png`` and ``posterior.html``.

    Parameters
    ----------
    out : Path
    result : PosteriorResult
    data : ExperimentalData, optional
        Its ``control`` and ``blocks`` lay out the predictive figure.
    fit : MethodResult or array_like, optional
        The identification (its run's curve at the estimate), or its values at the data's points, drawn in the
        predictive figure (:func:`predictive_figure`).
    log_axes : sequence of bool, optional
        Log axes of the corner plot per parameter (``ParameterSpace.log``).
    title : str
    provenance : dict, optional
        How the run was made (:func:`fracid.store.provenance.collect`): in the page, collapsed, and in
        ``posterior.json`` under ``provenance``.

    Returns
    -------
    list of str
        What was written (relative to ``out``), and a note in brackets for what was skipped.
    """
    out = Path(out)
    written = [result.save_csv(out / "posterior.csv").name]
    saved = {**posterior_dict(result), **({"provenance": provenance} if provenance else {})}
    (out / "posterior.json").write_text(json.dumps(without_nan(saved), indent=1, default=float) + "\n")
    written.append("posterior.json")
    skipped = []
    try:
        result.to_inference_data().to_netcdf(str(out / "posterior.nc"))
        written.append("posterior.nc")
    except (ImportError, ValueError) as err:  # no ArviZ, or no netCDF backend for it
        skipped.append(f"(posterior.nc skipped: {err})")
    control = None if data is None else data.control
    blocks = None if data is None else data.blocks
    figures_dir = out / "figures"
    figures_dir.mkdir(parents=True, exist_ok=True)
    pngs = {"corner": to_png(corner_figure(result, log_axes)),
            "posterior_predictive": to_png(predictive_figure(result, control, blocks, fit))}
    for name, png in pngs.items():
        (figures_dir / f"{name}.png").write_bytes(png)
        written.append(f"figures/{name}.png")
    write_posterior_page(out / "posterior.html", result, pngs, title=title, provenance=provenance)
    return [*written, "posterior.html", *skipped]


def comparison_table(result) -> str:
    """HTML table: per parameter, the identification's estimate, std and Gaussian 90 % interval beside the
    posterior's mean, std and 90 % credible interval."""
    from fracid.report.markup import html_table, num

    rows = []
    for name, entry in posterior_dict(result)["parameters"].items():
        kf, post = entry["gaussian"], entry["posterior"]
        rows.append([name, entry["unit"], num(kf["estimate"], 5), num(kf["std"], 3),
                     f"[{num(kf['interval_90'][0], 5)}, {num(kf['interval_90'][1], 5)}]",
                     num(post["mean"], 5), num(post["std"], 3),
                     f"[{num(post['interval_90'][0], 5)}, {num(post['interval_90'][1], 5)}]"])
    return html_table(["parameter", "unit", "estimate (identification)", "std (identification)",
                   "Gaussian 90 % interval (estimate +- 1.645 std)", "posterior mean", "posterior std",
                   "posterior 90 % credible interval"], rows, text_columns=(0, 1))


def statistics_table(result) -> str:
    """HTML table of the sampler's draws, rounds, effective sample size, failed runs and status."""
    from fracid.report.markup import html_table, num

    errors = ", ".join(f"{name} {num(e, 2)}" for name, e in zip(result.names, result.mean_error))
    rows = [["draws (forward runs)", len(result.x)], ["rounds", result.rounds],
            ["effective sample size (ESS)", num(result.ess, 4)],
            ["Monte-Carlo error of the posterior means", errors], ["failed runs", result.failed]]
    if result.levels is not None:
        levels = result.levels.summary()
        rows[0:3] = [["draws on the screening (coarse) mesh", levels["coarse_draws"]],
                     ["their effective sample size", num(levels["coarse_ess"], 4)],
                     ["fine-mesh runs (the correction)", levels["fine_runs"]],
                     ["spread of the fine / coarse likelihood ratio (1: the coarse mesh screens perfectly)",
                      num(levels["spread"], 3)],
                     ["effective sample size (ESS): the fewest equivalent independent draws", num(result.ess, 4)],
                     ["equivalent independent draws per parameter (its posterior mean as precise as that many draws)",
                      ", ".join(f"{n} {num(v, 4)}" for n, v in zip(result.names, levels["equivalent_draws"]))]]
    rows += [[f"note: {note}", ""] for note in result.notes] + [["status", result.status]]
    return html_table(["", ""], rows, text_columns=(0, 1))


def write_posterior_page(path, result, pngs: dict, *, title: str = "fracid posterior", provenance=None) -> Path:
    """A self-contained HTML page: the identification's Gaussian estimate beside the posterior per
    parameter, the sampler's statistics and rounds, the figures ``pngs`` (``corner`` and
    ``posterior_predictive`` PNG bytes) embedded and, collapsed, how the run was made (``provenance``)."""
    from fracid.report.error_terms import posterior_model_error
    from fracid.report.markup import esc, generated_now, html_image, html_table, num, provenance_section, write_document

    table, stats = comparison_table(result), statistics_table(result)
    status = esc(result.status) if result.converged else f'<span class="warn">{esc(result.status)}</span>'
    history = html_table(["round", "level (coarse: the screening)", "draws", "failed", "ESS after the round (fine: equivalent draws)",
                          "proposal components"],
                     [[k + 1, h.get("level", "coarse" if result.levels is not None else "fine"), h.get("draws", ""),
                       h.get("failed", ""), num(h.get("ess"), 4), h.get("components", "") or ""]
                      for k, h in enumerate(result.history)])
    names = ", ".join(str(n) for n in result.names)
    body = [
        f"<h1>{esc(title)}</h1>",
        (f'<p class="meta">Generated {esc(generated_now())} by fracid. Parameters: {esc(names)}; '
         f"{np.size(result.y_exp)} measured values.</p>"),
        "<h2>Identification and posterior</h2>",
        table,
        (f"<p>Identification: its Gaussian estimate; its interval is the Gaussian 90 % interval "
         f"estimate +- 1.645 std. Posterior: adaptive importance sampling on the exact forward model (every draw "
         f"one forward run), prior uniform between the bounds of [identify.bounds] (log-uniform where log-scaled); "
         f"its interval is the equal-tailed 90 % credible interval of the weighted draws. Status: {status}.</p>"),
        stats,
        posterior_model_error(result),
        "<h2>Figures</h2>",
        html_image(pngs["corner"], "corner plot",
               "Weighted draws of every parameter (diagonal: histogram, dotted: 90 % credible interval) and pair "
               "(below: 2D histogram), with the identification's Gaussian in red (normal curve; 1 and 2 std "
               "ellipses; x its estimate; orange +: the posterior mean)."),
        html_image(pngs["posterior_predictive"], "posterior predictive",
               "Measured points with +- 1 std, the posterior 90 % band of the computed curve (without measurement "
               "noise), its median, and the identification's fit (dashed)."),
        "<h2>Rounds of the sampler</h2>",
        history,
        provenance_section(provenance),
    ]
    return write_document(path, title, body)
