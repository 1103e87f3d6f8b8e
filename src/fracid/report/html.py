"""One self-contained HTML report of an identification (figures embedded as PNG data URIs).

The file needs nothing else: inline CSS, images as ``data:image/png;base64`` URIs, no external
resource. A small inline script counts the images that decoded after the page loaded and writes the
counts to ``<body data-images-loaded=".." data-images-total="..">`` so a headless browser can check
the report.
"""

from __future__ import annotations

import base64
import datetime
import html
import math
from pathlib import Path

import numpy as np


_CSS = """
body { font-family: -apple-system, "Segoe UI", Helvetica, Arial, sans-serif; margin: 2em auto; max-width: 1100px;
       padding: 0 1em; color: #222; line-height: 1.4; }
h1 { border-bottom: 2px solid #444; padding-bottom: .2em; }
h2 { border-bottom: 1px solid #bbb; padding-bottom: .15em; margin-top: 1.8em; }
table { border-collapse: collapse; margin: .8em 0; font-size: 0.92em; }
th, td { border: 1px solid #ccc; padding: .25em .6em; text-align: right; }
th { background: #f0f0f0; }
td.text, th.text { text-align: left; }
tr.failed td { color: #888; }
figure { margin: 1em 0; }
figure img { max-width: 100%; height: auto; border: 1px solid #ddd; }
figcaption { font-size: 0.9em; color: #555; }
.meta { color: #555; }
.warn { color: #a40000; font-weight: bold; }
ul.notes li { margin: .2em 0; }
"""

_SCRIPT = """
window.addEventListener("load", function () {
  var images = Array.prototype.slice.call(document.images);
  var loaded = images.filter(function (img) { return img.complete && img.naturalWidth > 0; }).length;
  document.body.dataset.imagesLoaded = String(loaded);
  document.body.dataset.imagesTotal = String(images.length);
});
"""

_RUN_LABELS = {
    "knn": "KNN forward runs (population)",
    "knn_failed": "KNN failed runs",
    "knn_computed": "KNN runs computed (the others loaded from the store)",
    "kalman": "Kalman filter forward runs",
    "kalman_failed": "Kalman filter failed runs",
    "kalman_computed": "Kalman runs computed (the others loaded from the store)",
    "kalman_run_equivalents": "Kalman filter run equivalents (full curves)",
    "kalman_iterations": "Kalman filter global iterations",
    "wall_seconds": "wall time",
}


def _e(value) -> str:
    return html.escape(str(value), quote=True)


def _num(value, digits: int = 6) -> str:
    try:
        v = float(value)
    except (TypeError, ValueError):
        return _e(value)
    if math.isnan(v):
        return "n/a"
    if math.isinf(v):
        return "inf" if v > 0 else "-inf"
    return f"{v:.{digits}g}"


def _duration(seconds) -> str:
    try:
        s = float(seconds)
    except (TypeError, ValueError):
        return _e(seconds)
    if not math.isfinite(s):
        return "n/a"
    if s < 60:
        return f"{s:.1f} s"
    h, rest = divmod(round(s), 3600)
    m, sec = divmod(rest, 60)
    return f"{s:.0f} s ({h} h {m} min {sec} s)" if h else f"{s:.0f} s ({m} min {sec} s)"


def _table(header, rows, text_columns=(), row_classes=None) -> str:
    """HTML table; header and cells are already-formatted strings (escaped here)."""
    def cell(tag, k, value):
        cls = ' class="text"' if k in text_columns else ""
        return f"<{tag}{cls}>{_e(value)}</{tag}>"

    out = ["<table>", "<tr>" + "".join(cell("th", k, h) for k, h in enumerate(header)) + "</tr>"]
    for r, row in enumerate(rows):
        cls = f' class="{_e(row_classes[r])}"' if row_classes and row_classes[r] else ""
        out.append(f"<tr{cls}>" + "".join(cell("td", k, v) for k, v in enumerate(row)) + "</tr>")
    out.append("</table>")
    return "\n".join(out)


def _image(png: bytes, alt: str, caption: str) -> str:
    data = base64.b64encode(png).decode("ascii")
    return (f'<figure><img src="data:image/png;base64,{data}" alt="{_e(alt)}">'
            f"<figcaption>{_e(caption)}</figcaption></figure>")


# ------------------------------------------------------------------------------------ metrics


