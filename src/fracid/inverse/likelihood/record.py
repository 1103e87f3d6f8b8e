"""What a result keeps of its error terms (``MethodResult.error_terms``, JSON), and the covariances rebuilt from it.

:func:`terms_record` writes, per data block, the measurement std beside the discretisation std and the
model-error std (RMS over the block's values, in the block's unit), the total std and the RMS misfit; the
settings; the discretisation error per value; sigma_m per group; the fixed-point loops; the estimate without the
terms. :func:`widened` builds the covariance of the terms, and :func:`error_likelihood` rebuilds from a record
what the posterior needs (the widened base covariance and the marginal likelihood of sigma_m).
"""

from __future__ import annotations

import dataclasses

import numpy as np

from fracid.data.covariance_update import low_rank_update
from fracid.inverse.core.fit_status import with_measurement
from fracid.inverse.likelihood.correlation import block_modes
from fracid.inverse.likelihood.marginal import MarginalLikelihood
from fracid.inverse.likelihood.model_error import error_groups, with_model_error
from fracid.inverse.likelihood.settings import FIXED_POINT_TOL, ModelError

#: an error term whose std exceeds this multiple of the measurement std "dominates" the stated uncertainty
DOMINANT = 1.0


def widened(C_exp, blocks, control, *, error=None, length=None, sigma=None, groups=None):
    """(base, total): C_exp plus the discretisation term (modes of ``error`` [units of y] correlated over
    ``length`` of each block's control range), then plus the model error ``sigma`` per group. Both carry C_exp
    (:func:`~fracid.inverse.core.fit_status.measurement_part`): restarts are decided on the measurement's misfit."""
    base = C_exp if error is None else low_rank_update(C_exp, block_modes(error, control, blocks, length))
    total = base if sigma is None else with_model_error(base, sigma, groups)
    return with_measurement(base, C_exp), with_measurement(total, C_exp)  # a poor fit is judged on C_exp alone


def _rms(values) -> float:
    values = np.asarray(values, float)
    return float(np.sqrt(np.mean(values**2))) if values.size else float("nan")


def _block_rows(problem, result, disc, sigma, groups, total) -> list[dict]:
    std, total_std = problem.C_exp.std(), total.std()
    misfit = np.asarray(result.y_fit, float) - problem.y_exp
    rows = []
    for k, (name, start, stop) in enumerate(problem.blocks):
        part = slice(start, stop)
        group = None if groups is None else next(g for g, names in enumerate(groups.blocks) if name in names)
        rows.append({"block": name, "points": stop - start, "peak": float(np.max(np.abs(problem.y_exp[part]))),
                     "measurement_std": _rms(std[part]),
                     "discretisation_std": None if disc is None else _rms(disc.error[part]),
                     "model_error_std": None if group is None else float(sigma[group]),
                     "total_std": _rms(total_std[part]), "rms_misfit": _rms(misfit[part]),
                     "order": None if disc is None else disc.orders[k],
                     "observed_order": None if disc is None else disc.observed[k]})
    return rows


def terms_record(problem, terms, first, result, loops, disc, computed) -> dict:
    """The ``error_terms`` of a result (module docstring): ``blocks`` (rows per block), ``discretisation``,
    ``model_error``, ``loops``, ``fixed_point``, ``measurement_only``, ``runs`` and ``notes``."""
    groups = None if terms.model_error is None else error_groups(
        terms.model_error, problem.blocks, problem.quantities, problem.y_exp, problem.control)
    sigma = None if groups is None else np.asarray(loops[-1]["sigma"], float)
    length = None if disc is None else terms.discretisation.correlation_length
    _, total = widened(problem.C_exp, problem.blocks, problem.control, error=None if disc is None else disc.error,
                       length=length, sigma=sigma, groups=groups)
    record = {
        "blocks": _block_rows(problem, result, disc, sigma, groups, total),
        "block_ranges": [list(b) for b in problem.blocks],
        "discretisation": None if disc is None else {
            **dataclasses.asdict(terms.discretisation), "ratio": disc.ratio, "meshes": disc.meshes,
            "orders": disc.orders, "observed": disc.observed, "error": disc.error.tolist()},
        "model_error": None if groups is None else {
            **dataclasses.asdict(terms.model_error), "sigma": [
                {"group": name, "blocks": blocks, "sigma": float(s), "scale": float(scale)}
                for name, blocks, s, scale in zip(groups.names, groups.blocks, sigma, groups.scales)]},
        "loops": loops, "loops_allowed": terms.loops, "fixed_point": loops[-1]["moved_std"] <= FIXED_POINT_TOL,
        "measurement_only": {"x": np.asarray(first.x).tolist(), "std": np.asarray(first.std).tolist(),
                             "status": first.status},
        "runs": {"identifications": len(loops), "computed": int(computed)},
    }
    record["notes"] = terms_lines(record)
    return record


