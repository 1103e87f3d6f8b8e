"""Figures and report of a study (:func:`fracid.inverse.studies.study.run_study`).

:func:`write_study` writes the JSON and CSV tables of the study, its figures as PNG files and one
HTML report: the identification report of :func:`fracid.report.html.write_report` followed by the
study's sections (verdict, posterior, sensitivity, uniqueness, multi-start, stability, predictions, size
effect). A study with a sampled posterior also gets the files of ``fracid posterior``
(:func:`fracid.report.posterior.write_posterior`: posterior.csv, .json, .nc, .html and the corner and
predictive figures), and its report a "Posterior" section: the identification's and the posterior's
90 % intervals side by side, the sampler's statistics and those two figures.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from fracid.report.figures import (ESTIMATE, MEASURED, NEIGHBOUR, new_figure, parameter_axis, parameter_label,
                                   parameter_units, sensitivity_figure, to_png)
from fracid.report.html import write_report
from fracid.report.markup import esc, html_image, html_table
from fracid.report.size_effect_figure import size_effect_figure
from fracid.report.posterior import (comparison_table, corner_figure, predictive_figure, statistics_table,
                                     write_posterior)


def valley_figure(maps, multi_start=None, truth=None, names=None):
    """Objective over each parameter pair (population coloured by log10(f - f_ref + 1)), the valley
    (points within the chi^2 level of the reference: the estimate's objective on a centred map, unless a
    population point fits better) and the multi-start starts and ends.

    ``names`` orders the columns of the multi-start points and of ``truth`` (the pair's own order
    when omitted, which only fits two parameters)."""
    if not maps:
        return None
    fig = new_figure(5.2 * len(maps), 4.4)
    axes = np.atleast_1d(fig.subplots(1, len(maps)))
    for ax, m in zip(axes, maps):
        reference = "f_estimate" if m.centred and m.f[0] <= m.f.min() else "f_min"
        excess = m.f - m.f.min()
        sc = ax.scatter(m.points[:, 0], m.points[:, 1], c=np.log10(excess + 1.0), cmap="viridis_r", s=25,
                        edgecolors="none")
        fig.colorbar(sc, ax=ax, label=f"log10(f - {reference} + 1) [-]")
        ax.plot(m.points[m.valley, 0], m.points[m.valley, 1], "o", mfc="none", mec=NEIGHBOUR, ms=10, mew=1.6,
                label=f"valley: f - {reference} <= {m.level:.3g} ({int(m.valley.sum())} points)")
        if m.centred:
            ax.plot([m.points[0, 0]], [m.points[0, 1]], "D", color=ESTIMATE, ms=8, mec="k", mew=0.6, label="estimate")
        i, j = (list(names).index(m.names[0]), list(names).index(m.names[1])) if names is not None else (0, 1)
        if multi_start is not None:
            for a, b in zip(multi_start.starts, multi_start.ends):
                ax.annotate("", xy=(b[i], b[j]), xytext=(a[i], a[j]), arrowprops={"arrowstyle": "->", "color": ESTIMATE})
            ax.plot(multi_start.ends[:, i], multi_start.ends[:, j], "*", color=ESTIMATE, ms=12, mec="k", mew=0.5,
                    label="multi-start ends")
        if truth is not None:
            ax.plot([truth[i]], [truth[j]], "P", color="k", ms=10, label="truth")
        parameter_axis(ax, "x", m.points[:, 0])
        parameter_axis(ax, "y", m.points[:, 1])
        ax.set_xlabel(parameter_label(m.names[0]))
        ax.set_ylabel(parameter_label(m.names[1]))
        title = f"valley correlation {m.correlation:+.2f}" if np.isfinite(m.correlation) else "valley"
        ax.set_title(title, fontsize=9)
        ax.grid(alpha=0.3)
        ax.legend(fontsize="x-small", loc="best")
    return fig


def stability_figure(stability, names, estimate=None, std=None):
    """Estimates of the noisy replicates per parameter, with the estimate and its +-2 std band."""
    ok = stability.ok
    p = len(names)
    fig = new_figure(3.2 * p, 3.4)
    axes = np.atleast_1d(fig.subplots(1, p))
    for j, (ax, name) in enumerate(zip(axes, names)):
        ax.plot(np.arange(1, ok.sum() + 1), stability.estimates[ok, j], "o", color=MEASURED, label="replicates")
        if estimate is not None:
            ax.axhline(estimate[j], color=ESTIMATE, label="estimate")
            if std is not None:
                ax.axhspan(estimate[j] - 2 * std[j], estimate[j] + 2 * std[j], color=ESTIMATE, alpha=0.12,
                           label="+- 2 std")
        ax.set_xlabel("replicate")
        ax.set_ylabel(parameter_label(name))
        ax.set_title(f"scatter {stability.relative_scatter[j]:.1%} (noise {stability.noise_level:.1%})", fontsize=9)
        ax.grid(alpha=0.3)
    axes[0].legend(fontsize="x-small")
    return fig


def prediction_figure(predictions):
    """Held-out data and their prediction at the estimate with a +-2 std band."""
    shown = [p for p in predictions if p.status == "ok"]
    if not shown:
        return None
    fig = new_figure(4.6 * len(shown), 3.6)
    axes = np.atleast_1d(fig.subplots(1, len(shown)))
    for ax, p in zip(axes, shown):
        ax.errorbar(p.control, p.y_exp, yerr=p.std_exp, fmt="o", ms=3, color=MEASURED, label="measured")
        ax.plot(p.control, p.y, "-", color=ESTIMATE, label="predicted")
        ax.fill_between(p.control, p.y - 2 * p.std, p.y + 2 * p.std, color=ESTIMATE, alpha=0.15, label="+- 2 std")
        ax.set_title(f"{p.name}: RMS {p.relative_rms:.1%}, chi2/point {p.chi2_per_point:.2f}", fontsize=9)
        ax.set_xlabel("control [mm]")
        ax.grid(alpha=0.3)
        ax.legend(fontsize="x-small")
    return fig


def study_figures(study, control=None, truth=None, size_effect=None) -> dict:
    """All figures of a study by name (None where there is nothing to draw)."""
    figs = {"valley": valley_figure(study.maps, study.multi_start, truth, study.names),
            "predictions": prediction_figure(study.predictions)}
    if study.sensitivity is not None:
        figs["sensitivity"] = sensitivity_figure(study.sensitivity, control)
    if study.stability is not None and study.stability.ok.sum() >= 2:
        ident = study.identification
        figs["stability"] = stability_figure(study.stability, study.names, ident.x, ident.std)
    if size_effect is not None:
        figs["size_effect"] = size_effect_figure(**size_effect)
    return figs


def _verdict_section(study) -> str:
    units = {**parameter_units(), **(study.identification.units or {})}
    rows = [[v.name, v.status, f"{v.value:.5g}", f"{v.std:.3g}", f"{v.std / abs(v.value):.1%}", v.measure,
             f"{v.partner} ({v.correlation:+.3f})" if v.partner else "", f"{v.variance_removed:.0%}",
             "; ".join(v.remarks + tuple(f"would help: {s}" for s in v.suggestions))] for v in study.verdict.parameters]
    table = html_table(["parameter", "verdict", "estimate", "std", "std/|x|", "measure", "most correlated with",
                    "prior variance removed", "remarks"], rows, text_columns=(0, 1, 5, 6, 8))
    if getattr(study, "posterior", None) is not None:
        table = ("<p>Measure: the posterior's equal-tailed 90 % credible interval (see Posterior below). Estimate: the "
                 "posterior mean; std: the interval's half-width / 1.645 (its standard deviation if the posterior were "
                 "normal); correlations: the weighted covariance of the draws.</p>" + table)
    text = "<pre>" + esc(study.verdict.text(units)) + "</pre>"
    runs = f"<p>{esc(study.runs_text())}</p>" if getattr(study, "runs", None) else ""
    notes = "".join(f"<li>{esc(n)}</li>" for n in getattr(study, "notes", ()))
    return table + text + runs + (f'<ul class="notes">{notes}</ul>' if notes else "")


def _posterior_section(post, pngs: dict) -> str:
    """The identification's Gaussian beside the sampled posterior, the sampler's statistics and its figures."""
    table, stats = comparison_table(post), statistics_table(post)
    status = esc(post.status) if post.converged else f'<span class="warn">{esc(post.status)}</span>'
    text = ("<p>Adaptive importance sampling on the exact forward model (every draw one forward run, stored in "
            "runs.sqlite under the label \"posterior\"), started from the identification's Gaussian, prior uniform "
            "between the bounds of [identify.bounds] (log-uniform where log-scaled), with the [posterior] settings. "
            f"Status: {status}. The draws and their weights are in posterior.csv, the numbers in posterior.json; "
            '<a href="posterior.html">posterior.html</a> shows the sampler\'s rounds too.</p>')
    figures = [html_image(pngs["corner"], "corner plot",
                      "Weighted draws of every parameter (diagonal: histogram, dotted: 90 % credible interval) and "
                      "pair (below: 2D histogram), with the identification's Gaussian in red (normal curve; 1 and 2 "
                      "std ellipses; x its estimate; orange +: the posterior mean).")]
    if pngs.get("posterior_predictive") is not None:
        figures.append(html_image(pngs["posterior_predictive"], "posterior predictive",
                              "Measured points with +- 1 std, the posterior 90 % band of the computed curve (without "
                              "measurement noise) and its median at the data's points, and the identification's fit "
                              "(dashed: its run's own curve)."))
    return text + table + stats + "".join(figures)


def posterior_pngs(study, data=None) -> dict:
    """The corner and predictive figures of the study's posterior as PNG bytes (empty without one)."""
    post = getattr(study, "posterior", None)
    if post is None:
        return {}
    control = None if data is None else data.control
    blocks = None if data is None else data.blocks
    return {"corner": to_png(corner_figure(post)),
            "posterior_predictive": to_png(predictive_figure(post, control, blocks, study.identification))}


