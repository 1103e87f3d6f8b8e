"""Maps of a displacement-field (DIC) block at the estimate: measured, computed and residual, frame by frame.

A field block (:class:`~fracid.inverse.core.observations.FieldObservation`) holds the displacement components at
points of the specimen's face and at frames (control values); drawn against the control like a curve it is a
cloud of thousands of points. Here every frame is a figure of maps over the face, and a summary figure follows
the fit along the frames.

Every frame carries a rigid-body motion (the specimen settling on its supports) that the model, whose supports
are fixed, does not compute; the identification marginalises it in the data covariance
(:mod:`fracid.data.dic.rigid`). :func:`fit_field` estimates it afterwards, frame by frame, from the residual
(measured - computed) by generalised least squares (:func:`~fracid.data.dic.rigid.fit_rigid_motion`), so the
maps show the measured field with that motion removed, comparable with the model's.

Units: positions x, y [mm]; displacements and residuals on the maps [micrometre]; rigid translations
t_x, t_y [micrometre] and rotation theta [microradian] in the figures and tables ([mm] and [rad] in
:class:`FieldFit`); residual RMS also in units of the noise std: the whitened RMS sqrt(r^T C^-1 r / n) of the
residual r with the rigid motion removed (about 1 when the model follows the data within their noise).

Hook: :data:`BLOCK_VIEWS` maps the ``kind`` of a block's coordinates (``"field"`` here) to the function
building its report view (:class:`BlockView`: heading, text, table, figures). A later kind (e.g. a
crack-opening profile fit, from :mod:`fracid.inverse.core.derived_observations`) adds its own entry;
:func:`block_views` and the HTML report (:func:`fracid.report.html.write_report`) and ``fracid identify``'s
figures/ then show it with no other change.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field

import numpy as np
from matplotlib.figure import Figure
from matplotlib.ticker import MaxNLocator
from matplotlib.tri import Triangulation

from fracid.report.figures import (COMPUTED, MEASURED, block_control_labels, float_array, new_figure,
                                   result_blocks, to_png)

#: micrometres per millimetre (maps and rigid translations are drawn in micrometres)
UM = 1e3
#: microradians per radian
URAD = 1e6
#: quantities of the blocks that are displacement fields (an observation kind's ``quantity``)
FIELD_QUANTITIES = ("u",)
#: names of the displacement components by index
COMPONENT_NAMES = ("u_x", "u_y")
#: a triangle with an edge longer than this many typical point spacings spans a hole and is not drawn
HOLE_EDGES = 2.0
#: colour map of the displacements and of the residuals (diverging, centred on 0)
DISPLACEMENT_MAP, RESIDUAL_MAP = "viridis", "RdBu_r"
#: filled contour levels of a map (at most)
LEVELS = 15
#: width of a frame's figure [in] (three maps a row)
MAP_WIDTH = 13.0


# ------------------------------------------------------------------------------------ the fit, frame by frame


@dataclass(frozen=True)
class FieldFit:
    """A field block's fit at the estimate, frame by frame, with each frame's rigid motion removed.

    Attributes
    ----------
    x, y : ndarray (n,)
        Position of every entry [mm].
    frame, component : ndarray of int (n,)
        Frame index (0, 1, ...) and component (0: u_x, 1: u_y) of every entry.
    controls : ndarray (n_frames,)
        Control value of every frame [mm] (NaN if unknown).
    measured, computed, rigid, residual : ndarray (n,)
        Measured and computed displacements, the fitted rigid motion's displacement and the residual
        measured - rigid - computed [mm] (NaN where the computed value is missing).
    motions : ndarray (n_frames, 3)
        Rigid motion of every frame: t_x [mm], t_y [mm], theta [rad] about the specimen's origin.
    rms_std : ndarray (n_frames, 3)
        Whitened RMS of the residual of every frame in noise stds: u_x, u_y, both (NaN where none).
    rms_mm : ndarray (n_frames, 3)
        Plain RMS of the residual of every frame [mm]: u_x, u_y, both.
    values : ndarray of int (n_frames,)
        Entries of every frame with a residual.
    noise : str
        What the noise std is: ``"covariance"`` (whitened by the given covariance) or ``"std"`` (the
        given std of every entry, independent errors).
    """

    x: np.ndarray
    y: np.ndarray
    frame: np.ndarray
    component: np.ndarray
    controls: np.ndarray
    measured: np.ndarray
    computed: np.ndarray
    rigid: np.ndarray
    residual: np.ndarray
    motions: np.ndarray
    rms_std: np.ndarray
    rms_mm: np.ndarray
    values: np.ndarray
    noise: str = "covariance"

    @property
    def n_frames(self) -> int:
        return len(self.controls)

    @property
    def components(self) -> tuple:
        return tuple(int(c) for c in np.unique(self.component))


def fit_field(x, y, frame, component, measured, computed, *, std=None, covariance=None, control=None,
              point=None) -> FieldFit:
    """The rigid motion of every frame of a field block, its residual and the residual's RMS.

    Parameters
    ----------
    x, y : array_like (n,)
        Position of every entry [mm] (a field observation's ``coordinates()``).
    frame : array_like of int (n,)
        Frame index of every entry (0, 1, ...).
    component : array_like of int (n,)
        0 (u_x) or 1 (u_y) for every entry.
    measured, computed : array_like (n,)
        Measured and computed displacements [mm]; a NaN computed value (a frame not reached) has no residual.
    std : array_like (n,), optional
        Noise std of every entry [mm], independent errors; used when ``covariance`` is None.
    covariance : fracid Covariance, optional
        The covariance of the block's entries [mm^2] (``data.covariance.take(block)``), the rigid motion
        marginalised in it or not: the rigid fit is generalised least squares with it, and the RMS in noise
        stds is sqrt(r^T C^-1 r / n) of the residual r with the rigid motion removed.
    control : array_like (n,), optional
        Control value of every entry [mm]: each frame's control value.
    point : array_like of int (n,), optional
        Point index of every entry (entries of one frame are in (component, point) order); by default the
        points are told apart by their position.

    Returns
    -------
    FieldFit

    Raises
    ------
    ValueError
        Arrays of unequal lengths, or neither ``std`` nor ``covariance``.
    """
    arrays = [float_array(a, np.nan) for a in (x, y, measured, computed)]
    frame, component = np.asarray(frame, int), np.asarray(component, int)
    n = frame.size
    if any(a.shape != (n,) for a in (*arrays, component)):
        raise ValueError(f"x, y, frame, component, measured and computed must have one value per entry ({n})")
    if covariance is None and std is None:
        raise ValueError("give the noise of the entries: std [mm] or covariance [mm^2]")
    x, y, measured, computed = arrays
    given = covariance is not None
    covariance = _noise_covariance(std, covariance, n)
    ids = _point_ids(x, y, point)
    n_frames = int(frame.max()) + 1 if n else 0
    rigid = np.full(n, np.nan)
    motions, rms_std, rms_mm = (np.full((n_frames, 3), np.nan) for _ in range(3))
    values = np.zeros(n_frames, int)
    for k in range(n_frames):
        entries = np.flatnonzero((frame == k) & np.isfinite(measured - computed))
        if entries.size == 0:
            continue
        frame_covariance = covariance.take(entries)
        motions[k], rigid[entries] = _frame_rigid_motion(x, y, ids, component, entries, measured - computed,
                                                         frame_covariance)
        rms_std[k], rms_mm[k] = _frame_rms((measured - rigid - computed)[entries], component[entries],
                                           frame_covariance)
        values[k] = entries.size
    return FieldFit(x, y, frame, component, _frame_controls(control, frame, n_frames), measured, computed, rigid,
                    measured - rigid - computed, motions, rms_std, rms_mm, values,
                    "covariance" if given else "std")


def _noise_covariance(std, covariance, n: int):
    if covariance is not None:
        if covariance.n != n:
            raise ValueError(f"the covariance has {covariance.n} entries, the field {n}")
        return covariance
    from fracid.data.covariance_matrix import Diagonal

    std = float_array(std, np.nan)
    if std.shape != (n,):
        raise ValueError(f"std has {std.size} values, the field {n}")
    return Diagonal(std**2, name="std of the field")


def _point_ids(x, y, point) -> np.ndarray:
    """An index of every entry's point: ``point`` when given, else by position (first seen first)."""
    if point is not None:
        return np.asarray(point, int)
    _, first, inverse = np.unique(np.column_stack([x, y]), axis=0, return_index=True, return_inverse=True)
    rank = np.empty(first.size, int)
    rank[np.argsort(first, kind="stable")] = np.arange(first.size)
    return rank[np.ravel(inverse)]


def _frame_controls(control, frame, n_frames: int) -> np.ndarray:
    if control is None:
        return np.full(n_frames, np.nan)
    control = float_array(control, np.nan)
    return np.array([control[frame == k][0] if np.any(frame == k) else np.nan for k in range(n_frames)])


def _frame_rigid_motion(x, y, ids, component, entries, difference, covariance):
    """(motion (3,), its displacement at ``entries``) of one frame, by
    :func:`~fracid.data.dic.rigid.fit_rigid_motion` on the frame's entries laid out component-major, point
    fastest (the layout it takes); ``covariance``: of the ``entries``, reordered to that layout if need be."""
    from fracid.data.dic.rigid import fit_rigid_motion

    components = tuple(int(c) for c in np.unique(component[entries]))
    points_used = np.unique(ids[entries])
    position = np.searchsorted(points_used, ids[entries])
    slot = np.searchsorted(components, component[entries]) * points_used.size + position
    order = np.argsort(slot, kind="stable")
    points = np.empty((points_used.size, 2))
    points[position] = np.column_stack([x[entries], y[entries]])
    residual = np.full(len(components) * points_used.size, np.nan)
    residual[slot] = difference[entries]
    in_layout = covariance if np.all(np.diff(order) > 0) else covariance.take(order)
    motion, fitted = fit_rigid_motion(points, components, residual, in_layout)
    return motion, fitted[slot]


def _frame_rms(residual, component, covariance) -> tuple[np.ndarray, np.ndarray]:
    """Whitened RMS [noise std] and RMS [mm] of one frame's residual (``covariance`` its entries'): u_x, u_y,
    both."""
    parts = [np.flatnonzero(component == c) for c in (0, 1)]
    rms_std = [math.sqrt(covariance.take(p).quadratic(residual[p]) / p.size) if p.size else math.nan for p in parts]
    rms_std.append(math.sqrt(covariance.quadratic(residual) / residual.size))
    rms_mm = [math.sqrt(np.mean(residual[p] ** 2)) if p.size else math.nan for p in parts]
    rms_mm.append(math.sqrt(np.mean(residual**2)))
    return np.array(rms_std), np.array(rms_mm)


# ------------------------------------------------------------------------------------ figures


def frame_figure(fit: FieldFit, k: int, *, name: str = "field", control_name: str = "control") -> Figure:
    """Maps of frame ``k``: a row per component (u_x, u_y), columns measured - rigid, computed and residual
    measured - rigid - computed [micrometre] over the specimen's face.

    Measured and computed maps of a component share their colour levels; the residual's are centred on 0.
    The title gives the frame (1-based), its control value [mm], the rigid motion removed and the residual's
    whitened RMS in noise stds.
    """
    components = fit.components
    fig = new_figure(MAP_WIDTH, map_row_height(fit.x, fit.y) * len(components) + 0.5)
    axes = fig.subplots(len(components), 3, squeeze=False)
    in_frame = fit.frame == k
    for row, c in zip(axes, components):
        entries = in_frame & (fit.component == c)
        label = COMPONENT_NAMES[c]
        measured, computed = (UM * (fit.measured - fit.rigid))[entries], (UM * fit.computed)[entries]
        shared = _levels(np.concatenate([measured, computed]))
        for ax, values, what in ((row[0], measured, "measured - rigid"), (row[1], computed, "computed")):
            _map(fig, ax, fit.x[entries], fit.y[entries], values, shared, DISPLACEMENT_MAP, f"{label} [µm]")
            ax.set_title(f"{label} {what}", fontsize=10)
        residual = (UM * fit.residual)[entries]
        _map(fig, row[2], fit.x[entries], fit.y[entries], residual, _levels(residual, symmetric=True), RESIDUAL_MAP,
             f"{label} residual [µm]")
        row[2].set_title(f"{label} residual (RMS {fit.rms_mm[k, c] * UM:.3g} µm, {fit.rms_std[k, c]:.3g} std)",
                         fontsize=10)
    fig.suptitle(frame_title(fit, k, name, control_name), fontsize=11)
    return fig


def map_row_height(x, y) -> float:
    """Height [in] of a row of three maps of the points (x, y) [mm] in a figure :data:`MAP_WIDTH` wide: the face's
    aspect ratio at the width of a panel, plus room for titles and axis labels (1.8 to 5 in)."""
    width, height = np.ptp(x) if len(x) else 1.0, np.ptp(y) if len(y) else 1.0
    return float(np.clip((MAP_WIDTH / 3.0 - 1.3) * height / max(width, 1e-12) + 1.0, 1.8, 5.0))


def frame_title(fit: FieldFit, k: int, name: str = "field", control_name: str = "control") -> str:
    """``"field: frame 2 of 6, CMOD = 0.034 mm; rigid motion removed: ..."``."""
    tx, ty, theta = fit.motions[k]
    control = f", {control_name} = {fit.controls[k]:.4g} mm" if math.isfinite(fit.controls[k]) else ""
    return (f"{name}: frame {k + 1} of {fit.n_frames}{control}; rigid motion removed: t_x = {UM * tx:.3g} µm, "
            f"t_y = {UM * ty:.3g} µm, theta = {URAD * theta:.3g} µrad; "
            f"residual RMS {fit.rms_std[k, 2]:.3g} noise std")


def summary_figure(fit: FieldFit, *, name: str = "field", control_label: str = "control [mm]") -> Figure:
    """The residual's whitened RMS per frame in noise stds (u_x, u_y, both; 1 = the noise), and the rigid
    motion fitted per frame: translations t_x, t_y [micrometre] and rotation theta [microradian]."""
    fig = new_figure(13.0, 3.8)
    rms, translation, rotation = fig.subplots(1, 3)
    x = fit.controls if np.all(np.isfinite(fit.controls)) else np.arange(1, fit.n_frames + 1, dtype=float)
    xlabel = control_label if np.all(np.isfinite(fit.controls)) else "frame [-]"
    for column, label, style in ((0, "u_x", "o-"), (1, "u_y", "s-"), (2, "both", "k^--")):
        if np.any(np.isfinite(fit.rms_std[:, column])):
            rms.plot(x, fit.rms_std[:, column], style, ms=4, label=label)
    rms.axhline(1.0, color="grey", lw=0.8, ls=":", label="noise level")
    rms.set_ylim(bottom=0.0)
    rms.set_ylabel("residual RMS [noise std]")
    rms.set_title(f"{name}: residual after rigid motion", fontsize=10)
    translation.plot(x, UM * fit.motions[:, 0], "o-", color=MEASURED, ms=4, label="t_x")
    translation.plot(x, UM * fit.motions[:, 1], "s-", color=COMPUTED, ms=4, label="t_y")
    translation.set_ylabel("rigid translation [µm]")
    translation.set_title("rigid translation per frame", fontsize=10)
    rotation.plot(x, URAD * fit.motions[:, 2], "o-", color="k", ms=4, label="theta")
    rotation.set_ylabel("rigid rotation theta [µrad]")
    rotation.set_title("rigid rotation per frame (about the origin)", fontsize=10)
    for ax in (rms, translation, rotation):
        ax.set_xlabel(xlabel)
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize="small")
    return fig


