"""Figures of an identification result (matplotlib, Agg canvas; no pyplot global state).

Every ``*_figure`` function takes an :class:`~fracid.inverse.strategy.IdentificationResult` (or any
object with the same attributes; lists from a JSON file are accepted) and returns a
:class:`matplotlib.figure.Figure`, or ``None`` when the result holds nothing to draw (no Kalman
history, no KNN population, a single parameter for the map). :func:`to_png` renders a figure to PNG
bytes at :data:`DPI`.

Units: control [mm], force [N], parameters in the units of
:meth:`~fracid.fem.parameters.DamageParameters.units`.
"""

from __future__ import annotations

import io
import math

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.colors import Normalize
from matplotlib.figure import Figure
from matplotlib.ticker import FuncFormatter


#: resolution of the PNG images [dots per inch]
DPI = 110

_MEASURED = "#1f77b4"
_COMPUTED = "#d62728"
_NEIGHBOUR = "#ff7f0e"
_FAILED = "#7f7f7f"
_ESTIMATE = "#d62728"


# ------------------------------------------------------------------------------------ helpers


def to_png(fig: Figure, dpi: int = DPI) -> bytes:
    """The figure as PNG bytes (rendered by the Agg canvas)."""
    if not isinstance(fig.canvas, FigureCanvasAgg):
        FigureCanvasAgg(fig)
    buffer = io.BytesIO()
    fig.savefig(buffer, format="png", dpi=dpi)
    return buffer.getvalue()


def _new_figure(width: float, height: float) -> Figure:
    fig = Figure(figsize=(width, height), layout="constrained")
    FigureCanvasAgg(fig)
    return fig


def parameter_units() -> dict:
    """Unit of every parameter name of the registered forward models (:func:`fracid.models.known_units`):
    a result holds only names, and the figures label the parameters of any model (e.g. ``ft [MPa]``)."""
    from fracid.models import known_units

    return known_units()


def parameter_label(name: str) -> str:
    """Axis label of a parameter with its unit, e.g. ``"c [mm^2]"``, ``"beta [-]"``, ``"ft [MPa]"``."""
    unit = parameter_units().get(name)
    return f"{name} [{unit}]" if unit else str(name)


def block_quantity(name: str) -> str:
    """Axis label of the measured quantity of a data block: a width [mm] if its name says so,
    else the force [N]."""
    from fracid.inverse.diagnostics import is_force_block

    return "force [N]" if is_force_block(name) else f"{name} [mm]"


#: how a control quantity is written on an axis (others: underscores as spaces)
_CONTROL_WORDS = {"cmod": "CMOD"}


def control_label(name: str | None) -> str:
    """Axis label of a control quantity, e.g. ``"CMOD [mm]"``, ``"deflection [mm]"``, ``"end displacement
    [mm]"``; ``"control [mm]"`` when the name is unknown (None or empty)."""
    if not name:
        return "control [mm]"
    return f"{_CONTROL_WORDS.get(str(name).lower(), str(name).replace('_', ' '))} [mm]"


def block_control_labels(result, n_blocks: int, label: str | None = None) -> list[str]:
    """The x-axis label of every block of a result: ``label`` when given, else from the result's
    ``control_names`` (one per block), else ``"control [mm]"``."""
    if label:
        return [label] * n_blocks
    names = list(getattr(result, "control_names", None) or [])
    return [control_label(names[i] if i < len(names) else None) for i in range(n_blocks)]


def _float_array(values, fill=np.inf) -> np.ndarray:
    """Array of floats; None (JSON null for inf/nan) becomes ``fill``."""
    if values is None:
        return np.array([], float)
    array = np.asarray(values, dtype=object)
    if array.dtype == object:
        array = np.where(np.equal(array, None), fill, array)
    return np.asarray(array, dtype=float)


def result_blocks(result) -> list[tuple[str, int, int]]:
    """(name, start, stop) of every data block of the result; one block ``"data"`` if none."""
    n = int(np.size(result.y_exp))
    blocks = [(str(b[0]), int(b[1]), int(b[2])) for b in (result.blocks or [])]
    return blocks or [("data", 0, n)]


