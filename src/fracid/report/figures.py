"""Figures of an identification result (matplotlib, Agg canvas; no pyplot global state).

Every ``*_figure`` function takes an :class:`~fracid.inverse.methods.knn_kalman.IdentificationResult` (or any
object with the same attributes; lists from a JSON file are accepted) and returns a
:class:`matplotlib.figure.Figure`, or ``None`` when the result holds nothing to draw (no Kalman
history, no KNN population, a single parameter for the map). :func:`to_png` renders a figure to PNG
bytes at :data:`DPI`.

Units: control [mm], force [N], parameters in the units of
:meth:`~fracid.fem.material.parameters.DamageParameters.units`.
"""

from __future__ import annotations

import contextlib
import contextvars
import io
import math

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure


#: resolution of the PNG images [dots per inch]
DPI = 110

MEASURED = "#1f77b4"
COMPUTED = "#d62728"
NEIGHBOUR = "#ff7f0e"
FAILED = "#7f7f7f"
ESTIMATE = "#d62728"


# ------------------------------------------------------------------------------------ helpers


_RENDERED = contextvars.ContextVar("fracid_rendered_figures", default=None)


@contextlib.contextmanager
def rendered_once():
    """Within the block, :func:`to_png` renders a figure given a ``stem`` once and returns that PNG for the stem
    afterwards: ``fracid identify`` draws the same figures into report.html and figures/ (rendering is most of a
    figure's cost)."""
    token = _RENDERED.set({})
    try:
        yield
    finally:
        _RENDERED.reset(token)


def to_png(fig: Figure, dpi: int = DPI, stem: str | None = None) -> bytes:
    """The figure as PNG bytes (rendered by the Agg canvas); ``stem`` names it (its file name in figures/) for
    :func:`rendered_once`."""
    rendered = _RENDERED.get() if stem is not None else None
    if rendered is not None and (stem, dpi) in rendered:
        return rendered[stem, dpi]
    if not isinstance(fig.canvas, FigureCanvasAgg):
        FigureCanvasAgg(fig)
    buffer = io.BytesIO()
    fig.savefig(buffer, format="png", dpi=dpi)
    if rendered is not None:
        rendered[stem, dpi] = buffer.getvalue()
    return buffer.getvalue()


def new_figure(width: float, height: float) -> Figure:
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
    lowered = str(name).lower()
    return f"{name} [mm]" if "width" in lowered or "fpz" in lowered else "force [N]"


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


def float_array(values, fill=np.inf) -> np.ndarray:
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


def log_axis(values) -> bool:
    """Log scale for a parameter axis spanning more than two decades of positive values."""
    values = np.asarray(values, float)
    values = values[np.isfinite(values)]
    return values.size > 1 and np.all(values > 0) and values.max() / values.min() > 100.0


def parameter_axis(ax, axis: str, values) -> None:
    """Log scale for a parameter spanning decades, else linear with scientific notation for small
    or large magnitudes (e.g. kappa_i ~ 1e-4) so tick labels stay short."""
    if log_axis(values):
        (ax.set_xscale if axis == "x" else ax.set_yscale)("log")
    else:
        ax.ticklabel_format(axis=axis, style="sci", scilimits=(-3, 4), useMathText=True)


def covariance_ellipse(centre, cov, n_std=2.0, n=200) -> np.ndarray:
    """Points (n, 2) of the n_std ellipse of a 2x2 covariance (Mahalanobis distance n_std)."""
    vals, vecs = np.linalg.eigh(0.5 * (cov + cov.T))
    vals = np.maximum(vals, 0.0)
    t = np.linspace(0.0, 2.0 * np.pi, n)
    circle = np.stack([np.cos(t), np.sin(t)])
    return (np.asarray(centre, float)[:, None] + n_std * vecs @ (np.sqrt(vals)[:, None] * circle)).T



#: the legend's words for a computed curve drawn through the data's points only (no run curve in the result)
AT_DATA_POINTS = "through its values at the data points only: the run's curve is not in this result"


def run_curves(result) -> list:
    """The run's own curves at the estimate of a result (its ``curves``; empty for an older result)."""
    return list(getattr(result, "curves", None) or [])


