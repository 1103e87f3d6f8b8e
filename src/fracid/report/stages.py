"""The report's sections of an inverse method's stages, one view per kind of record a stage leaves
(:data:`RECORD_VIEWS`: a population, a path of estimates, a generic record;
:mod:`fracid.inverse.core.stage_records`), and its run statistics.

The stages, their labels and the kinds of their records are the result's (``result.stages``,
``result.stage_records``): this module knows no method and no stage by name, so a new method's stages get
their sections without an edit here.
"""

from __future__ import annotations

import math

import numpy as np

from fracid.inverse.core.stage_records import GENERIC, PATH, POPULATION
from fracid.report.markup import duration, esc, html_image, num, html_table

#: row labels of a stage's counters ``runs["<stage>_<counter>"]``, after the stage's label
COUNTER_LABELS = {"failed": "failed runs", "computed": "runs computed (the others loaded from the store)",
                  "run_equivalents": "run equivalents (full curves)"}


def history_section(result, name, figures) -> str:
    """The path of estimates of the stage ``name`` (``result.record(name)``): the estimate after every step."""
    from fracid.report.stage_figures import history_figure  # matplotlib only when a report is drawn

    label = declared_stages(result).get(name, name)
    fig = history_figure(result, name)
    if fig is None:
        return f"<h2>{esc(label)}</h2>\n<p>No history of this stage in this result.</p>"
    shown = html_image(figures.to_png(fig, stem=name), f"{label} history",
                       f"Estimate after every step of the {label} with +/- 2 std from the step's covariance; "
                       "dotted lines separate global iterations, the dashed line is the final value.")
    return f"<h2>{esc(label)}</h2>\n{shown}"


def population_section(result, name, figures) -> str:
    """The population of the stage ``name`` (``result.record(name)``): objective against each parameter, map,
    best points and the prior it gave the next stage."""
    from fracid.report.stage_figures import (population_arrays, population_map_figure, population_objective_figure,
                                             strongest_pair)  # matplotlib only when a report is drawn

    label = declared_stages(result).get(name, name)
    arrays = population_arrays(result, name)
    if arrays is None:
        return f"<h2>{esc(label)} population</h2>\n<p>No {esc(label)} population in this result.</p>"
    points, f, failed, order, k = arrays
    parts = [f"<h2>{esc(label)} population</h2>"]
    mesh = (result.record(name) or {}).get("screening")
    if mesh:  # a population on a screening mesh ranks the start only: its objective is not the estimate's mesh's
        parts.append(f"<p>The population ran {esc(mesh)}.</p>")
    parts.append(html_image(figures.to_png(population_objective_figure(result, name), stem=f"{name}_objective"),
                            f"{label} objective",
                            "Objective of every population point against each parameter (log scale); circles: the "
                            f"{k} nearest; crosses at the top: failed runs; vertical line: the final estimate."))
    fig = population_map_figure(result, name)
    if fig is not None:
        i, j = strongest_pair(result)
        parts.append(html_image(figures.to_png(fig, stem=f"{name}_map"), f"{label} map",
                                f"Population over {result.names[i]} and {result.names[j]} (the most correlated pair), "
                                "coloured by log10 f, with the estimate and its 2-std ellipse."))
    record = result.record(name) or {}
    parts.append(f"<h3>The {min(10, len(order))} best population points</h3>")
    parts.append(_best_points(result, figures, arrays, list(record.get("errors") or [""] * len(points))))
    if record.get("x0") is not None:
        prior = ", ".join(f"{n} = {num(v, 5)}" for n, v in zip(result.names, np.asarray(record["x0"], float)))
        after = result.stage_after(name)
        target = f"the {declared_stages(result)[after]}" if after else "the next stage"
        parts.append(f"<p>Prior of {esc(target)} (mean of the {k} nearest): {esc(prior)}.</p>")
    return "\n".join(parts)