def knn_arrays(result):
    """Population ``points`` (N, p), objective ``f`` (inf where failed), boolean ``failed``,
    ranking ``order`` and ``k`` of the result's KNN search; ``None`` without a population."""
    knn = getattr(result, "knn", None) or {}
    points = knn.get("points")
    if points is None or np.size(points) == 0:
        return None
    p = len(result.names)
    points = _float_array(points, np.nan).reshape(-1, p)
    f = _float_array(knn.get("f"), np.inf)
    if f.size != len(points):
        f = np.full(len(points), np.inf)
    status = list(knn.get("status") or ["ok"] * len(points))
    failed = np.array([s != "ok" for s in status]) | ~np.isfinite(f)
    order = knn.get("order")
    order = np.argsort(np.where(failed, np.inf, f), kind="stable") if order is None else np.asarray(order, int)
    k = int(knn.get("k") or 0)
    return points, f, failed, order, k


def _log_axis(values) -> bool:
    """Log scale for a parameter axis spanning more than two decades of positive values."""
    values = np.asarray(values, float)
    values = values[np.isfinite(values)]
    return values.size > 1 and np.all(values > 0) and values.max() / values.min() > 100.0


def _parameter_axis(ax, axis: str, values) -> None:
    """Log scale for a parameter spanning decades, else linear with scientific notation for small
    or large magnitudes (e.g. kappa_i ~ 1e-4) so tick labels stay short."""
    if _log_axis(values):
        (ax.set_xscale if axis == "x" else ax.set_yscale)("log")
    else:
        ax.ticklabel_format(axis=axis, style="sci", scilimits=(-3, 4), useMathText=True)


def _objective_for_log(f: np.ndarray, failed: np.ndarray):
    """Objective values safe for a log axis (zeros raised to a floor) and the height of failed runs."""
    good = f[~failed & np.isfinite(f)]
    positive = good[good > 0]
    floor = positive.min() / 10.0 if positive.size else 1e-12
    shown = np.where(failed | ~np.isfinite(f), np.nan, np.maximum(f, floor))
    top = (np.nanmax(shown) if good.size else 1.0) * 5.0
    return shown, top, floor


def _ellipse(centre, cov, n_std=2.0, n=200) -> np.ndarray:
    """Points (n, 2) of the n_std ellipse of a 2x2 covariance (Mahalanobis distance n_std)."""
    vals, vecs = np.linalg.eigh(0.5 * (cov + cov.T))
    vals = np.maximum(vals, 0.0)
    t = np.linspace(0.0, 2.0 * np.pi, n)
    circle = np.stack([np.cos(t), np.sin(t)])
    return (np.asarray(centre, float)[:, None] + n_std * vecs @ (np.sqrt(vals)[:, None] * circle)).T


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


def fit_figure(result, control=None, control_label=None) -> Figure:
    """Measured points with their +/- 2 std band and the curve computed at the estimate, per block.

    The computed values are known at the data points only: the computed curve is the line through
    them (its finite values), not a finer curve.

    Parameters
    ----------
    result : IdentificationResult
    control : array_like, optional
        Control value [mm] of every entry of y (e.g. ``ExperimentalData.control``, the blocks
        concatenated); the result's ``control`` when omitted. Without either the x axis is the index
        of the point in its block.
    control_label : str, optional
        The x-axis label (e.g. ``"CMOD [mm]"``); by default from the result's ``control_names``.
    """
    y_exp = _float_array(result.y_exp, np.nan)
    std = _float_array(result.std_exp, np.nan)
    y_fit = _float_array(result.y_fit, np.nan) if result.y_fit is not None else np.full_like(y_exp, np.nan)
    control = getattr(result, "control", None) if control is None else control
    blocks = result_blocks(result)
    fig, panels = block_panels(blocks, None if control is None else _float_array(control, np.nan), y_exp.size)
    labels = block_control_labels(result, len(blocks), control_label)
    for (ax, name, part, x), label in zip(panels, labels):
        y, s, fit = y_exp[part], std[part], y_fit[part]
        sort = np.argsort(x, kind="stable")
        ax.fill_between(x[sort], (y - 2 * s)[sort], (y + 2 * s)[sort], color=_MEASURED, alpha=0.2, lw=0,
                        label="measured +/- 2 std")
        ax.plot(x, y, "o", color=_MEASURED, ms=3.5, label="measured")
        drawn = sort[np.isfinite(fit[sort])]
        if drawn.size:
            ax.plot(x[drawn], fit[drawn], "-", color=_COMPUTED, lw=1.6, label="computed at the estimate")
        finish_block_panel(ax, name, control is not None, label)
    return fig