def terms_lines(record: dict) -> list[str]:
    """The error terms in words: one line per term and per block, the fixed point (the summary's and the notes')."""
    lines = []
    disc, model = record.get("discretisation"), record.get("model_error")
    if disc:
        orders = ", ".join(f"{o:.3g}" + ("" if seen is not None else " (nominal)")
                           for o, seen in zip(disc["orders"], disc["observed"]))
        lines.append(f"discretisation error: Richardson from {' and '.join(disc['meshes'])} (h / {disc['ratio']:.3g}), "
                     f"order {orders}, correlated along each curve over {disc['correlation_length']:g} of its range")
    if model:
        prior = (f"half-Cauchy prior of scale {model['scale']:g} x the peak" if model["prior"] == "half-cauchy"
                 else "log-uniform prior")
        lines.append(f"model error ({model['kind']}, one std per {model['groups']}, {prior}, between "
                     f"{model['bounds'][0]:g} and {model['bounds'][1]:g} x the peak) identified with the parameters")
    for row in record.get("blocks", []):
        parts = [f"measurement std {_percent(row['measurement_std'], row)}"]
        if row["discretisation_std"] is not None:
            parts.append(f"discretisation std {_percent(row['discretisation_std'], row)}")
        if row["model_error_std"] is not None:
            parts.append(f"model-error std {_percent(row['model_error_std'], row)}")
        parts.append(f"total {_percent(row['total_std'], row)}; RMS misfit {_percent(row['rms_misfit'], row)}")
        lines.append(f"block {row['block']}: " + ", ".join(parts))
    loops = record.get("loops", [])
    if loops and record.get("loops_allowed", 1) > 1:
        state = "reached" if record.get("fixed_point") else "not reached"
        lines.append(f"{len(loops)} identification(s) with the terms; the fixed point {state} (the last moved the "
                     f"estimate by {loops[-1]['moved_std']:.2g} std)")
    elif loops:
        lines.append(f"the terms computed once, at the estimate without them; with them the estimate moved by "
                     f"{loops[-1]['moved_std']:.2g} std")
    return lines + dominant_terms(record)


def _percent(value, row) -> str:
    return f"{value:.3g} ({100 * value / row['peak']:.2g} % of the peak)" if row["peak"] > 0 else f"{value:.3g}"


def dominant_terms(record: dict) -> list[str]:
    """Statements of the blocks where an error term's std exceeds :data:`DOMINANT` times the measurement std."""
    out = []
    for row in (record or {}).get("blocks", []):
        for key, what in (("model_error_std", "the model's own error"), ("discretisation_std", "the mesh's error")):
            value = row.get(key)
            if value is not None and value > DOMINANT * row["measurement_std"]:
                out.append(f"{what} dominates the uncertainty of block {row['block']}: its std {value:.3g} is "
                           f"{value / row['measurement_std']:.2g} times the measurement std")
    return out


def error_likelihood(record: dict, C_exp, y_exp, control, quantities=()):
    """What a posterior needs of a result's error terms: (the base covariance, C_exp with the discretisation
    term; the :class:`~fracid.inverse.likelihood.marginal.MarginalLikelihood` of sigma_m, or None)."""
    blocks = [tuple(b) for b in record["block_ranges"]]
    disc, model = record.get("discretisation"), record.get("model_error")
    base, _ = widened(C_exp, blocks, np.asarray(control, float),
                      error=None if not disc else np.asarray(disc["error"], float),
                      length=None if not disc else disc["correlation_length"])
    if not model:
        return base, None
    names = {f.name for f in dataclasses.fields(ModelError)}
    settings = ModelError(**{k: (tuple(v) if k == "bounds" else v) for k, v in model.items() if k in names})
    groups = error_groups(settings, blocks, list(quantities), y_exp, control)
    return base, MarginalLikelihood(base, groups, settings, centre=[g["sigma"] for g in model["sigma"]])


__all__ = ["DOMINANT", "dominant_terms", "error_likelihood", "terms_lines", "terms_record",
           "widened"]