def _levels(values, symmetric: bool = False) -> np.ndarray:
    """Round contour levels over the finite ``values`` (centred on 0 if ``symmetric``; never a zero range)."""
    finite = np.asarray(values, float)[np.isfinite(values)]
    low, high = (float(finite.min()), float(finite.max())) if finite.size else (-1.0, 1.0)
    if symmetric:
        high = max(abs(low), abs(high))
        low = -high
    if high - low <= 1e-9 * max(abs(low), abs(high), 1e-12):
        low, high = low - max(abs(low), 1.0) * 1e-3, high + max(abs(high), 1.0) * 1e-3
    return MaxNLocator(LEVELS, symmetric=symmetric).tick_values(low, high)


def _map(fig, ax, x, y, values, levels, cmap: str, label: str) -> None:
    """A filled contour map of ``values`` at the points over the face (holes not bridged), or coloured points
    where the points cannot be triangulated; equal aspect, axes [mm], a colour bar labelled ``label``."""
    have = np.isfinite(values)
    x, y, values = x[have], y[have], values[have]
    triangulation = hole_free_triangulation(x, y)
    if triangulation is None:
        drawn = ax.scatter(x, y, c=values, cmap=cmap, vmin=levels[0], vmax=levels[-1], s=12)
    else:
        drawn = ax.tricontourf(triangulation, values, levels=levels, cmap=cmap, extend="both")
    ax.plot(x, y, ".", color="k", ms=0.8, alpha=0.4)
    fig.colorbar(drawn, ax=ax, label=label)
    ax.set_aspect("equal")
    ax.set_xlabel("x [mm]")
    ax.set_ylabel("y [mm]")