def block_panels(blocks, control, n_values: int):
    """A figure of one panel per data block (two columns beyond one block, unused panels hidden).

    Returns the figure and, per block, ``(ax, name, part, x)``: ``part`` the block's slice of y and ``x``
    its control values [mm], or the point index in the block when ``control`` is None. Raises ValueError
    when ``control`` does not hold ``n_values`` values. :func:`finish_block_panel` labels a panel.
    """
    if control is not None and np.shape(control) != (n_values,):
        raise ValueError(f"control has {np.size(control)} values but the result holds {n_values} measured values")
    ncols = 1 if len(blocks) == 1 else 2
    nrows = math.ceil(len(blocks) / ncols)
    fig = _new_figure(6.4 * ncols, 4.0 * nrows)
    axes = fig.subplots(nrows, ncols, squeeze=False).ravel()
    for ax in axes[len(blocks):]:
        ax.set_visible(False)
    panels = [(ax, name, slice(start, stop),
               control[start:stop] if control is not None else np.arange(stop - start, dtype=float))
              for ax, (name, start, stop) in zip(axes, blocks)]
    return fig, panels


def finish_block_panel(ax, name: str, has_control: bool, control_label: str = "control [mm]") -> None:
    """Axis labels (``control_label`` or the point index, the block's quantity), title, grid and legend
    of a block's panel."""
    ax.set_xlabel(control_label if has_control else "point index in the block [-]")
    ax.set_ylabel(block_quantity(name))
    ax.set_title(name)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize="small")


def kalman_figure(result) -> Figure | None:
    """Estimate of every parameter after every Kalman step with its +/- 2 std band.

    x axis: cumulative step index over the global iterations (0 = the prior from KNN when known);
    dotted vertical lines separate the global iterations; the horizontal line is the final value.
    """
    history = list(getattr(result, "history", None) or [])
    if not history:
        return None
    names = list(result.names)
    p = len(names)
    xs = np.array([_float_array(h["x"], np.nan).reshape(p) for h in history])
    stds = np.array([np.sqrt(np.maximum(np.diag(_float_array(h["C"], np.nan).reshape(p, p)), 0.0)) for h in history])
    index = np.arange(1, len(history) + 1)
    knn = getattr(result, "knn", None) or {}
    if knn.get("x0") is not None and knn.get("C0") is not None:
        x0 = _float_array(knn["x0"], np.nan).reshape(p)
        s0 = np.sqrt(np.maximum(np.diag(_float_array(knn["C0"], np.nan).reshape(p, p)), 0.0))
        xs, stds, index = np.vstack([x0, xs]), np.vstack([s0, stds]), np.concatenate([[0], index])
    iterations = [h.get("iteration", 1) for h in history]
    boundaries = [i + 0.5 for i in range(1, len(history)) if iterations[i] != iterations[i - 1]]
    final = _float_array(result.x, np.nan).reshape(p)
    fig = _new_figure(7.5, 2.3 * p + 0.6)
    axes = fig.subplots(p, 1, sharex=True, squeeze=False).ravel()
    for j, ax in enumerate(axes):
        ax.fill_between(index, xs[:, j] - 2 * stds[:, j], xs[:, j] + 2 * stds[:, j], color=_MEASURED, alpha=0.2,
                        lw=0, label="+/- 2 std")
        ax.plot(index, xs[:, j], "-o", color=_MEASURED, ms=2.5, lw=1.0, label="estimate")
        ax.axhline(final[j], color=_ESTIMATE, lw=1.0, ls="--", label=f"final {final[j]:.4g}")
        for b in boundaries:
            ax.axvline(b, color="k", lw=0.8, ls=":")
        ax.set_ylabel(parameter_label(names[j]))
        ax.ticklabel_format(axis="y", style="sci", scilimits=(-3, 4), useMathText=True)
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize="x-small", loc="best")
    n_iter = len(dict.fromkeys(iterations))
    axes[0].set_title(f"Kalman filter: {len(history)} steps in {n_iter} global iteration(s)"
                      + (" (step 0: KNN prior)" if index[0] == 0 else ""))
    axes[-1].set_xlabel("cumulative step [-] (dotted: new global iteration)")
    return fig


