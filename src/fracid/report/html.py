"""One self-contained HTML report of an identification (figures embedded as PNG data URIs).

The file needs nothing else: inline CSS, images as ``data:image/png;base64`` URIs, no external
resource. A small inline script counts the images that decoded after the page loaded and writes the
counts to ``<body data-images-loaded=".." data-images-total="..">`` so a headless browser can check
the report.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from fracid.inverse.core.fit_status import status_action
from fracid.report.error_terms import error_terms_section
from fracid.report.markup import esc, generated_now, html_image, num, provenance_section, html_table, write_document
from fracid.report.stages import stage_sections, runs_section, status_label


def fit_metrics(result, skip=()) -> list[dict]:
    """Fit of the curve computed at the estimate to the measured one, per data block.

    Parameters
    ----------
    result : IdentificationResult
    skip : collection of str
        Blocks left out: displacement fields (peaks and a diagonal objective share mean nothing for them; their
        own section gives their fit, :mod:`fracid.report.views`).

    Returns
    -------
    list of dict
        Per block: ``block``, ``n`` (points where both values are finite), ``rms`` (root mean square
        of y_fit - y_exp over the measured range, in the block's unit: N for forces),
        ``rms_percent`` (rms in % of ``|measured peak|``), ``peak_measured`` and ``peak_computed`` (the
        value of largest magnitude; the computed one on the run's own curve when the result keeps it, so that a
        peak between two data points counts), ``peak_error_percent`` ((computed - measured) / ``|measured|`` in %),
        ``index_peak_measured``/``index_peak_computed`` (positions in y) and ``f`` (the block's share
        of the objective sum(((y_exp - y_fit) / std_exp)^2)).
    """
    from fracid.inverse.core.diagnostics import block_curve, block_peak
    from fracid.report.figures import float_array, result_blocks, run_curves

    y_exp = float_array(result.y_exp, np.nan)
    y_fit = float_array(result.y_fit, np.nan) if result.y_fit is not None else np.full_like(y_exp, np.nan)
    std = float_array(result.std_exp, np.nan)
    metrics = []
    for k, (name, start, stop) in enumerate(result_blocks(result)):
        if name in set(skip):
            continue
        y, fit, s = y_exp[start:stop], y_fit[start:stop], std[start:stop]
        both = np.isfinite(y) & np.isfinite(fit)
        im = block_peak(y)
        peak_m = float(y[im]) if im is not None else math.nan
        if both.any():
            residual = fit[both] - y[both]
            rms = float(np.sqrt(np.mean(residual**2)))
            ic, curve = block_peak(fit), block_curve(run_curves(result), k)
            peak_c = float(fit[ic]) if curve is None else float(curve[1][block_peak(curve[1])])
            f = float(np.sum((residual / s[both]) ** 2))
        else:
            rms, ic, peak_c, f = math.nan, None, math.nan, math.nan
        scale = abs(peak_m) if peak_m and math.isfinite(peak_m) else math.nan
        metrics.append({
            "block": name, "n": int(both.sum()), "rms": rms, "rms_percent": 100.0 * rms / scale,
            "peak_measured": peak_m, "peak_computed": peak_c,
            "peak_error_percent": 100.0 * (peak_c - peak_m) / scale,
            "index_peak_measured": None if im is None else start + im,
            "index_peak_computed": None if ic is None else start + ic, "f": f,
        })
    return metrics


# ------------------------------------------------------------------------------------ sections


def parameter_section(result, control=None) -> str:
    from fracid.report.figures import parameter_units

    units = {**parameter_units(), **(getattr(result, "units", None) or {})}
    x = np.asarray(result.x, float)
    std = np.asarray(result.std, float)
    rows = []
    at_bound = set(getattr(result, "at_bound", None) or ())
    for name, v, s in zip(result.names, x, std):
        rel = f"{100.0 * s / abs(v):.3g}" if v != 0 and math.isfinite(v) and math.isfinite(s) else "n/a"
        shown = f"{name} (at a bound)" if name in at_bound else name
        rows.append([shown, num(v), num(s, 4), units.get(name, ""), rel])
    table = html_table(["parameter", "value", "std", "unit", "std / value [%]"], rows, text_columns=(0, 3))
    text = getattr(result, "status", "") or ("converged" if result.converged else "not converged")
    status = esc(text) if result.converged else f'<span class="warn">{esc(text)}</span>'
    action = getattr(result, "status_action", None)  # a MethodResult's knows its unidentified parameters
    action = action if isinstance(action, str) else status_action(text)
    status += f" (what to do: {esc(action)})" if action else ""
    warnings = result.warnings(control=control) if hasattr(result, "warnings") else []
    shown = "".join(f'<li><span class="warn">warning</span>: {esc(w)}</li>' for w in warnings)
    rms_text = result.rms_text() if hasattr(result, "rms_text") else "RMS error not computed"
    return (f"<h2>Identified parameters</h2>\n{table}\n"
            f"<p>{esc(status_label(result))}: {status}. Fit: {esc(rms_text)}. Standard "
            "deviations are the square roots of the diagonal of the posterior covariance C.</p>"
            + (f'\n<ul class="notes">{shown}</ul>' if shown else ""))


def correlation_section(result, figures) -> str:
    names = list(result.names)
    corr = np.asarray(result.correlation, float)
    rows = [[n] + [f"{v:+.3f}" if np.isfinite(v) else "n/a" for v in corr[i]] for i, n in enumerate(names)]
    table = html_table([""] + names, rows, text_columns=(0,))
    image = html_image(figures.to_png(figures.correlation_figure(result), stem="correlation"), "correlation matrix",
                   "Correlation matrix of the estimate (C_ij / (std_i std_j)); |value| near 1: the data "
                   "hardly separate the two parameters.")
    return f"<h2>Correlation</h2>\n{table}\n{image}"


def fit_section(result, control, figures, control_label=None, skip=()) -> str:
    """The fit of the curve blocks: figure, table and diagnostics; the blocks ``skip`` (displacement fields, shown
    in sections of their own) are named only."""
    metrics = fit_metrics(result, skip)
    rows = []
    for m in metrics:
        quantity = figures.block_quantity(m["block"])
        unit = quantity[quantity.rfind("[") + 1:-1] if quantity.endswith("]") else ""
        rows.append([m["block"], unit, m["n"], num(m["rms"], 4), num(m["rms_percent"], 3), num(m["peak_measured"], 5),
                     num(m["peak_computed"], 5), num(m["peak_error_percent"], 3), num(m["f"], 4)])
    table = html_table(["block", "unit", "points", "RMS error", "RMS / |measured peak| [%]", "measured peak",
                    "computed peak", "peak error [%]", "objective share f [-]"], rows, text_columns=(0, 1))
    fig = figures.fit_figure(result, control, control_label, skip=skip)
    image = "" if fig is None else html_image(
        figures.to_png(fig, stem="fit"), "measured and computed curves", "Measured points with the +/- 2 std band of the data and "
        + ("the curve computed at the estimate: the forward run's own curve (every step up to the data's last "
           "control value), dots where the data's points sample it." if figures.run_curves(result) else
           f"the curve computed at the estimate ({figures.AT_DATA_POINTS})."))
    unit_note = ("RMS error of the computed values over the measured range and peaks in the unit of the block "
                 "(N for forces, mm for widths); peaks are the values of largest magnitude; the objective share is "
                 "sum(((y_exp - y_fit) / std_exp)^2) over the block.")
    fields = [name for name, _, _ in figures.result_blocks(result) if name in set(skip)]
    if fields:
        unit_note += (f" Displacement field block(s) {', '.join(fields)}: not curves; their maps and fit per frame are "
                      "in their own sections (Displacement field ...).")
    return f"<h2>Fit</h2>\n{image}\n{table}\n<p>{esc(unit_note)}</p>\n{diagnostics_fragment(result, control)}"


def diagnostics_fragment(result, control) -> str:
    """The fit diagnostics (:mod:`fracid.inverse.core.diagnostics`): elastic slopes and peaks per force block,
    the worst residual, what they can see."""
    from fracid.inverse.core.diagnostics import ELASTIC_FRACTION, fit_diagnostics
    from fracid.report.figures import float_array

    control = getattr(result, "control", None) if control is None else control
    d = fit_diagnostics(None if control is None else float_array(control, np.nan), float_array(result.y_exp, np.nan),
                        float_array(result.std_exp, np.nan), float_array(result.y_fit, np.nan),
                        getattr(result, "blocks", None) or [], getattr(result, "quantities", None) or [],
                        getattr(result, "curves", None) or [])
    where = "control [mm]" if d["control"] == "mm" else "point index"
    rows = [[b["block"], b["elastic_points"], num(b["slope_data"], 4), num(b["slope_model"], 4),
             num(100 * b["slope_ratio"], 3), num(b["peak_data"], 5), num(b["control_peak_data"], 4),
             num(b["peak_model"], 5), num(b["control_peak_model"], 4), num(100 * b["peak_ratio"], 3)]
            for b in d["blocks"]]
    table = html_table(["force block", "elastic points", "measured slope", "computed slope", "computed / measured [%]",
                    "measured peak", f"at {where}", "computed peak", f"at {where}", "computed / measured [%]"],
                   rows, text_columns=(0,)) if rows else ""
    worst = d["worst"]
    text = (f"Worst residual: {worst['residual_std']:+.3g} std at point {worst['index']} (block {worst['block']}, "
            f"{where} {num(worst['control'], 4)}: computed {num(worst['computed'], 5)}, measured "
            f"{num(worst['measured'], 5)}). " if worst else "")
    text += (f"Elastic slope: the least-squares line through the origin and the points of each curve's own rising "
             f"branch (before its own peak) up to {100 * ELASTIC_FRACTION:.0f} % of its own peak (elastic points: the "
             "measured ones); when a curve has none that low, the secant to its first point, a lower bound of its "
             f"slope; slopes in the block's unit per {'mm' if d['control'] == 'mm' else 'point'}. Note: {d['note']}.")
    return f"<h3>Fit diagnostics</h3>\n{table}\n<p>{esc(text)}</p>"


def notes_section(result, data_notes) -> str:
    data_notes = [str(n) for n in data_notes]
    other = [str(n) for n in (result.notes or []) if str(n) not in set(data_notes)]
    parts = ["<h2>Notes</h2>"]
    if data_notes:
        parts.append("<h3>Data rules</h3>\n<ul class=\"notes\">" + "".join(f"<li>{esc(n)}</li>" for n in data_notes)
                     + "</ul>")
    if other:
        parts.append("<h3>Data and methods</h3>\n<ul class=\"notes\">" + "".join(f"<li>{esc(n)}</li>" for n in other)
                     + "</ul>")
    if len(parts) == 1:
        parts.append("<p>No notes.</p>")
    return "\n".join(parts)


def block_view_section(view) -> str:
    """The section of a block that is not a curve (:class:`~fracid.report.block_view.BlockView`: a
    displacement field's maps per frame): heading, text, table, figures."""
    table = html_table(view.header, view.rows) if view.rows else ""
    images = "\n".join(html_image(view.png(stem), stem.replace("_", " "), caption)
                        for stem, (_, caption) in view.figures.items())
    return "\n".join(part for part in (f"<h2>{esc(view.heading)}</h2>", f"<p>{esc(view.text)}</p>", table, images)
                     if part)


# ------------------------------------------------------------------------------------ report


def write_report(path, result, *, control=None, title: str = "fracid identification", data_notes=(),
                 extra_sections=(), control_label=None, provenance=None, fields=None, views=None) -> Path:
    """Write one self-contained HTML report of an identification.

    Parameters
    ----------
    path : str or Path
        The HTML file to write (parent directories are created).
    result : IdentificationResult
    control : array_like, optional
        Control value [mm] of every measured value (``ExperimentalData.control``); the result's
        ``control`` when omitted; the fit figure uses the point index without either.
    title : str
    data_notes : sequence of str
        Rules applied to the data (e.g. ``ExperimentalData.notes``), listed first in the notes.
    extra_sections : sequence of (str, str)
        (heading, HTML fragment) appended at the end; the heading is escaped, the fragment is not.
    control_label : str, optional
        The fit figure's x-axis label (e.g. ``"CMOD [mm]"``); by default from the result's ``control_names``.
    provenance : dict, optional
        How the result was obtained (:func:`fracid.store.provenance.collect`); the result's ``provenance``
        when omitted. Shown last, collapsed: "How this was run".
    fields : dict of str -> dict, optional
        The coordinates of the blocks that have a view, by block name: the observation kind's ``coordinates()``
        (for a displacement field ``frame``, ``component``, ``point``, ``x``, ``y`` [mm], ``control`` [mm]),
        optionally with ``covariance`` (the block's data covariance [mm^2]) and ``view`` (a key of
        :data:`fracid.report.views.VIEWS`; by default the view of the block's quantity). Each such block gets
        the section of its view (a displacement field: "Displacement field <name>", maps per frame, a summary, a
        table per frame) instead of a curve panel; a block without coordinates whose quantity a view shows
        (a field's ``"u"``) is named but not drawn.
    views : list of BlockView, optional
        The views already built by :func:`fracid.report.views.block_views` (``fields`` is then not used):
        ``fracid identify`` builds them once for the report and figures/.

    Returns
    -------
    Path
        The file written.
    """
    from fracid.report import figures  # matplotlib is imported only when a report is written
    from fracid.report.views import block_views_and_skipped

    views, skip = block_views_and_skipped(result, fields, views, control_label)
    date = generated_now()
    names = ", ".join(str(n) for n in result.names)
    body = [
        f"<h1>{esc(title)}</h1>",
        (f'<p class="meta">Generated {esc(date)} by fracid. Identified parameters: {esc(names)}; '
         f"{np.size(result.y_exp)} measured values.</p>"),
        parameter_section(result, control),
        correlation_section(result, figures),
        fit_section(result, control, figures, control_label, skip),
        error_terms_section(result),
        *(block_view_section(view) for view in views),
        *stage_sections(result, figures),
        runs_section(result),
        notes_section(result, data_notes),
    ]
    for heading, fragment in extra_sections:
        body.append(f"<h2>{esc(heading)}</h2>\n{fragment}")
    body.append(provenance_section(getattr(result, "provenance", None) if provenance is None else provenance))
    return write_document(path, title, body)


__all__ = ["block_view_section", "correlation_section", "fit_metrics", "fit_section", "notes_section",
           "parameter_section", "write_report"]