def hole_free_triangulation(x, y) -> Triangulation | None:
    """The Delaunay triangulation of the points with the triangles that span a hole masked (an edge longer than
    :data:`HOLE_EDGES` times the median distance to the nearest point: the notch, the region dropped near the
    crack); None with fewer than 3 points, points on a line or no triangle left."""
    if len(x) < 3:
        return None
    try:
        triangulation = Triangulation(x, y)
    except (ValueError, RuntimeError):  # collinear or duplicate points
        return None
    edges = np.hypot(*(np.stack([x, y])[:, triangulation.triangles] -
                       np.roll(np.stack([x, y])[:, triangulation.triangles], 1, axis=2)))  # (2, m, 3) -> (m, 3)
    nearest = np.min(np.where(edges > 0, edges, np.inf), axis=1)
    limit = HOLE_EDGES * float(np.median(nearest))
    mask = np.max(edges, axis=1) > limit
    if mask.all():
        return None
    triangulation.set_mask(mask)
    return triangulation


# ------------------------------------------------------------------------------------ report views (the hook)


@dataclass
class BlockView:
    """What the report shows of a block that is not a curve.

    Attributes
    ----------
    block : str
        The block's name.
    heading : str
        The section's heading, e.g. ``"Displacement field field"``.
    text : str
        A paragraph (plain text, escaped by the report).
    header, rows : list
        A table (formatted cells); empty: none.
    figures : dict of str -> (Figure, caption)
        The figures by file stem (``fracid identify`` writes ``figures/<stem>.png``), in order.

    :meth:`png` renders a figure once: the report and figures/ share the bytes.
    """

    block: str
    heading: str
    text: str
    header: list = field(default_factory=list)
    rows: list = field(default_factory=list)
    figures: dict = field(default_factory=dict)
    _png: dict = field(default_factory=dict, repr=False)

    def png(self, stem: str) -> bytes:
        """The figure ``stem`` as PNG bytes (rendered on the first call)."""
        if stem not in self._png:
            self._png[stem] = to_png(self.figures[stem][0])
        return self._png[stem]