def fit_metrics(result) -> list[dict]:
    """Fit of the curve computed at the estimate to the measured one, per data block.

    Returns
    -------
    list of dict
        Per block: ``block``, ``n`` (points where both values are finite), ``rms`` (root mean square
        of y_fit - y_exp over the measured range, in the block's unit: N for forces),
        ``rms_percent`` (rms in % of |measured peak|), ``peak_measured`` and ``peak_computed`` (the
        value of largest magnitude), ``peak_error_percent`` ((computed - measured) / |measured| in %),
        ``index_peak_measured``/``index_peak_computed`` (positions in y) and ``f`` (the block's share
        of the objective sum(((y_exp - y_fit) / std_exp)^2)).
    """
    from fracid.inverse.diagnostics import block_peak
    from fracid.report.figures import _float_array, result_blocks

    y_exp = _float_array(result.y_exp, np.nan)
    y_fit = _float_array(result.y_fit, np.nan) if result.y_fit is not None else np.full_like(y_exp, np.nan)
    std = _float_array(result.std_exp, np.nan)
    metrics = []
    for name, start, stop in result_blocks(result):
        y, fit, s = y_exp[start:stop], y_fit[start:stop], std[start:stop]
        both = np.isfinite(y) & np.isfinite(fit)
        im = block_peak(y)
        peak_m = float(y[im]) if im is not None else math.nan
        if both.any():
            residual = fit[both] - y[both]
            rms = float(np.sqrt(np.mean(residual**2)))
            ic = block_peak(fit)
            peak_c = float(fit[ic])
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


def _parameter_section(result, control=None) -> str:
    from fracid.report.figures import parameter_units

    units = {**parameter_units(), **(getattr(result, "units", None) or {})}
    x = np.asarray(result.x, float)
    std = np.asarray(result.std, float)
    rows = []
    at_bound = set(getattr(result, "at_bound", None) or ())
    for name, v, s in zip(result.names, x, std):
        rel = f"{100.0 * s / abs(v):.3g}" if v != 0 and math.isfinite(v) and math.isfinite(s) else "n/a"
        shown = f"{name} (at a bound)" if name in at_bound else name
        rows.append([shown, _num(v), _num(s, 4), units.get(name, ""), rel])
    table = _table(["parameter", "value", "std", "unit", "std / value [%]"], rows, text_columns=(0, 3))
    text = getattr(result, "status", "") or ("converged" if result.converged else "not converged")
    status = _e(text) if result.converged else f'<span class="warn">{_e(text)}</span>'
    warnings = result.warnings(control=control) if hasattr(result, "warnings") else []
    shown = "".join(f'<li><span class="warn">warning</span>: {_e(w)}</li>' for w in warnings)
    rms = getattr(result, "rms_percent", float("nan"))
    return (f"<h2>Identified parameters</h2>\n{table}\n"
            f"<p>{_e(_status_label(result))}: {status}. Fit: RMS error {_num(rms, 3)} % of the measured peak. Standard "
            "deviations are the square roots of the diagonal of the posterior covariance C.</p>"
            + (f'\n<ul class="notes">{shown}</ul>' if shown else ""))


def _correlation_section(result, figures) -> str:
    names = list(result.names)
    corr = np.asarray(result.correlation, float)
    rows = [[n] + [f"{v:+.3f}" if np.isfinite(v) else "n/a" for v in corr[i]] for i, n in enumerate(names)]
    table = _table([""] + names, rows, text_columns=(0,))
    image = _image(figures.to_png(figures.correlation_figure(result)), "correlation matrix",
                   "Correlation matrix of the estimate (C_ij / (std_i std_j)); |value| near 1: the data "
                   "hardly separate the two parameters.")
    return f"<h2>Correlation</h2>\n{table}\n{image}"


def _fit_section(result, control, figures, control_label=None) -> str:
    metrics = fit_metrics(result)
    rows = []
    for m in metrics:
        quantity = figures.block_quantity(m["block"])
        unit = quantity[quantity.rfind("[") + 1:-1] if quantity.endswith("]") else ""
        rows.append([m["block"], unit, m["n"], _num(m["rms"], 4), _num(m["rms_percent"], 3), _num(m["peak_measured"], 5),
                     _num(m["peak_computed"], 5), _num(m["peak_error_percent"], 3), _num(m["f"], 4)])
    table = _table(["block", "unit", "points", "RMS error", "RMS / |measured peak| [%]", "measured peak",
                    "computed peak", "peak error [%]", "objective share f [-]"], rows, text_columns=(0, 1))
    image = _image(figures.to_png(figures.fit_figure(result, control, control_label)), "measured and computed curves",
                   "Measured points with the +/- 2 std band of the data and the curve computed at the estimate "
                   "(a line through its values at the data points).")
    unit_note = ("RMS error of the computed values over the measured range and peaks in the unit of the block "
                 "(N for forces, mm for widths); peaks are the values of largest magnitude; the objective share is "
                 "sum(((y_exp - y_fit) / std_exp)^2) over the block.")
    return f"<h2>Fit</h2>\n{image}\n{table}\n<p>{_e(unit_note)}</p>\n{_diagnostics_fragment(result, control)}"