def _best_points(result, figures, arrays, errors) -> str:
    """The table of the 10 best points of a population (rank, objective, parameters, status)."""
    points, f, failed, order, _ = arrays
    rows, classes = [], []
    for rank, idx in enumerate(order[:10], start=1):
        status = "ok" if not failed[idx] else f"failed: {errors[idx] if idx < len(errors) else ''}"[:120]
        rows.append([rank, num(f[idx], 5)] + [num(v, 5) for v in points[idx]] + [status])
        classes.append("failed" if failed[idx] else "")
    header = ["rank", "f"] + [figures.parameter_label(n) for n in result.names] + ["status"]
    return html_table(header, rows, text_columns=(len(header) - 1,), row_classes=classes)


def runs_section(result) -> str:
    """The forward runs of every stage and their counters (``result.runs``), the wall time and whether the
    stage that gave the estimate converged."""
    runs = dict(result.runs or {})
    for stage in result.stages_of_kind(PATH):  # an older result without the count: the passes of its path
        if f"{stage}_iterations" not in runs and result.record(stage):
            runs[f"{stage}_iterations"] = len({h.get("iteration", 1) for h in result.record(stage)})
    rows = [[run_label(result, key), duration(runs[key]) if key == "wall_seconds" else num(runs[key], 6)]
            for key in _run_keys(result, runs)]
    rows.append([f"{status_label(result)} converged", "yes" if result.converged else "no"])
    return "<h2>Run statistics</h2>\n" + html_table(["", ""], rows, text_columns=(0,))


def _run_keys(result, runs) -> list[str]:
    """The counters in the order of the stages (the stage's runs, failed, computed, the others), then the
    wall time, then any other."""
    keys = []
    for stage in declared_stages(result):
        own = [key for key in runs if key.startswith(f"{stage}_")]
        keys += [key for key in (stage, f"{stage}_failed", f"{stage}_computed") if key in runs]
        keys += [key for key in own if key not in keys]
    keys += [key for key in ("wall_seconds",) if key in runs]
    return keys + [key for key in runs if key not in keys]


def declared_stages(result) -> dict:
    """The stages the result declares (name -> label), in the order they ran."""
    return dict(getattr(result, "stages", None) or {})


def status_label(result) -> str:
    """The stage that gave the estimate, as the status line names it."""
    return getattr(result, "status_label", None) or "identification"


def run_label(result, key: str) -> str:
    """Row label of a run counter: a stage's from its label (and :data:`COUNTER_LABELS`), the wall time's."""
    if key == "wall_seconds":
        return "wall time"
    for stage, label in declared_stages(result).items():
        if key == stage:
            return f"{label} forward runs" + (" (population)" if result.record_kind(stage) == POPULATION else "")
        if key.startswith(f"{stage}_"):
            counter = key[len(stage) + 1:]
            return f"{label} {COUNTER_LABELS.get(counter, counter.replace('_', ' '))}"
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
    record = result.record(name)
    if isinstance(record, dict) and record:
        body = html_table(["", ""], [[str(key), record_value(value)] for key, value in record.items()], text_columns=(0,))
    elif record is not None and not isinstance(record, dict):
        body = f"<p>{esc(record_value(record))}</p>"
    else:
        body = "<p>No record of this stage in this result.</p>"
    return f"<h2>{esc(label)}</h2>\n{body}"


#: the report's view of a stage by the kind of record it left: ``section(result, stage name, figures module)``
RECORD_VIEWS = {POPULATION: population_section, PATH: history_section, GENERIC: record_section}


def stage_sections(result, figures, limit: int | None = None) -> list[str]:
    """A section per stage the result declares, from the one that gave the estimate back to the first
    (the first ``limit`` of them), each by the view of its kind of record (:data:`RECORD_VIEWS`)."""
    names = list(reversed(declared_stages(result)))[:limit]
    return [RECORD_VIEWS.get(result.record_kind(name), record_section)(result, name, figures) for name in names]


__all__ = ["COUNTER_LABELS", "RECORD_VIEWS", "declared_stages", "history_section", "population_section", "record_section",
           "runs_section", "stage_sections", "status_label"]
