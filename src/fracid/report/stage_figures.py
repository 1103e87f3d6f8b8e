"""Figures of the stages of an inverse method, one set per kind of record a stage leaves
(:mod:`fracid.inverse.core.stage_records`): the estimate along a path of estimates, and a population
(objective against each parameter, map over the most correlated pair).

Each function returns a :class:`matplotlib.figure.Figure`, or ``None`` when the result holds nothing to
draw; :func:`fracid.report.figures.to_png` renders it. A stage is named by the result (``result.stages``); the
figures know no method and no stage by name.
"""

from __future__ import annotations

import math

import numpy as np
from matplotlib.colors import Normalize
from matplotlib.figure import Figure

from fracid.inverse.core.stage_records import PATH, POPULATION
from fracid.report.figures import (ESTIMATE, FAILED, MEASURED, NEIGHBOUR, covariance_ellipse, float_array, new_figure,
                                   parameter_axis,
                                   parameter_label)


def stage_of_kind(result, kind: str, stage: str | None = None) -> str | None:
    """``stage``, or the first stage of the result that left a record of the kind ``kind`` (None without one)."""
    if stage is not None:
        return stage
    return next(iter(result.stages_of_kind(kind)), None)


def stage_label(result, stage: str | None) -> str:
    """The label the result gives the stage ``stage`` (its name without one)."""
    return dict(getattr(result, "stages", None) or {}).get(stage, stage or "")


def population_arrays(result, stage: str | None = None):
    """Population ``points`` (N, p), objective ``f`` (inf where failed), boolean ``failed``,
    ranking ``order`` and ``k`` of the population record of ``stage`` (None: the first stage that left
    one); ``None`` without a population."""
    stage = stage_of_kind(result, POPULATION, stage)
    record = (result.record(stage) if stage is not None else None) or {}
    points = record.get("points")
    if points is None or np.size(points) == 0:
        return None
    p = len(result.names)
    points = float_array(points, np.nan).reshape(-1, p)
    f = float_array(record.get("f"), np.inf)
    if f.size != len(points):
        f = np.full(len(points), np.inf)
    status = list(record.get("status") or ["ok"] * len(points))
    failed = np.array([s != "ok" for s in status]) | ~np.isfinite(f)
    order = record.get("order")
    order = np.argsort(np.where(failed, np.inf, f), kind="stable") if order is None else np.asarray(order, int)
    k = int(record.get("k") or 0)
    return points, f, failed, order, k


def population_mesh(result, stage: str | None) -> str:
    """``" on a screening mesh 2 times coarser"`` for a population that ran on a screening mesh (its record's
    ``screening``, :mod:`fracid.inverse.methods.knn_screening`), else "": the figures' titles say which mesh ranked it."""
    mesh = str(((result.record(stage) if stage is not None else None) or {}).get("screening") or "")
    if "screening mesh" not in mesh:
        return ""
    return " " + mesh.split(" (")[0]


def _objective_for_log(f: np.ndarray, failed: np.ndarray):
    """Objective values safe for a log axis (zeros raised to a floor) and the height of failed runs."""
    good = f[~failed & np.isfinite(f)]
    positive = good[good > 0]
    floor = positive.min() / 10.0 if positive.size else 1e-12
    shown = np.where(failed | ~np.isfinite(f), np.nan, np.maximum(f, floor))
    top = (np.nanmax(shown) if good.size else 1.0) * 5.0
    return shown, top, floor


def strongest_pair(result) -> tuple[int, int] | None:
    """Indices (i, j), i < j, of the two parameters with the largest ``|correlation|``; None for p < 2."""
    p = len(result.names)
    if p < 2:
        return None
    corr = np.asarray(result.correlation, float)
    best, pair = -1.0, (0, 1)
    for i in range(p):
        for j in range(i + 1, p):
            value = abs(corr[i, j]) if np.isfinite(corr[i, j]) else -0.5
            if value > best:
                best, pair = value, (i, j)
    return pair


# ------------------------------------------------------------------------------------ figures