def _diagnostics_fragment(result, control) -> str:
    """The fit diagnostics (:mod:`fracid.inverse.diagnostics`): elastic slopes and peaks per force block,
    the worst residual, what they can see."""
    from fracid.inverse.diagnostics import ELASTIC_FRACTION, fit_diagnostics
    from fracid.report.figures import _float_array

    control = getattr(result, "control", None) if control is None else control
    d = fit_diagnostics(None if control is None else _float_array(control, np.nan), _float_array(result.y_exp, np.nan),
                        _float_array(result.std_exp, np.nan), _float_array(result.y_fit, np.nan),
                        getattr(result, "blocks", None) or [], getattr(result, "quantities", None) or [])
    where = "control [mm]" if d["control"] == "mm" else "point index"
    rows = [[b["block"], b["elastic_points"], _num(b["slope_data"], 4), _num(b["slope_model"], 4),
             _num(100 * b["slope_ratio"], 3), _num(b["peak_data"], 5), _num(b["control_peak_data"], 4),
             _num(b["peak_model"], 5), _num(b["control_peak_model"], 4), _num(100 * b["peak_ratio"], 3)]
            for b in d["blocks"]]
    table = _table(["force block", "elastic points", "measured slope", "computed slope", "computed / measured [%]",
                    "measured peak", f"at {where}", "computed peak", f"at {where}", "computed / measured [%]"],
                   rows, text_columns=(0,)) if rows else ""
    worst = d["worst"]
    text = (f"Worst residual: {worst['residual_std']:+.3g} std at point {worst['index']} (block {worst['block']}, "
            f"{where} {_num(worst['control'], 4)}: computed {_num(worst['computed'], 5)}, measured "
            f"{_num(worst['measured'], 5)}). " if worst else "")
    text += (f"Elastic slope: the least-squares line through the measured points of the rising branch up to "
             f"{100 * ELASTIC_FRACTION:.0f} % of the block's peak, and through the computed values at the same points; "
             f"slopes in the block's unit per {'mm' if d['control'] == 'mm' else 'point'}. Note: {d['note']}.")
    return f"<h3>Fit diagnostics</h3>\n{table}\n<p>{_e(text)}</p>"


def _kalman_section(result, name, figures) -> str:
    fig = figures.kalman_figure(result)
    if fig is None:
        return "<h2>Kalman filter</h2>\n<p>No Kalman history in this result.</p>"
    image = _image(figures.to_png(fig), "Kalman filter history",
                   "Estimate after every step of the Kalman filter with +/- 2 std from the step's covariance; "
                   "dotted lines separate global iterations, the dashed line is the final value.")
    return f"<h2>Kalman filter</h2>\n{image}"


def _knn_section(result, name, figures) -> str:
    arrays = figures.knn_arrays(result)
    if arrays is None:
        return "<h2>KNN population</h2>\n<p>No KNN population in this result.</p>"
    points, f, failed, order, k = arrays
    parts = ["<h2>KNN population</h2>"]
    parts.append(_image(figures.to_png(figures.knn_objective_figure(result)), "KNN objective",
                        "Objective of every population point against each parameter (log scale); circles: the "
                        f"{k} nearest; crosses at the top: failed runs; vertical line: the final estimate."))
    fig = figures.knn_map_figure(result)
    if fig is not None:
        i, j = figures.strongest_pair(result)
        parts.append(_image(figures.to_png(fig), "KNN map",
                            f"Population over {result.names[i]} and {result.names[j]} (the most correlated pair), "
                            "coloured by log10 f, with the estimate and its 2-std ellipse."))
    errors = list((result.knn or {}).get("errors") or [""] * len(points))
    rows, classes = [], []
    for rank, idx in enumerate(order[:10], start=1):
        status = "ok" if not failed[idx] else f"failed: {errors[idx] if idx < len(errors) else ''}"[:120]
        rows.append([rank, _num(f[idx], 5)] + [_num(v, 5) for v in points[idx]] + [status])
        classes.append("failed" if failed[idx] else "")
    header = ["rank", "f"] + [figures.parameter_label(n) for n in result.names] + ["status"]
    parts.append(f"<h3>The {min(10, len(order))} best population points</h3>")
    parts.append(_table(header, rows, text_columns=(len(header) - 1,), row_classes=classes))
    knn = result.knn or {}
    if knn.get("x0") is not None:
        x0 = np.asarray(knn["x0"], float)
        prior = ", ".join(f"{n} = {_num(v, 5)}" for n, v in zip(result.names, x0))
        parts.append(f"<p>Prior of the Kalman filter (mean of the {k} nearest): {_e(prior)}.</p>")
    return "\n".join(parts)