def field_view(name: str, coordinates: dict, measured, computed, std, control_label: str = "control [mm]") -> BlockView:
    """The report's view of a displacement-field block: summary and per-frame figures and a table per frame.

    Parameters
    ----------
    name : str
        The block's name.
    coordinates : dict
        The field observation's ``coordinates()`` (``control``, ``frame``, ``component``, ``point``, ``x``,
        ``y``), optionally with ``covariance`` (the block's data covariance, [mm^2]) or ``std`` (the noise std
        of every entry, [mm]); without either, ``std`` (the data's std) is used.
    measured, computed, std : array_like
        The block's measured and computed values and data std [mm].
    control_label : str
        The control axis label, e.g. ``"CMOD [mm]"``.
    """
    covariance = coordinates.get("covariance")
    noise_std = coordinates.get("std", std) if covariance is None else None
    fit = fit_field(coordinates["x"], coordinates["y"], coordinates["frame"], coordinates["component"], measured,
                    computed, std=noise_std, covariance=covariance, control=coordinates.get("control"),
                    point=coordinates.get("point"))
    control_name = control_label.rsplit(" [", 1)[0]
    stem = f"field_{file_stem(name)}"
    figures = {f"{stem}_summary": (summary_figure(fit, name=name, control_label=control_label),
                                         "Residual RMS per frame in noise stds (whitened by the data covariance; 1: "
                                         "the noise) and the rigid motion fitted per frame.")}
    for k in range(fit.n_frames):
        figures[f"{stem}_frame{k + 1}"] = (
            frame_figure(fit, k, name=name, control_name=control_name),
            f"Frame {k + 1}: measured displacement with the frame's fitted rigid motion removed, computed at the "
            "estimate, and their difference, in micrometres over the specimen's face (dots: the points).")
    header, rows = field_table(fit, control_name)
    return BlockView(name, f"Displacement field {name}", field_text(fit), header, rows, figures)


