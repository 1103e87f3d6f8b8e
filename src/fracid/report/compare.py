"""The report of ``fracid compare``: models ranked by log evidence on one data set
(:class:`~fracid.inverse.studies.comparison_result.ComparisonResult`).

:func:`write_compare` writes ``compare.json``, ``figures/compare_fits.png`` (the data with every model's fit
overlaid, :func:`fits_figure`), ``figures/compare_evidence.png`` (the log evidences with their Monte-Carlo
error bars and the Laplace approximations, :func:`evidence_figure`) and ``compare.html`` (:data:`REPORT`): the
warnings first (models not compared or not ranked, doubtful numbers), the ranking table, both figures, per model
its parameters, its verdict and its posterior's status, the failures, the definitions, the prior rule and how it
was run.

Units: control [mm], force [N]; the log evidences are natural logarithms [-].
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from fracid.inverse.studies.evidence import TIE_SIGMAS
from fracid.report.figures import (MEASURED, block_control_labels, block_panels, block_run_curve, draw_computed,
                                   finish_block_panel, new_figure, to_png)
from fracid.report.html import parameter_section
from fracid.report.markup import duration, esc, generated_now, html_image, html_table, provenance_section, write_document

__all__ = ["DEFINITIONS", "REPORT", "evidence_figure", "fits_figure", "write_compare"]

#: the report's file name: its own, so that it never replaces identify's or study's report.html in a shared --out
REPORT = "compare.html"

#: what the table's numbers are (the report's and the docs' paragraph)
DEFINITIONS = (
    "log Z: log evidence p(y | model) with the prior uniform between each model's bounds (log-uniform for its log "
    "parameters) and the Gaussian likelihood normalised, from the importance weights of its posterior's draws "
    "(adaptive importance sampling on the exact model), +- its Monte-Carlo standard error. Laplace: the Gaussian "
    "approximation at the estimate, log L + log prior + p/2 log(2 pi) + 1/2 log det Sigma with Sigma = (S^T C^-1 "
    "S)^-1. delta log Z: the log Bayes factor against the first. AIC = 2 p - 2 log L, BIC = p ln n - 2 log L at "
    "the estimate (lower is better). MAP objective: chi2 plus the term of the prior the search gave, the objective "
    "the inverse method minimised. RMS in % of the measured peak. A tie: log Z within "
    f"{TIE_SIGMAS:g} combined Monte-Carlo errors of the first's; the Monte-Carlo error is the larger of the delta "
    "method's and a bootstrap over the draws. Not estimated, not ranked: a posterior whose effective sample size is "
    "below the sampler's floor. log Z, bounds widened: log Z - log(volume ratio) with every prior span widened "
    "(exact when the likelihood has no mass beyond the bounds; a lower bound when the posterior reaches them).")


def _colours(n: int) -> list:
    from matplotlib import colormaps

    return [colormaps["tab10"](i % 10) for i in range(n)]


def fits_figure(result):
    """The data (points, +- 2 std band) and every model's curve computed at its estimate (the run's own,
    :func:`~fracid.report.figures.draw_computed`; the line through the data's points for a model without it),
    one panel per data block."""
    data = result.data
    y, std = np.asarray(data.y, float), np.asarray(data.std, float)
    fig, panels = block_panels(list(data.blocks), np.asarray(data.control, float), y.size)
    labels = block_control_labels(result.scores[0].identification, len(panels))
    for k, ((ax, name, part, x), label) in enumerate(zip(panels, labels)):
        order = np.argsort(x, kind="stable")
        ax.fill_between(x[order], (y[part] - 2 * std[part])[order], (y[part] + 2 * std[part])[order], color=MEASURED,
                        alpha=0.15, lw=0, label="data +/- 2 std")
        for score, colour in zip(result.scores, _colours(len(result.scores))):
            ident = score.identification
            draw_computed(ax, x, np.asarray(ident.y_fit, float)[part], block_run_curve(ident, k), colour=colour,
                          lw=1.5, label=f"{score.rank}. {score.label} (RMS {score.rms_percent:.2g} %)")
        ax.plot(x, y[part], "o", color="k", ms=3.5, label="data", zorder=3)
        finish_block_panel(ax, name, True, label)
    return fig


#: the evidence figure adds a panel of the models within this many log units of the best when others lie
#: further off (their spread would hide the error bars of the close ones)
ZOOM = 10.0


def evidence_figure(result):
    """The log evidence of every model with +- :data:`TIE_SIGMAS` Monte-Carlo standard errors (bars) and the
    Laplace approximation (open marker), best at the top, and beside it the models within :data:`ZOOM` of the
    best when some lie further; None when no model has a log evidence."""
    scores = [s for s in result.scores if s.estimated]  # not the log evidences below the ESS floor
    if not scores:
        return None
    near = [s for s in scores if scores[0].log_evidence - s.log_evidence <= ZOOM]
    panels = [scores] if len(near) in (1, len(scores)) else [scores, near]
    fig = new_figure(6.4 * len(panels), 0.6 * len(scores) + 1.6)
    for ax, shown in zip(np.atleast_1d(fig.subplots(1, len(panels))), panels):
        _evidence_panel(ax, shown)
    return fig


def _evidence_panel(ax, scores) -> None:
    rows = np.arange(len(scores))[::-1]
    ax.errorbar([s.log_evidence for s in scores], rows, xerr=TIE_SIGMAS * np.array([s.log_evidence_error for s in scores]),
                fmt="o", color="k", capsize=4, label=f"log Z +/- {TIE_SIGMAS:g} MC std")
    ax.plot([s.log_evidence_laplace for s in scores], rows, "s", mfc="none", color="#d62728", label="Laplace")
    for row, s in zip(rows, scores):
        ax.annotate(s.evidence_text(), (s.log_evidence, row), textcoords="offset points", xytext=(0, 7), ha="center",
                    fontsize="x-small")
    ax.set_yticks(rows, [s.label for s in scores])
    ax.set_ylim(-0.7, len(scores) - 0.3)
    ax.set_xlabel("log evidence [-]")
    ax.grid(True, axis="x", alpha=0.3)
    ax.legend(fontsize="small")


def _model_section(score) -> str:
    ident = score.identification
    verdict = score.verdict.text({name: unit for name, unit in (ident.units or {}).items() if unit != "-"})
    rank = f"{score.rank}." if score.rank else "not ranked:"
    return (f"<details><summary>{esc(rank)} {esc(score.label)} ({esc(score.model)}): parameters, verdict, "
            f"posterior</summary>\n{parameter_section(ident)}\n<h3>Verdict</h3>\n<pre>{esc(verdict)}</pre>\n"
            f"<p>Posterior: {esc(score.posterior_status)}; {ident.forward_runs} identification runs"
            + (f", {len(score.posterior.x)} posterior draws, ESS {score.posterior.ess:.0f}" if score.posterior else "")
            + f"; {esc(duration(score.seconds))}.</p>\n</details>")


def _page(result, pngs: dict, title: str, provenance) -> list:
    header, rows = result.table()
    warnings = result.warnings()
    body = [f"<h1>{esc(title)}</h1>", f'<p class="meta">Generated {esc(generated_now())} by fracid.</p>']
    if warnings:  # first: what is missing from the ranking or doubtful in it
        body += ['<h2 class="warning">Warnings</h2>',
                 '<ul class="warnings">' + "".join(f"<li>{esc(w)}</li>" for w in warnings) + "</ul>"]
    body += ['<ul class="notes">' + "".join(f"<li>{esc(n)}</li>" for n in result.notes()[len(warnings):]) + "</ul>",
            "<h2>Ranking by log evidence</h2>", html_table(header, rows, text_columns=(1, 11)),
            f"<p>{esc(DEFINITIONS)}</p>"]
    if result.settings.get("prior"):
        body.append(f"<p>Prior of every model: {esc(result.settings['prior'])}.</p>")
    captions = {"compare_evidence": "Log evidence of every model with its Monte-Carlo error bars and the Laplace "
                                    "approximation at the estimate.",
                "compare_fits": "The data and every model's curve computed at its estimate (its forward run's own "
                                "curve, dots where the data's points sample it)."}
    body += [html_image(png, name, captions[name]) for name, png in pngs.items()]
    body.append("<h2>Models</h2>")
    body += [_model_section(score) for score in result.scores]
    body += [f"<p><strong>{esc(label)}: not compared.</strong> {esc(why)}</p>" for label, why in result.failures.items()]
    settings = result.settings.get("posterior", {})
    body.append(f"<p>Inverse method {esc(result.settings.get('method', ''))}; posterior settings "
                f"{esc(', '.join(f'{k} {v}' for k, v in settings.items()))}.</p>")
    body.append(provenance_section(provenance))
    return body


def write_compare(out, result, *, title: str = "fracid compare", provenance=None) -> list[str]:
    """Write the comparison's files into ``out``: compare.json, figures/compare_fits.png,
    figures/compare_evidence.png (when a model has a log evidence) and :data:`REPORT`; their names (relative)."""
    out = Path(out)
    (out / "figures").mkdir(parents=True, exist_ok=True)
    result.save(out / "compare.json")
    drawn = {"compare_evidence": evidence_figure(result), "compare_fits": fits_figure(result) if result.scores else None}
    pngs = {name: to_png(fig) for name, fig in drawn.items() if fig is not None}
    for name, png in pngs.items():
        (out / "figures" / f"{name}.png").write_bytes(png)
    write_document(out / REPORT, title, _page(result, pngs, title, provenance))
    return ["compare.json", REPORT, *(f"figures/{name}.png" for name in pngs)]