def study_sections(study, figures: dict, posterior_figures: dict | None = None) -> list:
    """(heading, HTML) sections of a study for :func:`~fracid.report.html.write_report`.

    ``posterior_figures``: the PNG bytes of the posterior's ``corner`` and ``posterior_predictive``
    figures (drawn here when the study has a posterior and they are not given)."""
    sections = [("Verdict", _verdict_section(study))]
    if getattr(study, "posterior", None) is not None:
        pngs = posterior_figures or posterior_pngs(study)
        sections.append(("Posterior", _posterior_section(study.posterior, pngs)))
    captions = {
        "sensitivity": "Normalised sensitivities along the load history and the share of each parameter's prior "
                       "(bounds) variance removed by the data up to each point.",
        "valley": "Objective over the population around the estimate (diamond); circled: the valley of sets the "
                  "data cannot tell from the estimate (chi^2 95 % level); arrows: local fits from distinct starting points.",
        "stability": "Estimates from data with noise added (fixed seeds): the scatter against the estimate's +-2 std.",
        "predictions": "Data not used for calibration, predicted at the estimate (+-2 std propagated from its "
                       "covariance).",
        "size_effect": "Nominal strength versus size with Bazant's size effect law fitted.",
    }
    for name in [*captions, *(n for n in figures if n not in captions)]:  # a figure without a caption too
        fig = figures.get(name)
        if fig is not None:
            sections.append((name.replace("_", " ").capitalize(), html_image(to_png(fig), name, captions.get(name, ""))))
    if study.multi_start is not None:
        ms = study.multi_start
        rows = [[i + 1, *np.round(a, 6).tolist(), *np.round(b, 6).tolist(), f"{f:.4g}"]
                for i, (a, b, f) in enumerate(zip(ms.starts, ms.ends, ms.f))]
        header = ["start"] + [f"start {n}" for n in study.names] + [f"end {n}" for n in study.names] + ["f at end"]
        sections.append(("Multi-start check", html_table(header, rows)))
    return sections