def file_stem(name: str) -> str:
    """``name`` fit for a file name: letters, digits, ``-`` and ``_`` kept, anything else ``_``."""
    return re.sub(r"[^A-Za-z0-9_-]", "_", str(name)) or "_"


def field_table(fit: FieldFit, control_name: str = "control") -> tuple[list, list]:
    """Header and rows (one per frame) of a field's fit: values, residual RMS [micrometre] and [noise std],
    rigid motion t_x, t_y [micrometre], theta [microradian]."""
    header = ["frame", f"{control_name} [mm]", "values", "RMS u_x [µm]", "RMS u_y [µm]", "RMS u_x [std]",
              "RMS u_y [std]", "RMS [std]", "t_x [µm]", "t_y [µm]", "theta [µrad]"]
    rows = [[k + 1, _cell(fit.controls[k], 4), int(fit.values[k]), _cell(UM * fit.rms_mm[k, 0]),
             _cell(UM * fit.rms_mm[k, 1]), _cell(fit.rms_std[k, 0]), _cell(fit.rms_std[k, 1]),
             _cell(fit.rms_std[k, 2]), _cell(UM * fit.motions[k, 0]), _cell(UM * fit.motions[k, 1]),
             _cell(URAD * fit.motions[k, 2])] for k in range(fit.n_frames)]
    return header, rows