def knn_objective_figure(result) -> Figure | None:
    """Objective f (log scale) of every population point against each parameter.

    Failed runs are drawn as grey crosses above the largest objective; the k nearest neighbours are
    highlighted and the final estimate is a vertical line.
    """
    arrays = knn_arrays(result)
    if arrays is None:
        return None
    points, f, failed, order, k = arrays
    names = list(result.names)
    p = len(names)
    shown, top, _ = _objective_for_log(f, failed)
    nearest = np.zeros(len(points), bool)
    nearest[order[:k]] = True
    final = _float_array(result.x, np.nan).reshape(p)
    ncols = min(p, 3)
    nrows = math.ceil(p / ncols)
    fig = _new_figure(4.3 * ncols, 3.6 * nrows)
    axes = fig.subplots(nrows, ncols, squeeze=False, sharey=True).ravel()
    for j, ax in enumerate(axes[:p]):
        ok = ~failed
        ax.plot(points[ok & ~nearest, j], shown[ok & ~nearest], "o", color=_MEASURED, ms=4, alpha=0.7,
                label="population")
        ax.plot(points[nearest, j], shown[nearest], "o", mfc="none", mec=_NEIGHBOUR, mew=1.8, ms=8,
                label=f"{k} nearest")
        if failed.any():
            ax.plot(points[failed, j], np.full(failed.sum(), top), "x", color=_FAILED, ms=7, mew=1.5,
                    label=f"failed ({failed.sum()})")
        ax.axvline(final[j], color=_ESTIMATE, lw=1.2, label=f"estimate {final[j]:.4g}")
        ax.set_yscale("log")
        _parameter_axis(ax, "x", points[:, j])
        ax.set_xlabel(parameter_label(names[j]))
        ax.grid(True, which="both", alpha=0.25)
    axes[0].set_ylabel("objective f [-]")
    axes[0].legend(fontsize="x-small", loc="best")
    for ax in axes[p:]:
        ax.set_visible(False)
    fig.suptitle(f"KNN population: {len(points)} runs, objective f = (y_exp - y)^T C_exp^-1 (y_exp - y)",
                 fontsize="medium")
    return fig


def knn_map_figure(result) -> Figure | None:
    """Population over the two most correlated parameters, coloured by log10 f, with the k nearest
    and the estimate with its 2-std ellipse (and the KNN prior's, dashed). None for one parameter."""
    pair = strongest_pair(result)
    arrays = knn_arrays(result)
    if pair is None or arrays is None:
        return None
    i, j = pair
    points, f, failed, order, k = arrays
    names = list(result.names)
    shown, _, _ = _objective_for_log(f, failed)
    ok = ~failed
    fig = _new_figure(6.4, 5.0)
    ax = fig.subplots()
    colour = np.log10(shown[ok])
    norm = Normalize(vmin=np.nanmin(colour), vmax=np.nanmax(colour)) if colour.size else None
    scatter = ax.scatter(points[ok, i], points[ok, j], c=colour, cmap="viridis_r", norm=norm, s=30,
                         edgecolors="none", label="population")
    fig.colorbar(scatter, ax=ax, label="log10 f [-]")
    near = order[:k]
    ax.plot(points[near, i], points[near, j], "o", mfc="none", mec=_NEIGHBOUR, mew=1.8, ms=10, label=f"{k} nearest")
    if failed.any():
        ax.plot(points[failed, i], points[failed, j], "x", color=_FAILED, ms=7, mew=1.5,
                label=f"failed ({failed.sum()})")
    x = _float_array(result.x, np.nan)
    C = _float_array(result.C, np.nan).reshape(len(names), len(names))
    sub = np.ix_([i, j], [i, j])
    knn = getattr(result, "knn", None) or {}
    if knn.get("x0") is not None and knn.get("C0") is not None:
        x0 = _float_array(knn["x0"], np.nan)
        C0 = _float_array(knn["C0"], np.nan).reshape(len(names), len(names))
        e0 = _ellipse(x0[[i, j]], C0[sub])
        ax.plot(e0[:, 0], e0[:, 1], "--", color=_NEIGHBOUR, lw=1.0, label="KNN prior, 2 std")
    ellipse = _ellipse(x[[i, j]], C[sub])
    ax.plot(ellipse[:, 0], ellipse[:, 1], "-", color=_ESTIMATE, lw=1.4, label="estimate, 2 std")
    ax.plot([x[i]], [x[j]], "*", color=_ESTIMATE, ms=14, mec="k", mew=0.6, label="estimate")
    _parameter_axis(ax, "x", points[:, i])
    _parameter_axis(ax, "y", points[:, j])
    corr = float(np.asarray(result.correlation, float)[i, j])
    ax.set_title(f"{names[i]} - {names[j]} (correlation {corr:+.3f})")
    ax.set_xlabel(parameter_label(names[i]))
    ax.set_ylabel(parameter_label(names[j]))
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize="x-small", loc="best")
    return fig