def history_figure(result, stage: str | None = None) -> Figure | None:
    """Estimate of every parameter after every step of the path of estimates of ``stage`` (None: the first
    stage that left one) with its +/- 2 std band.

    x axis: cumulative step index over the global iterations (0 = the prior of the search when known);
    dotted vertical lines separate the global iterations; the horizontal line is the final value.
    """
    stage = stage_of_kind(result, PATH, stage)
    history = list((result.record(stage) if stage is not None else None) or [])
    label = stage_label(result, stage)
    if not history:
        return None
    names = list(result.names)
    p = len(names)
    xs = np.array([float_array(h["x"], np.nan).reshape(p) for h in history])
    stds = np.array([np.sqrt(np.maximum(np.diag(float_array(h["C"], np.nan).reshape(p, p)), 0.0)) for h in history])
    index = np.arange(1, len(history) + 1)
    prior = result.search_prior()
    if prior is not None:
        x0 = float_array(prior[1], np.nan).reshape(p)
        s0 = np.sqrt(np.maximum(np.diag(float_array(prior[2], np.nan).reshape(p, p)), 0.0))
        xs, stds, index = np.vstack([x0, xs]), np.vstack([s0, stds]), np.concatenate([[0], index])
    iterations = [h.get("iteration", 1) for h in history]
    boundaries = [i + 0.5 for i in range(1, len(history)) if iterations[i] != iterations[i - 1]]
    final = float_array(result.x, np.nan).reshape(p)
    fig = new_figure(7.5, 2.3 * p + 0.6)
    axes = fig.subplots(p, 1, sharex=True, squeeze=False).ravel()
    for j, ax in enumerate(axes):
        ax.fill_between(index, xs[:, j] - 2 * stds[:, j], xs[:, j] + 2 * stds[:, j], color=MEASURED, alpha=0.2,
                        lw=0, label="+/- 2 std")
        ax.plot(index, xs[:, j], "-o", color=MEASURED, ms=2.5, lw=1.0, label="estimate")
        ax.axhline(final[j], color=ESTIMATE, lw=1.0, ls="--", label=f"final {final[j]:.4g}")
        for b in boundaries:
            ax.axvline(b, color="k", lw=0.8, ls=":")
        ax.set_ylabel(parameter_label(names[j]))
        ax.ticklabel_format(axis="y", style="sci", scilimits=(-3, 4), useMathText=True)
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize="x-small", loc="best")
    n_iter = len(dict.fromkeys(iterations))
    axes[0].set_title(f"{label}: {len(history)} steps in {n_iter} global iteration(s)"
                      + (f" (step 0: {stage_label(result, prior[0])} prior)" if index[0] == 0 else ""))
    axes[-1].set_xlabel("cumulative step [-] (dotted: new global iteration)")
    return fig


def population_objective_figure(result, stage: str | None = None) -> Figure | None:
    """Objective f (log scale) of every point of the population of ``stage`` (None: the first stage that left
    one) against each parameter.

    Failed runs are drawn as grey crosses above the largest objective; the k nearest neighbours are
    highlighted and the final estimate is a vertical line.
    """
    stage = stage_of_kind(result, POPULATION, stage)
    arrays = population_arrays(result, stage)
    if arrays is None:
        return None
    points, f, failed, order, k = arrays
    names = list(result.names)
    p = len(names)
    shown, top, _ = _objective_for_log(f, failed)
    nearest = np.zeros(len(points), bool)
    nearest[order[:k]] = True
    final = float_array(result.x, np.nan).reshape(p)
    ncols = min(p, 3)
    nrows = math.ceil(p / ncols)
    fig = new_figure(4.3 * ncols, 3.6 * nrows)
    axes = fig.subplots(nrows, ncols, squeeze=False, sharey=True).ravel()
    for j, ax in enumerate(axes[:p]):
        ok = ~failed
        ax.plot(points[ok & ~nearest, j], shown[ok & ~nearest], "o", color=MEASURED, ms=4, alpha=0.7,
                label="population")
        ax.plot(points[nearest, j], shown[nearest], "o", mfc="none", mec=NEIGHBOUR, mew=1.8, ms=8,
                label=f"{k} nearest")
        if failed.any():
            ax.plot(points[failed, j], np.full(failed.sum(), top), "x", color=FAILED, ms=7, mew=1.5,
                    label=f"failed ({failed.sum()})")
        ax.axvline(final[j], color=ESTIMATE, lw=1.2, label=f"estimate {final[j]:.4g}")
        ax.set_yscale("log")
        parameter_axis(ax, "x", points[:, j])
        ax.set_xlabel(parameter_label(names[j]))
        ax.grid(True, which="both", alpha=0.25)
    axes[0].set_ylabel("objective f [-]")
    axes[0].legend(fontsize="x-small", loc="best")
    for ax in axes[p:]:
        ax.set_visible(False)
    mesh = population_mesh(result, stage)
    fig.suptitle(f"{stage_label(result, stage)} population: {len(points)} runs{mesh}, objective f = (y_exp - y)^T "
                 "C_exp^-1 (y_exp - y)", fontsize="medium")
    return fig


