"""The fit of a displacement-field (DIC) block at the estimate, frame by frame, with each frame's rigid motion
removed: what the field's report view (:mod:`fracid.report.field_figures`) draws and tabulates.

Every frame carries a rigid-body motion (the specimen settling on its supports) that the model, whose supports
are fixed, does not compute; the identification marginalises it in the data covariance
(:mod:`fracid.data.dic.rigid`). :func:`fit_field` estimates it afterwards, frame by frame, from the residual
(measured - computed) by generalised least squares (:func:`~fracid.data.dic.rigid.fit_rigid_motion`), so the
maps show the measured field with that motion removed, comparable with the model's.

Units: positions x, y [mm]; displacements, residuals and rigid translations [mm] and rotation [rad] in
:class:`FieldFit`; [micrometre] and [microradian] in the table (:func:`field_table`); residual RMS also in units
of the noise std: the whitened RMS sqrt(r^T C^-1 r / n) of the residual r with the rigid motion removed (about 1
when the model follows the data within their noise).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from fracid.report.figures import float_array

#: micrometres per millimetre (maps and rigid translations are drawn in micrometres)
UM = 1e3
#: microradians per radian
URAD = 1e6
#: names of the displacement components by index
COMPONENT_NAMES = ("u_x", "u_y")


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


__all__ = ["COMPONENT_NAMES", "UM", "URAD", "FieldFit", "field_table", "field_text", "fit_field"]