def correlation_figure(result) -> Figure:
    """Heat map of the correlation matrix of the estimate, values written in each cell."""
    names = list(result.names)
    corr = np.asarray(result.correlation, float)
    p = len(names)
    size = 2.2 + 0.8 * p
    fig = _new_figure(size + 1.4, size)
    ax = fig.subplots()
    image = ax.imshow(corr, cmap="RdBu_r", vmin=-1.0, vmax=1.0, aspect="auto")
    fig.colorbar(image, ax=ax, label="correlation [-]")
    for a in range(p):
        for b in range(p):
            value = corr[a, b]
            ax.text(b, a, f"{value:+.2f}" if np.isfinite(value) else "n/a", ha="center", va="center",
                    color="white" if np.isfinite(value) and abs(value) > 0.6 else "black", fontsize=10)
    ax.set_xticks(range(p), names)
    ax.set_yticks(range(p), names)
    ax.set_title("correlation of the identified parameters")
    return fig


# ------------------------------------------------------------------------------------ forward runs


def curve_figure(result) -> Figure:
    """Force versus the control quantity of a forward run, with its local observables beside it."""
    local = [n for n in ("fpz_width", "damaged_zone_width") if n in result.observables]
    fig = _new_figure(10.0 if local else 6.0, 4.0)
    axes = fig.subplots(1, 2 if local else 1, squeeze=False)[0]
    axes[0].plot(result.control, result.force, "-o", ms=2.5)
    axes[0].set_xlabel(f"{result.control_name} [mm]")
    axes[0].set_ylabel("force [N]")
    axes[0].set_title(f"peak {result.peak_force:.4g} N ({result.status})", fontsize=9)
    axes[0].grid(alpha=0.3)
    if local:
        axes[1].plot(result.control, result.observables[local[0]], "-o", ms=2.5, color=_ESTIMATE)
        axes[1].set_xlabel(f"{result.control_name} [mm]")
        axes[1].set_ylabel(f"{local[0].replace('_', ' ')} [mm]")
        axes[1].grid(alpha=0.3)
    return fig


def sensitivity_figure(history, control=None) -> Figure:
    """Normalised sensitivities along the load history (left) and the share of each parameter's
    prior variance removed by the data up to each step (right)."""
    n = history.S.shape[0]
    x = np.arange(n) if control is None else np.asarray(control, float)
    fig = _new_figure(10.0, 4.0)
    left, right = fig.subplots(1, 2)
    for j, name in enumerate(history.names):
        left.plot(x, history.normalised[:, j], "-o", ms=2.5, label=name)
        right.plot(x, history.variance_share[:, j], "-o", ms=2.5, label=name)
    left.axhline(0.0, color="k", lw=0.5)
    left.set_ylabel("d y / d x_j * x_j / max|y|  [-]")
    right.set_ylabel("share of prior variance removed [-]")
    right.set_ylim(-0.02, 1.02)
    for ax in (left, right):
        ax.set_xlabel("control [mm]" if control is not None else "observation")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    return fig


# ------------------------------------------------------------------------------------ size effect