def population_map_figure(result, stage: str | None = None) -> Figure | None:
    """The population of ``stage`` (None: the first stage that left one) over the two most correlated
    parameters, coloured by log10 f, with the k nearest and the estimate with its 2-std ellipse (and the
    search's prior's, dashed). None for one parameter."""
    stage = stage_of_kind(result, POPULATION, stage)
    pair = strongest_pair(result)
    arrays = population_arrays(result, stage)
    if pair is None or arrays is None:
        return None
    i, j = pair
    points, f, failed, order, k = arrays
    names = list(result.names)
    shown, _, _ = _objective_for_log(f, failed)
    ok = ~failed
    fig = new_figure(6.4, 5.0)
    ax = fig.subplots()
    colour = np.log10(shown[ok])
    norm = Normalize(vmin=np.nanmin(colour), vmax=np.nanmax(colour)) if colour.size else None
    scatter = ax.scatter(points[ok, i], points[ok, j], c=colour, cmap="viridis_r", norm=norm, s=30,
                         edgecolors="none", label="population")
    fig.colorbar(scatter, ax=ax, label="log10 f [-]")
    near = order[:k]
    ax.plot(points[near, i], points[near, j], "o", mfc="none", mec=NEIGHBOUR, mew=1.8, ms=10, label=f"{k} nearest")
    if failed.any():
        ax.plot(points[failed, i], points[failed, j], "x", color=FAILED, ms=7, mew=1.5,
                label=f"failed ({failed.sum()})")
    x = float_array(result.x, np.nan)
    C = float_array(result.C, np.nan).reshape(len(names), len(names))
    sub = np.ix_([i, j], [i, j])
    prior = result.search_prior()
    if prior is not None:
        x0 = float_array(prior[1], np.nan)
        C0 = float_array(prior[2], np.nan).reshape(len(names), len(names))
        e0 = covariance_ellipse(x0[[i, j]], C0[sub])
        ax.plot(e0[:, 0], e0[:, 1], "--", color=NEIGHBOUR, lw=1.0, label=f"{stage_label(result, prior[0])} prior, 2 std")
    ellipse = covariance_ellipse(x[[i, j]], C[sub])
    ax.plot(ellipse[:, 0], ellipse[:, 1], "-", color=ESTIMATE, lw=1.4, label="estimate, 2 std")
    ax.plot([x[i]], [x[j]], "*", color=ESTIMATE, ms=14, mec="k", mew=0.6, label="estimate")
    parameter_axis(ax, "x", points[:, i])
    parameter_axis(ax, "y", points[:, j])
    corr = float(np.asarray(result.correlation, float)[i, j])
    ax.set_title(f"{names[i]} - {names[j]} (correlation {corr:+.3f}){population_mesh(result, stage)}")
    ax.set_xlabel(parameter_label(names[i]))
    ax.set_ylabel(parameter_label(names[j]))
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize="x-small", loc="best")
    return fig


def _population_figures(result, stage: str) -> dict:
    return {f"{stage}_objective": population_objective_figure(result, stage),
            f"{stage}_map": population_map_figure(result, stage)}


def _path_figures(result, stage: str) -> dict:
    return {stage: history_figure(result, stage)}


#: the figures of a stage by the kind of record it left: ``figures(result, stage) -> {file stem: Figure or None}``
RECORD_FIGURES = {POPULATION: _population_figures, PATH: _path_figures}


def stage_figures(result) -> dict:
    """The figures of every stage the result declares (``result.stages``) whose kind of record has figures
    (:data:`RECORD_FIGURES`), by file stem (``"<stage>"`` for a path, ``"<stage>_objective"`` and
    ``"<stage>_map"`` for a population); None where there is nothing to draw."""
    out = {}
    for stage in dict(getattr(result, "stages", None) or {}):
        figures = RECORD_FIGURES.get(result.record_kind(stage))
        if figures is not None:
            out.update(figures(result, stage))
    return out


__all__ = ["RECORD_FIGURES", "history_figure", "population_arrays", "population_map_figure", "population_mesh",
           "population_objective_figure", "stage_figures", "stage_label", "stage_of_kind", "strongest_pair"]
