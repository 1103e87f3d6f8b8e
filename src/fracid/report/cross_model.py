"""Tables, figure and HTML report of cross-model calibrations and comparisons.

Inputs are the results of :mod:`fracid.inverse.studies.cross_model`: :class:`CrossCalibration` (model B
fitted to a curve of model A) and :class:`ModelComparison` (models fitted to one data set).
:func:`cross_rows` and :func:`comparison_rows` give the tables as formatted cells, written as
Markdown by :func:`markdown_table` and as HTML by :func:`write_cross_model_report`, which also
embeds :func:`curves_figure` and, per fitted model, the sections of the identification report
(:mod:`fracid.report.html`).

Units: CMOD [mm], force [N], energy [N mm]; parameters in the units of their class.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from fracid.report.figures import COMPUTED, MEASURED, NEIGHBOUR, new_figure, to_png
from fracid.report.html import fit_section, parameter_section
from fracid.report.markup import esc, generated_now, html_image, html_table, write_document
from fracid.report.stages import runs_section, stage_sections

#: line colours of the fitted models, in the order of the fits of a panel
_MODEL_COLOURS = (COMPUTED, "#2ca02c", NEIGHBOUR, "#9467bd")

_CROSS_HEADER = ["case", "source", "fitted model", "fitted parameters (+- std)", "RMS / peak [%]",
                 "peak force: source, fit [N]", "dissipated energy: source, fit [N mm]", "energy ratio fit / source [-]",
                 "forward runs"]
_COMPARISON_HEADER = ["model", "fitted parameters (+- std)", "RMS / peak [%]", "peak force [N]",
                      "dissipated energy [N mm]", "forward runs", "converged"]


@dataclass(frozen=True)
class CurvePanel:
    """One panel of :func:`curves_figure`: data points, optionally the full source curve, and fits.

    Parameters
    ----------
    title : str
    control, y : ndarray
        Data points [mm], [N].
    std : ndarray or None
        Their standard deviations [N] (drawn as a +-2 std band) or None.
    fits : sequence of ModelFit
        Fitted models; each is drawn as its run at the estimate.
    source : (label, control, force) or None
        The full curve the data were sampled from (cross-calibration).
    data_label : str
    """

    title: str
    control: np.ndarray
    y: np.ndarray
    std: np.ndarray | None
    fits: tuple
    source: tuple | None = None
    data_label: str = "data"

    @classmethod
    def of_cross(cls, title: str, cross) -> "CurvePanel":
        """The panel of a :class:`~fracid.inverse.studies.cross_model.CrossCalibration`."""
        return cls(title, cross.data.control, cross.data.y, None, (cross.fit,),
                   (f"source: {cross.source_label}", cross.source_control, cross.source_force),
                   data_label="source at the data points")

    @classmethod
    def of_comparison(cls, title: str, comparison, data_label: str = "measured") -> "CurvePanel":
        """The panel of a :class:`~fracid.inverse.studies.cross_model.ModelComparison` (data with +-2 std)."""
        data = comparison.data
        return cls(title, data.control, data.y, data.std, tuple(comparison.fits), None, data_label)


def curves_figure(panels, *, control_label: str = "CMOD [mm]"):
    """Force against the control quantity: data, source curves and the runs of the fitted models.

    Parameters
    ----------
    panels : sequence of CurvePanel
    control_label : str
        Label of the horizontal axis.

    Returns
    -------
    matplotlib.figure.Figure
        One panel per entry, side by side.
    """
    panels = list(panels)
    fig = new_figure(5.0 * len(panels), 4.0)
    axes = np.atleast_1d(fig.subplots(1, len(panels), squeeze=False)[0])
    for ax, panel in zip(axes, panels):
        if panel.std is not None:
            ax.fill_between(panel.control, panel.y - 2 * panel.std, panel.y + 2 * panel.std, color=MEASURED,
                            alpha=0.2, lw=0, label=f"{panel.data_label} +/- 2 std")
        if panel.source is not None:
            label, control, force = panel.source
            ax.plot(control, force, "-", color="k", lw=1.0, label=label)
        ax.plot(panel.control, panel.y, "o", color=MEASURED, ms=3.5, label=panel.data_label)
        for fit, colour in zip(panel.fits, _MODEL_COLOURS):
            ax.plot(fit.control, fit.force, "--", color=colour, lw=1.6,
                    label=f"{fit.label} (RMS {100 * fit.rms_relative:.1f} %)")
        ax.set_xlabel(control_label)
        ax.set_ylabel("force [N]")
        ax.set_title(panel.title, fontsize="medium")
        ax.set_ylim(bottom=0.0)
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize="x-small")
    return fig


def _parameters_text(fit) -> str:
    units = fit.units
    return "; ".join(f"{n} = {v:.4g} +- {s:.2g}" + (f" {units[n]}" if units.get(n, "-") != "-" else "")
                     for n, v, s in zip(fit.names, fit.x, fit.std))


def _source_text(cross) -> str:
    params = cross.source_params
    shown = ", ".join(f"{n} {getattr(params, n):.5g}" for n in params.names())
    return f"{cross.source_label} ({shown})"


def cross_rows(crosses) -> tuple[list, list]:
    """Header and formatted rows of cross-calibrations.

    Parameters
    ----------
    crosses : sequence of (str, CrossCalibration)
        Case label and result.
    """
    rows = []
    for case, cross in crosses:
        fit = cross.fit
        rows.append([case, _source_text(cross), fit.label, _parameters_text(fit), f"{100 * fit.rms_relative:.2f}",
                     f"{cross.source_peak_force:.1f}, {fit.peak_force:.1f}",
                     f"{cross.source_energy:.2f}, {fit.dissipated_energy:.2f}", f"{cross.energy_ratio:.3f}",
                     str(fit.forward_runs)])
    return list(_CROSS_HEADER), rows


def comparison_rows(comparison) -> tuple[list, list]:
    """Header and formatted rows of a model comparison (one row per model)."""
    rows = [[fit.label, _parameters_text(fit), f"{100 * fit.rms_relative:.2f}", f"{fit.peak_force:.1f}",
             f"{fit.dissipated_energy:.2f}", str(fit.forward_runs), "yes" if fit.identification.converged else "no"]
            for fit in comparison.fits]
    return list(_COMPARISON_HEADER), rows


def markdown_table(header, rows) -> str:
    """A GitHub Markdown table of formatted cells (``|`` in a cell is escaped)."""
    def line(cells):
        return "| " + " | ".join(str(c).replace("|", "\\|") for c in cells) + " |"

    return "\n".join([line(header), "|" + "---|" * len(header), *(line(r) for r in rows)])


def _fit_details(fit, control) -> str:
    from fracid.report import figures

    result = fit.identification
    final_stage = stage_sections(result, figures, limit=1)  # the stage that gave the estimate
    sections = [parameter_section(result), fit_section(result, control, figures), *final_stage, runs_section(result)]
    return (f"<details><summary>{esc(fit.label)} ({esc(fit.model_key)}): identification details</summary>\n"
            + "\n".join(sections) + "\n</details>")


def write_cross_model_report(path, *, crosses=(), comparisons=(), title="fracid: cross-model calibration",
                             intro: str = "", notes=()):
    """One self-contained HTML page of cross-calibrations and model comparisons.

    Parameters
    ----------
    path : str or Path
        The HTML file (parents created).
    crosses : sequence of (str, CrossCalibration)
        Case label and result of each cross-calibration.
    comparisons : sequence of (str, ModelComparison)
        Label and result of each comparison on one data set.
    title : str
    intro : str
        A paragraph of plain text under the title (escaped).
    notes : sequence of str
        Plain-text notes listed at the end (settings, meshes, sources of the data).

    Returns
    -------
    Path
        The file written.
    """
    crosses, comparisons = list(crosses), list(comparisons)
    panels = ([CurvePanel.of_cross(case, cross) for case, cross in crosses]
              + [CurvePanel.of_comparison(label, comparison) for label, comparison in comparisons])
    body = [f"<h1>{esc(title)}</h1>", f'<p class="meta">Generated {esc(generated_now())} by fracid.</p>']
    if intro:
        body.append(f"<p>{esc(intro)}</p>")
    if panels:
        body.append(html_image(to_png(curves_figure(panels)), "fitted curves",
                           "Data (points), the source curves of the cross-calibrations (black) and the runs of the "
                           "fitted models at their estimates (dashed)."))
    if crosses:
        header, rows = cross_rows(crosses)
        body.append("<h2>Cross-calibration: model B fitted to a curve of model A</h2>")
        body.append(html_table(header, rows, text_columns=(0, 1, 2, 3)))
        body.append("<p>RMS: root mean square of the force residual at the data points over the source's peak force. "
                    "Dissipated energy: external work minus elastic energy of the runs to the last data point.</p>")
    for label, comparison in comparisons:
        header, rows = comparison_rows(comparison)
        peak = float(np.max(np.abs(comparison.data.y)))
        body.append(f"<h2>{esc(label)}</h2>")
        body.append(html_table(header, rows, text_columns=(0, 1)))
        body.append(f"<p>{comparison.data.y.size} data points from {comparison.data.control[0]:.4g} to "
                    f"{comparison.data.control[-1]:.4g} mm; measured peak {peak:.1f} N (the RMS is relative to it). "
                    "Dissipated energy of each model's run at its estimate to the last data point.</p>")
        for failed, reason in getattr(comparison, "failures", {}).items():
            body.append(f"<p><strong>{esc(failed)}: not fitted.</strong> {esc(reason)}</p>")
    body.append("<h2>Identification details</h2>")
    for case, cross in crosses:
        body.append(f"<h3>{esc(case)}</h3>\n" + _fit_details(cross.fit, cross.data.control))
    for label, comparison in comparisons:
        body.append(f"<h3>{esc(label)}</h3>\n"
                    + "\n".join(_fit_details(fit, comparison.data.control) for fit in comparison.fits))
    if notes:
        body.append("<h2>Notes</h2>\n<ul class=\"notes\">" + "".join(f"<li>{esc(n)}</li>" for n in notes) + "</ul>")
    return write_document(path, title, body)
