"""Figures of the stages of an inverse method: the estimate along a refinement's history and the
population of a search (objective against each parameter, map over the most correlated pair).

Each function returns a :class:`matplotlib.figure.Figure`, or ``None`` when the result holds nothing to
draw; :func:`fracid.report.figures.to_png` renders it.
"""

from __future__ import annotations

import math

import numpy as np
from matplotlib.colors import Normalize
from matplotlib.figure import Figure

from fracid.report.figures import (ESTIMATE, FAILED, MEASURED, NEIGHBOUR, covariance_ellipse, float_array, new_figure,
                                   parameter_axis,
                                   parameter_label)


def population_arrays(result):
    """Population ``points`` (N, p), objective ``f`` (inf where failed), boolean ``failed``,
    ranking ``order`` and ``k`` of the result's KNN search; ``None`` without a population."""
    knn = getattr(result, "knn", None) or {}
    points = knn.get("points")
    if points is None or np.size(points) == 0:
        return None
    p = len(result.names)
    points = float_array(points, np.nan).reshape(-1, p)
    f = float_array(knn.get("f"), np.inf)
    if f.size != len(points):
        f = np.full(len(points), np.inf)
    status = list(knn.get("status") or ["ok"] * len(points))
    failed = np.array([s != "ok" for s in status]) | ~np.isfinite(f)
    order = knn.get("order")
    order = np.argsort(np.where(failed, np.inf, f), kind="stable") if order is None else np.asarray(order, int)
    k = int(knn.get("k") or 0)
    return points, f, failed, order, k


def _objective_for_log(f: np.ndarray, failed: np.ndarray):
    """Objective values safe for a log axis (zeros raised to a floor) and the height of failed runs."""
    good = f[~failed & np.isfinite(f)]
    positive = good[good > 0]
    floor = positive.min() / 10.0 if positive.size else 1e-12
    shown = np.where(failed | ~np.isfinite(f), np.nan, np.maximum(f, floor))
    top = (np.nanmax(shown) if good.size else 1.0) * 5.0
    return shown, top, floor


def strongest_pair(result) -> tuple[int, int] | None:
    """Indices (i, j), i < j, of the two parameters with the largest |correlation|; None for p < 2."""
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


def history_figure(result, label: str = "Kalman filter") -> Figure | None:
    """Estimate of every parameter after every step of the stage ``label`` (the Kalman filter's steps, the
    Gauss-Newton linearisations: ``result.history``) with its +/- 2 std band.

    x axis: cumulative step index over the global iterations (0 = the prior from KNN when known);
    dotted vertical lines separate the global iterations; the horizontal line is the final value.
    """
    history = list(getattr(result, "history", None) or [])
    if not history:
        return None
    names = list(result.names)
    p = len(names)
    xs = np.array([float_array(h["x"], np.nan).reshape(p) for h in history])
    stds = np.array([np.sqrt(np.maximum(np.diag(float_array(h["C"], np.nan).reshape(p, p)), 0.0)) for h in history])
    index = np.arange(1, len(history) + 1)
    knn = getattr(result, "knn", None) or {}
    if knn.get("x0") is not None and knn.get("C0") is not None:
        x0 = float_array(knn["x0"], np.nan).reshape(p)
        s0 = np.sqrt(np.maximum(np.diag(float_array(knn["C0"], np.nan).reshape(p, p)), 0.0))
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
                      + (" (step 0: KNN prior)" if index[0] == 0 else ""))
    axes[-1].set_xlabel("cumulative step [-] (dotted: new global iteration)")
    return fig


def population_objective_figure(result) -> Figure | None:
    """Objective f (log scale) of every population point against each parameter.

    Failed runs are drawn as grey crosses above the largest objective; the k nearest neighbours are
    highlighted and the final estimate is a vertical line.
    """
    arrays = population_arrays(result)
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
    fig.suptitle(f"KNN population: {len(points)} runs, objective f = (y_exp - y)^T C_exp^-1 (y_exp - y)",
                 fontsize="medium")
    return fig


def population_map_figure(result) -> Figure | None:
    """Population over the two most correlated parameters, coloured by log10 f, with the k nearest
    and the estimate with its 2-std ellipse (and the KNN prior's, dashed). None for one parameter."""
    pair = strongest_pair(result)
    arrays = population_arrays(result)
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
    knn = getattr(result, "knn", None) or {}
    if knn.get("x0") is not None and knn.get("C0") is not None:
        x0 = float_array(knn["x0"], np.nan)
        C0 = float_array(knn["C0"], np.nan).reshape(len(names), len(names))
        e0 = covariance_ellipse(x0[[i, j]], C0[sub])
        ax.plot(e0[:, 0], e0[:, 1], "--", color=NEIGHBOUR, lw=1.0, label="KNN prior, 2 std")
    ellipse = covariance_ellipse(x[[i, j]], C[sub])
    ax.plot(ellipse[:, 0], ellipse[:, 1], "-", color=ESTIMATE, lw=1.4, label="estimate, 2 std")
    ax.plot([x[i]], [x[j]], "*", color=ESTIMATE, ms=14, mec="k", mew=0.6, label="estimate")
    parameter_axis(ax, "x", points[:, i])
    parameter_axis(ax, "y", points[:, j])
    corr = float(np.asarray(result.correlation, float)[i, j])
    ax.set_title(f"{names[i]} - {names[j]} (correlation {corr:+.3f})")
    ax.set_xlabel(parameter_label(names[i]))
    ax.set_ylabel(parameter_label(names[j]))
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize="x-small", loc="best")
    return fig




def _population_figures(result, stage: str, label: str) -> dict:
    return {f"{stage}_objective": population_objective_figure(result), f"{stage}_map": population_map_figure(result)}


def _history_figures(result, stage: str, label: str) -> dict:
    return {stage: history_figure(result, label)}


#: figures of the stages known by name: ``figures(result, stage, label) -> {file stem: Figure or None}``
STAGE_FIGURES = {"knn": _population_figures, "kalman": _history_figures, "gauss_newton": _history_figures}


def stage_figures(result) -> dict:
    """The figures of every stage the result declares (``result.stages``) that :data:`STAGE_FIGURES`
    knows, by file stem (``"kalman"``, ``"knn_objective"``, ``"knn_map"``, ...); None where there is
    nothing to draw."""
    out = {}
    for stage, label in dict(getattr(result, "stages", None) or {}).items():
        if stage in STAGE_FIGURES:
            out.update(STAGE_FIGURES[stage](result, stage, label))
    return out


__all__ = ["STAGE_FIGURES", "history_figure", "population_arrays", "population_map_figure",
           "population_objective_figure", "stage_figures", "strongest_pair"]