def write_study(directory, study, data, *, title="fracid study", truth=None, size_effect=None,
                provenance=None) -> list:
    """Write the study's JSON/CSV tables, figures (PNG) and HTML report into ``directory``; with a
    posterior, also the files of :func:`~fracid.report.posterior.write_posterior`.

    ``provenance`` (:func:`fracid.store.provenance.collect`) is shown, collapsed, in the reports; the
    identification's own when omitted.

    Returns the paths written; a note in brackets (a string, not a path) for a posterior file skipped.
    """
    directory = Path(directory)
    provenance = provenance or getattr(study.identification, "provenance", None)
    study.save(directory)
    figs = study_figures(study, data.control if data is not None else None, truth, size_effect)
    (directory / "figures").mkdir(parents=True, exist_ok=True)
    written = [directory / "study.json", directory / "verdict.txt"]
    for name, fig in figs.items():
        if fig is not None:
            path = directory / "figures" / f"{name}.png"
            path.write_bytes(to_png(fig))
            written.append(path)
    pngs, notes = None, []
    if getattr(study, "posterior", None) is not None:
        post = study.posterior
        for item in write_posterior(directory, post, data=data, fit=study.identification,
                                    title=f"{title}: posterior", provenance=provenance):  # log axes: the posterior's own (its space's)
            if item.startswith("("):
                notes.append(item)
            else:
                written.append(directory / item)
        pngs = {name: (directory / "figures" / f"{name}.png").read_bytes()
                for name in ("corner", "posterior_predictive")}
    report = write_report(directory / "report.html", study.identification,
                          control=None if data is None else data.control, title=title,
                          data_notes=() if data is None else data.notes,
                          extra_sections=study_sections(study, figs, pngs), provenance=provenance)
    return written + [report] + notes