def draw_computed(ax, x, fit, curve, label: str, colour=COMPUTED, style: str = "-", lw: float = 1.6) -> bool:
    """The curve computed at the estimate in a block's panel: the run's own (``curve``: control [mm] and values
    of every step, :func:`~fracid.inverse.core.diagnostics.block_curve`) with its values at the data's points
    marked on it; without it, the line through the values at the data's points (``fit`` at ``x``), labelled so
    (:data:`AT_DATA_POINTS`). Returns whether the run's curve was drawn."""
    x, fit = np.asarray(x, float), np.asarray(fit, float)
    order = np.argsort(x, kind="stable")
    shown = order[np.isfinite(fit[order]) & np.isfinite(x[order])]
    if curve is not None:
        ax.plot(curve[0], curve[1], style, color=colour, lw=lw, label=label)
        ax.plot(x[shown], fit[shown], ".", color=colour, ms=4)  # where the data sample it
        return True
    if shown.size:
        ax.plot(x[shown], fit[shown], style, color=colour, lw=lw, label=f"{label} ({AT_DATA_POINTS})")
    return False


def block_run_curve(result, index: int, has_control: bool = True):
    """The run's curve of block ``index`` of ``result`` as (control, values), or None (none kept, or the x axis
    is the point index)."""
    from fracid.inverse.core.diagnostics import block_curve

    return block_curve(run_curves(result), index) if has_control else None


def fit_figure(result, control=None, control_label=None, skip=()) -> Figure | None:
    """Measured points with their +/- 2 std band and the curve computed at the estimate, per block.

    The computed curve is the forward run's own at the estimate (every step up to the data's last control
    value, the result's ``curves``), its values at the data's points marked on it; a result without it (an
    older one) gets the line through the values at the data's points, labelled so.

    Parameters
    ----------
    result : IdentificationResult
    control : array_like, optional
        Control value [mm] of every entry of y (e.g. ``ExperimentalData.control``, the blocks
        concatenated); the result's ``control`` when omitted. Without either the x axis is the index
        of the point in its block.
    control_label : str, optional
        The x-axis label (e.g. ``"CMOD [mm]"``); by default from the result's ``control_names``.
    skip : collection of str
        Blocks not drawn: those with a view of their own (:func:`fracid.report.views.view_block_names`), which
        are no curves against the control and have maps of their own. None is returned when no block is left.
    """
    y_exp = float_array(result.y_exp, np.nan)
    std = float_array(result.std_exp, np.nan)
    y_fit = float_array(result.y_fit, np.nan) if result.y_fit is not None else np.full_like(y_exp, np.nan)
    control = getattr(result, "control", None) if control is None else control
    blocks = result_blocks(result)
    labels = block_control_labels(result, len(blocks), control_label)
    drawn_blocks = [(k, block, label) for k, (block, label) in enumerate(zip(blocks, labels))
                    if block[0] not in set(skip)]
    if not drawn_blocks:
        return None
    indices, blocks, labels = zip(*drawn_blocks)
    fig, panels = block_panels(blocks, None if control is None else float_array(control, np.nan), y_exp.size)
    for (ax, name, part, x), label, k in zip(panels, labels, indices):
        y, s = y_exp[part], std[part]
        sort = np.argsort(x, kind="stable")
        ax.fill_between(x[sort], (y - 2 * s)[sort], (y + 2 * s)[sort], color=MEASURED, alpha=0.2, lw=0,
                        label="measured +/- 2 std")
        draw_computed(ax, x, y_fit[part], block_run_curve(result, k, control is not None), "computed at the estimate")
        ax.plot(x, y, "o", color=MEASURED, ms=3.5, label="measured", zorder=3)
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
    fig = new_figure(6.4 * ncols, 4.0 * nrows)
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


def correlation_figure(result) -> Figure:
    """Heat map of the correlation matrix of the estimate, values written in each cell."""
    names = list(result.names)
    corr = np.asarray(result.correlation, float)
    p = len(names)
    size = 2.2 + 0.8 * p
    fig = new_figure(size + 1.4, size)
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
    fig = new_figure(10.0 if local else 6.0, 4.0)
    axes = fig.subplots(1, 2 if local else 1, squeeze=False)[0]
    axes[0].plot(result.control, result.force, "-o", ms=2.5)
    axes[0].set_xlabel(f"{result.control_name} [mm]")
    axes[0].set_ylabel("force [N]")
    axes[0].set_title(f"peak {result.peak_force:.4g} N ({result.status})", fontsize=9)
    axes[0].grid(alpha=0.3)
    if local:
        axes[1].plot(result.control, result.observables[local[0]], "-o", ms=2.5, color=ESTIMATE)
        axes[1].set_xlabel(f"{result.control_name} [mm]")
        axes[1].set_ylabel(f"{local[0].replace('_', ' ')} [mm]")
        axes[1].grid(alpha=0.3)
    return fig


def sensitivity_figure(history, control=None) -> Figure:
    """Normalised sensitivities along the load history (left) and the share of each parameter's
    prior variance removed by the data up to each step (right)."""
    n = history.S.shape[0]
    x = np.arange(n) if control is None else np.asarray(control, float)
    fig = new_figure(10.0, 4.0)
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
