"""The report's sections of an inverse method's stages, by stage name (:data:`STAGE_SECTIONS`), and its run
statistics: a refinement's history (Kalman filter steps, Gauss-Newton linearisations), a search's
population; a stage without a section of its own gets its label and its records.

A new method's stage gets a section by one entry in :data:`STAGE_SECTIONS`
(``section(result, stage name, figures module)`` returning an HTML fragment); without one it is still
reported (:func:`record_section`).
"""

from __future__ import annotations

import math

import numpy as np

from fracid.report.markup import duration, esc, html_image, num, html_table


RUN_LABELS = {
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


def history_section(result, name, figures) -> str:
    """The estimate along the history of the refinement stage ``name`` (Kalman filter steps, Gauss-Newton
    linearisations: ``result.history``)."""
    from fracid.report.stage_figures import history_figure

    label = declared_stages(result).get(name, name)
    fig = history_figure(result, label)
    if fig is None:
        return f"<h2>{esc(label)}</h2>\n<p>No history of this stage in this result.</p>"
    shown = html_image(figures.to_png(fig, stem=name), f"{label} history",
                  f"Estimate after every step of the {label} with +/- 2 std from the step's covariance; "
                  "dotted lines separate global iterations, the dashed line is the final value.")
    return f"<h2>{esc(label)}</h2>\n{shown}"


def population_section(result, name, figures) -> str:
    """The population of the search stage ``name``: objective against each parameter, map, best points."""
    from fracid.report import stage_figures

    arrays = stage_figures.population_arrays(result)
    if arrays is None:
        return "<h2>KNN population</h2>\n<p>No KNN population in this result.</p>"
    points, f, failed, order, k = arrays
    parts = ["<h2>KNN population</h2>"]
    parts.append(html_image(figures.to_png(stage_figures.population_objective_figure(result), stem=f"{name}_objective"),
                            "KNN objective",
                        "Objective of every population point against each parameter (log scale); circles: the "
                        f"{k} nearest; crosses at the top: failed runs; vertical line: the final estimate."))
    fig = stage_figures.population_map_figure(result)
    if fig is not None:
        i, j = stage_figures.strongest_pair(result)
        parts.append(html_image(figures.to_png(fig, stem=f"{name}_map"), "KNN map",
                            f"Population over {result.names[i]} and {result.names[j]} (the most correlated pair), "
                            "coloured by log10 f, with the estimate and its 2-std ellipse."))
    errors = list((result.knn or {}).get("errors") or [""] * len(points))
    rows, classes = [], []
    for rank, idx in enumerate(order[:10], start=1):
        status = "ok" if not failed[idx] else f"failed: {errors[idx] if idx < len(errors) else ''}"[:120]
        rows.append([rank, num(f[idx], 5)] + [num(v, 5) for v in points[idx]] + [status])
        classes.append("failed" if failed[idx] else "")
    header = ["rank", "f"] + [figures.parameter_label(n) for n in result.names] + ["status"]
    parts.append(f"<h3>The {min(10, len(order))} best population points</h3>")
    parts.append(html_table(header, rows, text_columns=(len(header) - 1,), row_classes=classes))
    knn = result.knn or {}
    if knn.get("x0") is not None:
        x0 = np.asarray(knn["x0"], float)
        prior = ", ".join(f"{n} = {num(v, 5)}" for n, v in zip(result.names, x0))
        parts.append(f"<p>Prior of the Kalman filter (mean of the {k} nearest): {esc(prior)}.</p>")
    return "\n".join(parts)


#: report sections of the stages known by name: ``section(result, stage name, figures module)``
STAGE_SECTIONS = {"knn": population_section, "kalman": history_section, "gauss_newton": history_section}


def runs_section(result) -> str:
    runs = dict(result.runs or {})
    history = getattr(result, "history", None)
    if "kalman" in declared_stages(result) and "kalman_iterations" not in runs and history:
        runs["kalman_iterations"] = len({h.get("iteration", 1) for h in history})
    rows = []
    for key in list(RUN_LABELS) + [k for k in runs if k not in RUN_LABELS]:
        if key not in runs:
            continue
        value = runs[key]
        shown = duration(value) if key == "wall_seconds" else num(value, 6)
        rows.append([run_label(result, key), shown])
    rows.append([f"{status_label(result)} converged", "yes" if result.converged else "no"])
    return "<h2>Run statistics</h2>\n" + html_table(["", ""], rows, text_columns=(0,))


def declared_stages(result) -> dict:
    """The stages the result declares (name -> label), in the order they ran."""
    return dict(getattr(result, "stages", None) or {})


def status_label(result) -> str:
    """The stage that gave the estimate, as the status line names it."""
    return getattr(result, "status_label", None) or "identification"


def run_label(result, key: str) -> str:
    """Row label of a run counter: known ones from :data:`RUN_LABELS`, a stage's from its label."""
    if key in RUN_LABELS:
        return RUN_LABELS[key]
    for stage, label in declared_stages(result).items():
        if key == stage:
            return f"{label} forward runs"
        if key.startswith(f"{stage}_"):
            return f"{label} {key[len(stage) + 1:].replace('_', ' ')}"
    return key


def record_value(value) -> str:
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


def record_section(result, name: str, figures) -> str:
    """A stage the report has no section of its own for: its label and what it recorded
    (``result.records[name]``; its forward runs are under the run statistics)."""
    label = declared_stages(result).get(name, name)
    record = (getattr(result, "records", None) or {}).get(name)
    if isinstance(record, dict) and record:
        body = html_table(["", ""], [[str(key), record_value(value)] for key, value in record.items()], text_columns=(0,))
    elif record is not None and not isinstance(record, dict):
        body = f"<p>{esc(record_value(record))}</p>"
    else:
        body = "<p>No record of this stage in this result.</p>"
    return f"<h2>{esc(label)}</h2>\n{body}"


def stage_sections(result, figures, limit: int | None = None) -> list[str]:
    """A section per stage the result declares, from the one that gave the estimate back to the first
    (the first ``limit`` of them): a known stage's by :data:`STAGE_SECTIONS`, any other's by
    :func:`record_section`."""
    names = list(reversed(declared_stages(result)))[:limit]
    return [STAGE_SECTIONS.get(name, record_section)(result, name, figures) for name in names]


__all__ = ["RUN_LABELS", "STAGE_SECTIONS", "declared_stages", "history_section", "population_section", "record_section",
           "runs_section", "stage_sections", "status_label"]
