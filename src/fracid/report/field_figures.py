"""Maps of a displacement-field (DIC) block at the estimate: measured, computed and residual, frame by frame,
and the field's report view (:func:`field_view`, the view ``"displacement-field"`` of :data:`fracid.report.views.VIEWS`).

A field block (:class:`~fracid.inverse.core.field_observations.FieldObservation`) holds the displacement components at
points of the specimen's face and at frames (control values); drawn against the control like a curve it is a
cloud of thousands of points. Here every frame is a figure of maps over the face, and a summary figure follows
the fit along the frames; the fit itself, each frame's rigid motion removed, is :mod:`fracid.report.field_fit`'s.

Units: positions x, y [mm]; displacements and residuals on the maps [micrometre]; rigid translations
t_x, t_y [micrometre] and rotation theta [microradian] in the figures.
"""

from __future__ import annotations

import math

import numpy as np
from matplotlib.figure import Figure
from matplotlib.ticker import MaxNLocator
from matplotlib.tri import Triangulation

from fracid.report.block_view import BlockView, file_stem
from fracid.report.field_fit import COMPONENT_NAMES, UM, URAD, FieldFit, field_table, field_text, fit_field
from fracid.report.figures import COMPUTED, MEASURED, new_figure

#: a triangle with an edge longer than this many typical point spacings spans a hole and is not drawn
HOLE_EDGES = 2.0
#: colour map of the displacements and of the residuals (diverging, centred on 0)
DISPLACEMENT_MAP, RESIDUAL_MAP = "viridis", "RdBu_r"
#: filled contour levels of a map (at most)
LEVELS = 15
#: width of a frame's figure [in] (three maps a row)
MAP_WIDTH = 13.0


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
    stem = field_stem(name)
    figures = {f"{stem}_summary": (summary_figure(fit, name=name, control_label=control_label),
                                         "Residual RMS per frame in noise stds (whitened by the data covariance; 1: "
                                         "the noise) and the rigid motion fitted per frame.")}
    for k in range(fit.n_frames):
        figures[f"{stem}_frame{k + 1}"] = (
            frame_figure(fit, k, name=name, control_name=control_name),
            f"Frame {k + 1}: measured displacement with the frame's fitted rigid motion removed, computed at the "
            "estimate, and their difference, in micrometres over the specimen's face (dots: the points).")
    figures.update(local_figures(fit, stem, coordinates.get("crack"), control_label))
    if coordinates.get("placement") is not None:
        figures[f"{stem}_camera"] = (
            camera_figure(fit, coordinates["placement"], fit.n_frames - 1, coordinates.get("camera_unit", "px")),
            "The last frame's measured displacements (its rigid motion removed) in the camera's coordinates and "
            "units, as the DIC code showed them: a check of the placement.")
    if coordinates.get("sync") is not None:
        from fracid.report.sync_figure import synchronisation_figure

        figures[f"{stem}_sync"] = (synchronisation_figure(coordinates["sync"]),
                                   "The frames synchronised with the testing machine's log: marked on its load curve "
                                   "and, with their uncertainty, on its control over time.")
    header, rows = field_table(fit, control_name)
    return BlockView(name, field_heading(name), field_text(fit), header, rows, figures)


def local_figures(fit: FieldFit, stem: str, crack, control_label: str) -> dict:
    """The strain maps of every frame and, with the specimen's crack line, the opening profile and the
    process-zone width, measured and computed (:mod:`fracid.report.field_local`)."""
    from fracid.data.dic.strain import default_radius
    from fracid.report.field_local import local_data, local_figure, strain_figure

    radius = default_radius(np.column_stack([fit.x, fit.y]))
    figures = {}
    for k in range(fit.n_frames):
        figures[f"{stem}_strain_frame{k + 1}"] = (
            strain_figure(fit, k, radius, _strain_map, f"frame {k + 1} of {fit.n_frames}, "
                                                              f"{control_label.split(' [')[0]} {fit.controls[k]:.4g}"),
            f"Frame {k + 1}: the largest principal strain, measured and computed at the estimate by the same plane "
            f"fit within {radius:.3g} mm, and their difference (10⁻³).")
    if crack is not None:
        local = local_data(fit, crack, radius)
        figures[f"{stem}_local"] = (
            local_figure(fit, local, control_label),
            f"The crack-opening profile along the ligament (virtual extensometers over {2 * local['gauge']:.3g} mm) "
            "and the process-zone width per frame, measured (rigid motion removed) and computed, by the same "
            "estimators.")
    return figures


def camera_figure(fit: FieldFit, placement, k: int, unit: str = "px") -> Figure:
    """Frame ``k``'s measured displacements in the camera's coordinates and units (the placement inverted:
    :meth:`~fracid.data.dic.CameraPlacement.to_camera`), one map per component."""
    from fracid.report.field_local import frame_displacements

    points, measured, _ = frame_displacements(fit, k)
    camera = placement.to_camera(points)
    u = placement.displacements_to_camera(np.nan_to_num(measured))
    u[np.isnan(measured)] = np.nan
    fig = new_figure(MAP_WIDTH, map_row_height(camera[:, 0], camera[:, 1]) + 0.6)
    for ax, c in zip(fig.subplots(1, 2, squeeze=False)[0], (0, 1)):
        finite = np.isfinite(u[:, c])
        _map(fig, ax, camera[finite, 0], camera[finite, 1], u[finite, c], _levels(u[finite, c]), DISPLACEMENT_MAP,
             f"{'UV'[c]} [{unit}]")
        ax.set_xlabel(f"X [{unit}]")
        ax.set_ylabel(f"Y [{unit}]")
        ax.set_title(f"{'UV'[c]} measured, frame {k + 1}, in the camera's frame", fontsize=9)
    fig.suptitle(f"placement: {placement.describe()}", fontsize=9)
    return fig


def _strain_map(fig, ax, x, y, values, shared, label) -> None:
    """One strain map: the finite values, levels shared with ``shared`` (or centred on 0 when None)."""
    finite = np.isfinite(values)
    levels = _levels(shared[np.isfinite(shared)]) if shared is not None else _levels(values[finite], symmetric=True)
    _map(fig, ax, x[finite], y[finite], values[finite], levels, DISPLACEMENT_MAP if shared is not None else
         RESIDUAL_MAP, label)


#: the heading of a field block's section; its last word names the figures' files
HEADING = "Displacement field"
_NOUN = HEADING.split()[-1].lower()


def field_heading(name: str) -> str:
    """The report's heading of the field block ``name``: "Displacement field", and its name unless that is
    the heading's last word itself (not "Displacement field field")."""
    return HEADING if name.strip().lower() == _NOUN else f"{HEADING} {name}"


def field_stem(name: str) -> str:
    """The file-name stem of the field block ``name``'s figures: ``field_<name>``, or ``field`` for a block named
    "field" (not ``field_field``)."""
    stem = file_stem(name)
    return _NOUN if stem.lower() == _NOUN else f"{_NOUN}_{stem}"


__all__ = ["field_heading", "field_stem", "field_view", "frame_figure", "frame_title", "hole_free_triangulation", "map_row_height", "summary_figure"]