def field_text(fit: FieldFit) -> str:
    """The paragraph under a field's heading: what the maps and the table show, and in which units."""
    noise = ("whitened by the data covariance of the frame (sqrt(r^T C^-1 r / n))" if fit.noise == "covariance"
             else "divided by the std of every value (independent errors)")
    return (f"{int(np.sum(fit.values))} values over {fit.n_frames} frames. Every frame's rigid-body motion (t_x, t_y, "
            "theta about the specimen's origin), which the identification marginalised, is fitted to the residual "
            "by generalised least squares and removed from the measured field, so the maps compare the deformation "
            f"with the model's. Maps and RMS in micrometres; RMS in noise stds {noise}: about 1 when the model "
            "follows the data within their noise.")


def _cell(value, digits: int = 3) -> str:
    return f"{value:.{digits}g}" if math.isfinite(value) else "n/a"


#: the view of a block by the ``kind`` of its coordinates: (name, coordinates, measured, computed, std,
#: control_label) -> BlockView. A later kind (a crack-opening profile fit) adds an entry here.
BLOCK_VIEWS = {"field": field_view}


def field_block_names(result, fields=None) -> set:
    """Names of the blocks that are not curves: those in ``fields`` and those whose quantity is a
    displacement field (:data:`FIELD_QUANTITIES`)."""
    quantities = list(getattr(result, "quantities", None) or [])
    named = {name for (name, _, _), q in zip(result_blocks(result), quantities) if q in FIELD_QUANTITIES}
    return named | set(fields or {})