#: report sections of the stages known by name: ``section(result, stage name, figures module)``
STAGE_SECTIONS = {"kalman": _kalman_section, "knn": _knn_section}


def _runs_section(result) -> str:
    runs = dict(result.runs or {})
    history = getattr(result, "history", None)
    if "kalman" in _stages(result) and "kalman_iterations" not in runs and history:
        runs["kalman_iterations"] = len({h.get("iteration", 1) for h in history})
    rows = []
    for key in list(_RUN_LABELS) + [k for k in runs if k not in _RUN_LABELS]:
        if key not in runs:
            continue
        value = runs[key]
        shown = _duration(value) if key == "wall_seconds" else _num(value, 6)
        rows.append([_run_label(result, key), shown])
    rows.append([f"{_status_label(result)} converged", "yes" if result.converged else "no"])
    return "<h2>Run statistics</h2>\n" + _table(["", ""], rows, text_columns=(0,))


def _stages(result) -> dict:
    """The stages the result declares (name -> label), in the order they ran."""
    return dict(getattr(result, "stages", None) or {})


def _status_label(result) -> str:
    """The stage that gave the estimate, as the status line names it."""
    return getattr(result, "status_label", None) or "identification"


def _run_label(result, key: str) -> str:
    """Row label of a run counter: known ones from :data:`_RUN_LABELS`, a stage's from its label."""
    if key in _RUN_LABELS:
        return _RUN_LABELS[key]
    for stage, label in _stages(result).items():
        if key == stage:
            return f"{label} forward runs"
        if key.startswith(f"{stage}_"):
            return f"{label} {key[len(stage) + 1:].replace('_', ' ')}"
    return key


def _record_value(value) -> str:
    """A recorded value in one cell: numbers formatted, sequences of up to 10 values listed."""
    def one(v):
        if isinstance(v, (int, float, np.number)) and not isinstance(v, bool):
            return f"{float(v):.6g}" if math.isfinite(float(v)) else str(float(v))
        return str(v)

    if isinstance(value, dict):
        return f"{len(value)} entries"
    if isinstance(value, (list, tuple, np.ndarray)):
        flat = list(np.ravel(np.asarray(value, dtype=object)))
        text = ", ".join(one(v) for v in flat[:10]) + (f", ... ({len(flat)} values)" if len(flat) > 10 else "")
    else:
        text = one(value)
    return text if len(text) <= 200 else text[:197] + "..."


def _stage_section(result, name: str, figures) -> str:
    """A stage the report has no section of its own for: its label and what it recorded
    (``result.records[name]``; its forward runs are under the run statistics)."""
    label = _stages(result).get(name, name)
    record = (getattr(result, "records", None) or {}).get(name)
    if isinstance(record, dict) and record:
        body = _table(["", ""], [[str(key), _record_value(value)] for key, value in record.items()], text_columns=(0,))
    elif record is not None and not isinstance(record, dict):
        body = f"<p>{_e(_record_value(record))}</p>"
    else:
        body = "<p>No record of this stage in this result.</p>"
    return f"<h2>{_e(label)}</h2>\n{body}"


def _stage_sections(result, figures, limit: int | None = None) -> list[str]:
    """A section per stage the result declares, from the one that gave the estimate back to the first
    (the first ``limit`` of them): a known stage's by :data:`STAGE_SECTIONS`, any other's by
    :func:`_stage_section`."""
    names = list(reversed(_stages(result)))[:limit]
    return [STAGE_SECTIONS.get(name, _stage_section)(result, name, figures) for name in names]


