"""The report's section on the error terms of the likelihood (``MethodResult.error_terms``): per data block the
measurement std beside the discretisation std and the model-error std, the estimates without and with them; and
the posterior's model-error std (``PosteriorResult.model_error``).

Units: those of each block (N for forces, mm for widths), also in % of the block's largest ``|measured value|``.
"""

from __future__ import annotations

import numpy as np

from fracid.report.markup import esc, html_table, num


def _with_percent(value, peak) -> str:
    if value is None:
        return "-"
    return f"{num(value, 3)} ({num(100.0 * value / peak, 2)} %)" if peak else num(value, 3)


def _order(row) -> str:
    if row.get("order") is None:
        return "-"
    return num(row["order"], 3) + (" (observed)" if row.get("observed_order") is not None else " (nominal)")


def block_table(record: dict) -> str:
    """Per block: the measurement, discretisation, model-error and total std, the RMS misfit and the order."""
    rows = [[row["block"], row["points"], *(_with_percent(row[key], row["peak"]) for key in
                                             ("measurement_std", "discretisation_std", "model_error_std",
                                              "total_std", "rms_misfit")), _order(row)]
            for row in record.get("blocks", [])]
    return html_table(["block", "points", "measurement std (% of peak)", "discretisation std", "model-error std",
                       "total std", "RMS misfit", "order of convergence"], rows, text_columns=(0, 7))


def estimate_table(result, record: dict) -> str:
    """Per parameter: the estimate and std without the terms (the measurement's alone) and with them."""
    before = record.get("measurement_only") or {}
    x0, s0 = np.asarray(before.get("x", []), float), np.asarray(before.get("std", []), float)
    rows = []
    for j, name in enumerate(result.names):
        if j >= x0.size:
            break
        s1 = float(np.asarray(result.std, float)[j])
        rows.append([name, num(x0[j], 5), num(s0[j], 3), num(result.x[j], 5), num(s1, 3),
                     num(s1 / s0[j], 3) if s0[j] > 0 else "n/a"])
    return html_table(["parameter", "estimate without the terms", "std without", "estimate with them", "std with",
                       "std ratio"], rows, text_columns=(0,))


def error_terms_section(result) -> str:
    """The section "Error terms" of an identification report ("" when the result has none)."""
    record = getattr(result, "error_terms", None) or {}
    if not record:
        return ""
    notes = "".join(f"<li>{esc(line)}</li>" for line in record.get("notes", []))
    return ("<h2>Error terms: discretisation and model error</h2>\n"
            "<p>The data covariance holds the measurement scatter; the error terms below are added to it and the "
            "identification is run again with them (the estimates and std of this report include them; the data's "
            "std in the fit section is the measurement's). RMS over each block's values, in the block's unit.</p>\n"
            f"{block_table(record)}\n{estimate_table(result, record)}\n<ul class=\"notes\">{notes}</ul>")


def posterior_model_error(post) -> str:
    """The posterior's model-error std per group ("" without): mean, median and 90 % credible interval."""
    groups = getattr(post, "model_error", None) or []
    if not groups:
        return ""
    rows = [[g["group"], num(g["mean"], 4), num(g["median"], 4),
             f"[{num(g['interval_90'][0], 4)}, {num(g['interval_90'][1], 4)}]"] for g in groups]
    return ("<h2>Model error</h2>\n<p>The std of the model's own error, integrated out per draw over its prior "
            "(a quadrature in log sigma: no forward run of its own); its posterior from the weighted draws.</p>\n"
            + html_table(["group of blocks", "posterior mean", "median", "90 % credible interval"], rows,
                         text_columns=(0,)))


__all__ = ["block_table", "error_terms_section", "estimate_table", "posterior_model_error"]