def block_views(result, fields=None, control_label: str | None = None) -> list[BlockView]:
    """The views of the result's non-curve blocks, in the order of the blocks.

    Parameters
    ----------
    result : IdentificationResult
    fields : dict of str -> dict, optional
        Per block name, its coordinates (an observation kind's ``coordinates()``, plus ``kind``: a key of
        :data:`BLOCK_VIEWS`, ``"field"`` by default, and optionally ``covariance`` or ``std``).
    control_label : str, optional
        The control axis label; by default from the result's ``control_names``.

    A field block without coordinates (its quantity says it is a field) gets a view of text only: the maps
    need the points.
    """
    fields = fields or {}
    blocks = result_blocks(result)
    labels = block_control_labels(result, len(blocks), control_label)
    names = field_block_names(result, fields)
    y_exp, std = float_array(result.y_exp, np.nan), float_array(result.std_exp, np.nan)
    y_fit = float_array(result.y_fit, np.nan) if result.y_fit is not None else np.full_like(y_exp, np.nan)
    views = []
    for (name, start, stop), label in zip(blocks, labels):
        if name not in names:
            continue
        info = fields.get(name)
        if info is None or len(np.asarray(info["frame"])) != stop - start:
            views.append(BlockView(name, f"Displacement field {name}", _no_coordinates_text(name, info, stop - start)))
            continue
        view = BLOCK_VIEWS[info.get("kind", "field")]
        views.append(view(name, info, y_exp[start:stop], y_fit[start:stop], std[start:stop], label))
    return views


def block_views_and_skipped(result, fields=None, views=None, control_label: str | None = None) -> tuple[list, set]:
    """The views of the non-curve blocks (``views`` when given, else :func:`block_views`) and the names of the
    blocks the curve figure and table leave out (:func:`field_block_names` and the views' blocks)."""
    views = block_views(result, fields, control_label) if views is None else list(views)
    return views, field_block_names(result, fields) | {view.block for view in views}


def _no_coordinates_text(name: str, info, n: int) -> str:
    held = "not given" if info is None else f"given for {len(np.asarray(info['frame']))} values"
    return (f"Block {name!r} ({n} values) is a displacement field; its point coordinates are {held}, so it is not "
            "drawn (a field is no curve against the control). fracid identify draws its maps.")


__all__ = ["BLOCK_VIEWS", "BlockView", "FieldFit", "block_views", "block_views_and_skipped", "field_block_names",
           "field_table", "field_text", "field_view", "file_stem", "fit_field", "frame_figure", "frame_title",
           "hole_free_triangulation", "map_row_height", "summary_figure"]