def _notes_section(result, data_notes) -> str:
    data_notes = [str(n) for n in data_notes]
    other = [str(n) for n in (result.notes or []) if str(n) not in set(data_notes)]
    parts = ["<h2>Notes</h2>"]
    if data_notes:
        parts.append("<h3>Data rules</h3>\n<ul class=\"notes\">" + "".join(f"<li>{_e(n)}</li>" for n in data_notes)
                     + "</ul>")
    if other:
        parts.append("<h3>Data and methods</h3>\n<ul class=\"notes\">" + "".join(f"<li>{_e(n)}</li>" for n in other)
                     + "</ul>")
    if len(parts) == 1:
        parts.append("<p>No notes.</p>")
    return "\n".join(parts)


# ------------------------------------------------------------------------------------ report


def write_report(path, result, *, control=None, title: str = "fracid identification", data_notes=(),
                 extra_sections=(), control_label=None, provenance=None) -> Path:
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
        How the result was obtained (:func:`fracid.provenance.collect`); the result's ``provenance``
        when omitted. Shown last, collapsed: "How this was run".

    Returns
    -------
    Path
        The file written.
    """
    from fracid.report import figures  # matplotlib is imported only when a report is written

    date = generated_now()
    names = ", ".join(str(n) for n in result.names)
    body = [
        f"<h1>{_e(title)}</h1>",
        (f'<p class="meta">Generated {_e(date)} by fracid. Identified parameters: {_e(names)}; '
         f"{np.size(result.y_exp)} measured values.</p>"),
        _parameter_section(result, control),
        _correlation_section(result, figures),
        _fit_section(result, control, figures, control_label),
        *_stage_sections(result, figures),
        _runs_section(result),
        _notes_section(result, data_notes),
    ]
    for heading, fragment in extra_sections:
        body.append(f"<h2>{_e(heading)}</h2>\n{fragment}")
    body.append(provenance_section(getattr(result, "provenance", None) if provenance is None else provenance))
    return write_document(path, title, body)


def provenance_section(provenance) -> str:
    """A collapsed ``<details>`` "How this was run": version, command, date, machine, data files with
    their SHA-256, specimen and mesh, parameters, bounds and the configuration (as JSON); empty
    without a provenance."""
    import json

    if not provenance:
        return ""
    p = dict(provenance)
    files = _table(["data file", "bytes", "SHA-256"], [[f.get("path", ""), f.get("bytes", ""),
                                                      f.get("sha256", f.get("error", ""))]
                                                     for f in p.get("data_files") or []], text_columns=(0, 2))
    rows = [["fracid", p.get("fracid", "")], ["command", p.get("command", "")], ["date (UTC)", p.get("date", "")]]
    rows += [[key.replace("_", " "), value] for key, value in (p.get("machine") or {}).items()]
    parts = [_table(["", ""], rows, text_columns=(0, 1)), files if p.get("data_files") else ""]
    for key, heading in (("specimen", "Specimen and mesh"), ("parameters", "Model parameters (the fixed ones at "
                         "their values)"), ("bounds", "Bounds of the identified parameters"), ("config",
                         "Configuration (as read, defaults filled)")):
        if p.get(key) is not None:
            parts.append(f"<h3>{_e(heading)}</h3>\n<pre>{_e(json.dumps(p[key], indent=1))}</pre>")
    return ('<details class="provenance">\n<summary>How this was run</summary>\n' + "\n".join(x for x in parts if x)
            + "\n</details>")


def generated_now() -> str:
    """The local date and time for a report's "Generated ..." line."""
    return datetime.datetime.now().astimezone().strftime("%Y-%m-%d %H:%M %Z")


def write_document(path, title: str, body) -> Path:
    """Write a self-contained HTML page: the report's style and image check around ``body``.

    Parameters
    ----------
    path : str or Path
        The HTML file to write (parent directories are created).
    title : str
        Page title (escaped here).
    body : sequence of str
        HTML fragments, in order (not escaped).

    Returns
    -------
    Path
        The file written.
    """
    path = Path(path)
    document = "\n".join([
        "<!DOCTYPE html>",
        '<html lang="en">',
        "<head>",
        '<meta charset="utf-8">',
        '<meta name="viewport" content="width=device-width, initial-scale=1">',
        f"<title>{_e(title)}</title>",
        f"<style>{_CSS}</style>",
        "</head>",
        "<body>",
        *body,
        f"<script>{_SCRIPT}</script>",
        "</body>",
        "</html>",
        "",
    ])
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(document, encoding="utf-8")
    return path