def size_effect_figure(sizes, sigma_computed, fit=None, sigma_measured=None, measured_std=None,
                       calibrated=None) -> Figure:
    """Nominal strength against size on log-log axes, with Bazant's size effect law when fitted.

    Parameters
    ----------
    sizes : array_like
        Specimen sizes D [mm].
    sigma_computed : array_like
        Computed nominal strengths at ``sizes`` [MPa]; nan (a failed run) is left out.
    fit : SizeEffectFit, optional
        Drawn as the law over the sizes' range, with its asymptotes: the strength criterion
        sigma_N = B f_t and LEFM sigma_N = B f_t sqrt(D0 / D) (slope -1/2), which cross at D0.
    sigma_measured, measured_std : array_like, optional
        Measured nominal strengths at ``sizes`` and their standard deviations [MPa] (error bars of
        +/- 1 std); nan where a size was not tested.
    calibrated : array_like of bool, optional
        True for the sizes whose data calibrated the model: their computed points are filled,
        those of the other (predicted) sizes hollow. None: no distinction.
    """
    D = _float_array(sizes, np.nan)
    computed = _float_array(sigma_computed, np.nan)
    if computed.shape != D.shape:
        raise ValueError(f"sigma_computed has {computed.size} values but sizes has {D.size}")
    fig = _new_figure(6.4, 4.6)
    ax = fig.subplots()
    shown = [computed]
    if fit is not None:
        _size_effect_law(ax, fit, D)
    if sigma_measured is not None:
        measured = _float_array(sigma_measured, np.nan)
        std = None if measured_std is None else _float_array(measured_std, np.nan)
        shown.append(measured)
        ax.errorbar(D, measured, yerr=std, fmt="s", color=_MEASURED, mfc="none", ms=9, capsize=3,
                    label="measured" + (" +/- 1 std" if std is not None else ""))
    if calibrated is None:
        ax.plot(D, computed, "o", color=_COMPUTED, ms=7, label="computed")
    else:
        used = np.asarray(calibrated, dtype=bool)
        if used.shape != D.shape:
            raise ValueError(f"calibrated has {used.size} values but sizes has {D.size}; give one flag per size")
        ax.plot(D[used], computed[used], "o", color=_COMPUTED, ms=7, label="computed, calibration sizes")
        ax.plot(D[~used], computed[~used], "o", mfc="white", mec=_COMPUTED, mew=1.6, ms=7,
                label="computed, predicted sizes")
    ax.set_xscale("log")
    ax.set_yscale("log")
    _plain_log_ticks(ax.xaxis)
    _plain_log_ticks(ax.yaxis)
    if fit is not None:
        # the LEFM line grows without bound as D -> 0: cap the axis just above the law and the points
        ax.set_ylim(top=1.6 * np.nanmax(np.concatenate([[fit.B_ft], *shown])))
    ax.set_xlabel("size D [mm]")
    ax.set_ylabel("nominal strength sigma_N [MPa]")
    ax.grid(True, which="both", alpha=0.25)
    ax.legend(fontsize="small", loc="best")
    return fig


def _plain_log_ticks(axis) -> None:
    """Plain numbers (0.8, 2, 1000) on a log axis rather than powers of ten; the minor ticks are
    labelled only when the axis spans less than a decade (a strength axis often does), as there
    are then at most eight of them."""
    axis.set_major_formatter(FuncFormatter(lambda value, _: f"{value:g}"))

    def minor(value, _):
        low, high = axis.get_view_interval()
        return f"{value:g}" if high < 10.0 * low else ""

    axis.set_minor_formatter(FuncFormatter(minor))


def _size_effect_law(ax, fit, D) -> None:
    """The fitted law and its two asymptotes over a range wide enough to show where they meet."""
    data = D[np.isfinite(D) & (D > 0)]
    # show the transition at D0 when it is near the data, never decades of empty axis
    span = np.concatenate([data, [np.clip(fit.D0, data.min() / 10.0, data.max() * 10.0)]])
    grid = np.geomspace(span.min() / 2.0, span.max() * 2.0, 200)
    ax.plot(grid, fit.predict(grid), "-", color=_ESTIMATE, lw=1.6,
            label=f"size effect law: B f_t = {fit.B_ft:.3g} MPa, D0 = {fit.D0:.3g} mm")
    ax.axhline(fit.B_ft, color="k", lw=0.9, ls="--", label="strength criterion")
    ax.plot(grid, fit.B_ft * np.sqrt(fit.D0 / grid), "k-.", lw=0.9, label="LEFM, slope -1/2")
