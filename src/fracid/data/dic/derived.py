"""Local data derived from a DIC displacement field: the crack-opening profile and the process-zone width.

:func:`opening_profile` (virtual extensometers across the crack, the crack-opening profile w(y) [mm]) and
:func:`process_zone_width` (the width [mm] of the zone where the strain normal to the crack exceeds a
threshold) apply an estimator of :mod:`fracid.data.dic.estimators` to the normal displacement u_n of every
frame of a field block (:func:`derived_block`: the values, their covariance J C J^T, J the estimator's
Jacobian over the field's entries and C the field's covariance). The same estimator is applied to the
model's displacements at the same points by
:class:`~fracid.inverse.core.derived_observations.DerivedFieldObservation` (exact sensitivities by the chain
rule), so data and model are processed identically: the estimator's smoothing biases neither. The
conventions (crack line, signed offsets, pairs or a symmetric half): :mod:`fracid.data.dic.estimators`.

Rigid motion: a rigid motion u = t + theta (-y, x) is a linear field, which the plane fit reproduces
exactly. A strain is its gradient normal to the crack: 0 for every rigid motion, so the width is free of
it. A pair of ends at the same height sees the same u_n = t_x - theta y: the difference removes it
exactly. On a half, 2 u_n(+d) carries 2 (t_x - theta y) of the data's rigid motion, which the model
(fixed supports) does not have: give ``rigid_motion`` (per frame, e.g. from :func:`frame_rigid_motions`
of a field residual, subtracted from the data's displacements before the estimate, taken as exact), or
build the field block with ``rigid_std`` (its covariance then carries the rigid motion, and so does the
opening's W C W^T: the profile's mean and tilt in y become uninformative at each frame), or state that the
data have none (the camera referenced to the supports).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from fracid.data.arguments import numeric_array
from fracid.data.covariance import unusable_variances
from fracid.data.covariance_matrix import Dense
from fracid.data.dataset import ExperimentalData
from fracid.data.dic.estimators import Extensometers, StrainTransects
from fracid.data.dic.field import FieldBlock
from fracid.data.dic.rigid import fit_rigid_motion, rigid_modes
from fracid.data.errors import DataError
from fracid.specimens.crack_line import CrackLine, crack_line


@dataclass(frozen=True, eq=False)
class DerivedBlock:
    """A derived data block and what its model-side observation needs.

    Attributes
    ----------
    data : ExperimentalData
        One block of n_frames x estimator.size values (frame slowest, height fastest), their covariance
        J C J^T and the frame's control value of every entry [mm].
    estimator : Extensometers or StrainTransects
        The estimator applied to u_n at the points.
    points : ndarray (n_points, 2)
        The field's DIC points [mm] (specimen frame).
    frames : ndarray (n_frames,)
        Control value of each frame [mm].
    present : ndarray of bool (n_frames, n_points)
        The points with a u_n value at each frame (the estimator used these only).
    jacobian : ndarray (n_y, field.data.n_y)
        d y / d (the field's values) at the data: the estimate's weights W for the opening profile (y = W u),
        the linearisation J for the width; the covariance is J C J^T.
    """

    data: ExperimentalData
    estimator: object
    points: np.ndarray
    frames: np.ndarray
    present: np.ndarray
    jacobian: np.ndarray


def field_normals(field: FieldBlock, normal: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The normal component u_n of a field block per frame.

    Returns
    -------
    values : ndarray (n_frames, n_points)
        u_n [mm], NaN where missing.
    present : ndarray of bool (n_frames, n_points)
    entry : ndarray of int (n_frames, n_points)
        Position of each value in ``field.data.y`` (-1 where missing).
    """
    if normal not in field.components:
        raise DataError(f"the field block has components {list(field.components)}; the crack's normal "
                        f"displacement (component {normal}: {'uv'[normal]}) is needed: include {'uv'[normal]!r}")
    shape = (len(field.frames), len(field.components), len(field.points))
    entry = np.full(field.keep.size, -1)
    entry[field.keep] = np.arange(int(field.keep.sum()))
    entry = entry.reshape(shape)[:, field.components.index(normal)]
    present = entry >= 0
    values = np.where(present, field.data.y[np.maximum(entry, 0)], np.nan)
    return values, present, entry


def _rigid_per_frame(rigid_motion, n_frames: int) -> np.ndarray:
    """``rigid_motion`` ((3,) or (n_frames, 3)) broadcast to one finite row per frame, or a DataError."""
    motion = numeric_array(rigid_motion, "rigid_motion")
    if motion.shape not in ((3,), (n_frames, 3)) or not np.all(np.isfinite(motion)):
        raise DataError(f"rigid_motion has shape {motion.shape}; give (t_x [mm], t_y [mm], theta [rad]) or one such "
                        f"row per frame, shape ({n_frames}, 3), finite")
    return np.broadcast_to(motion, (n_frames, 3))


def derived_block(field: FieldBlock, estimator, *, name: str, rigid_motion=None, notes=()) -> DerivedBlock:
    """The data block of ``estimator`` applied to a DIC field block, with its covariance by linearisation.

    Parameters
    ----------
    field : FieldBlock
        From :func:`fracid.data.dic.field_block` (with the crack's normal component).
    estimator : Extensometers or StrainTransects
        What is derived from u_n at each frame.
    name : str
        Name of the block.
    rigid_motion : array_like, shape (3,) or (n_frames, 3), optional
        (t_x [mm], t_y [mm], theta [rad]) of every frame, subtracted from the data's u_n first (taken as
        exact); None: none subtracted.
    notes : sequence of str
        What to record about the estimator.

    Returns
    -------
    DerivedBlock
        y = f(u_n) per frame; covariance J C J^T [mm^2] with J = d f / d u over the field's entries and C
        the field's covariance (exact for a linear f: the opening profile).

    Raises
    ------
    DataError
        A field without the normal component, too few points near an estimate, a bad ``rigid_motion``, or
        a value with no variance (a width with no strain above the threshold at a frame).
    """
    line = estimator.line
    values, present, entry = field_normals(field, line.normal)
    n_frames, m = len(field.frames), estimator.size
    applied = ()
    if rigid_motion is not None:
        motion = _rigid_per_frame(rigid_motion, n_frames)
        values = values - motion @ rigid_modes(field.points, [line.normal]).T
        applied = (f"rigid motion subtracted from u_{'xy'[line.normal]} at every frame: "
                   f"{np.round(motion, 8).tolist()} (t_x mm, t_y mm, theta rad)",)
    y = np.empty(n_frames * m)
    W = np.zeros((n_frames * m, field.data.n_y))
    for k in range(n_frames):
        try:
            y[k * m:(k + 1) * m], J = estimator.evaluate(field.points, present[k], values[k])
        except DataError as error:
            raise DataError(f"{name!r}, frame at control {field.frames[k]:.6g} mm: {error}") from None
        W[k * m:(k + 1) * m, entry[k, present[k]]] = J[:, present[k]]
    used = np.flatnonzero(np.any(W != 0.0, axis=0))
    covariance = (W[:, used] @ field.data.covariance.take(used).dense() @ W[:, used].T if used.size
                  else np.zeros((y.size, y.size)))
    covariance = 0.5 * (covariance + covariance.T)  # symmetric to rounding (a large rigid-motion prior breaks it)
    variance = np.diag(covariance)
    unusable = unusable_variances(variance)
    if np.any(unusable):
        i = int(np.argmax(unusable))
        raise DataError(f"{name!r}: the value at height {estimator.heights[i % m]:g} mm, frame at control "
                        f"{field.frames[i // m]:.6g} mm has no variance ({variance[i]:.3g} mm^2, not a positive normal "
                        "number: it does not depend on the data, e.g. a width with at most one sample above the "
                        "threshold, or the field's std is too small); leave that frame out or lower the threshold")
    data = ExperimentalData(control=np.repeat(field.frames, m), y=y, covariance=Dense(covariance),
                            blocks=((name, 0, y.size),),
                            notes=(*field.data.notes, *notes, *applied,
                                   f"{name!r}: covariance J C J^T from the field's covariance over the {used.size} "
                                   "values the estimates use"))
    W.setflags(write=False)
    return DerivedBlock(data, estimator, field.points, field.frames, present, W)


def _sides(field: FieldBlock, line: CrackLine, pairs) -> bool:
    """``pairs`` or, if None, whether the field has points on both sides of the crack line."""
    if pairs is not None:
        return bool(pairs)
    return bool(np.any(line.offsets(field.points) < 0))


def opening_profile(field: FieldBlock, specimen, heights, gauge: float, *, radius: float, pairs: bool | None = None,
                    rigid_motion=None, name: str = "opening") -> DerivedBlock:
    """The crack-opening profile of a DIC field: virtual extensometers across the crack along the ligament.

    Parameters
    ----------
    field : FieldBlock
        The DIC field block (:func:`fracid.data.dic.field_block`, with u: the crack's normal component).
    specimen
        The specimen (or its description): its crack line (:func:`crack_line`).
    heights : array_like
        Positions of the gauges along the ligament [mm], increasing, within the crack path.
    gauge : float
        Half-length d of the gauges [mm], larger than the band of missing points near the crack.
    radius : float
        Radius of the plane fit around each gauge end [mm].
    pairs : bool, optional
        Ends on both sides (w = u_n(+d) - u_n(-d), rigid motion removed) or one (w = 2 u_n(+d), the symmetric
        half); None: pairs if the field has points on both sides of the crack line.
    rigid_motion : array_like, shape (3,) or (n_frames, 3), optional
        Rigid motion subtracted from the data first (on a half: see the module's conventions).
    name : str
        Name of the block.

    Returns
    -------
    DerivedBlock
        w [mm] at every frame and height (frame slowest), covariance W C W^T [mm^2].

    Raises
    ------
    ValueError
        Heights outside the ligament, gauge or radius <= 0 (named); DataError: no points near a gauge end
        (the end named), no normal component.
    """
    line = crack_line(specimen)
    estimator = Extensometers(line, heights, gauge, radius, _sides(field, line, pairs))
    form = ("u_n(+d) - u_n(-d) (both sides: the rigid motion cancels)" if estimator.pairs else
            "2 u_n(+d) (symmetric half: the data's rigid motion adds 2 (t_x - theta y), unless subtracted with "
            "rigid_motion; a field covariance with rigid_std carries it into W C W^T)")
    note = (f"{name!r}: crack-opening profile by virtual extensometers of half-length {estimator.gauge:g} mm at "
            f"heights {estimator.heights.tolist()} mm, w = {form}, u_n at each end by a plane fit over the points "
            f"within {estimator.radius:g} mm")
    return derived_block(field, estimator, name=name, rigid_motion=rigid_motion, notes=(note,))


def process_zone_width(field: FieldBlock, specimen, heights, offsets, *, radius: float, threshold: float,
                       name: str = "fpz_width") -> DerivedBlock:
    """The process-zone width of a DIC field: the spread of the strain above ``threshold`` across the crack.

    Parameters
    ----------
    field : FieldBlock
        The DIC field block (with the crack's normal component).
    specimen
        The specimen (or its description).
    heights : array_like
        Positions of the transects along the ligament [mm].
    offsets : array_like
        Signed distances of each transect's samples from the crack line [mm] (:class:`StrainTransects`).
    radius : float
        Radius of the plane fit giving the strain at each sample [mm].
    threshold : float
        Strain above which a sample counts [-].
    name : str
        Name of the block.

    Returns
    -------
    DerivedBlock
        w [mm] at every frame and height; covariance J C J^T [mm^2] by linearisation at the data.

    Raises
    ------
    ValueError, DataError
        As :func:`opening_profile`; a frame where no sample exceeds the threshold (no variance).
    """
    estimator = StrainTransects(crack_line(specimen), heights, offsets, radius, threshold)
    note = (f"{name!r}: process-zone width 2 sqrt(3) std of max(eps - {estimator.threshold:g}, 0)^2 over offsets "
            f"{estimator.offsets.tolist()} mm at heights {estimator.heights.tolist()} mm, eps = du_n/dx_n by a plane "
            f"fit over the points within {estimator.radius:g} mm; covariance linearised at the data")
    return derived_block(field, estimator, name=name, notes=(note,))


def frame_rigid_motions(field: FieldBlock, model) -> np.ndarray:
    """The rigid motion of every frame of a field block's residual (data minus ``model``), by generalised
    least squares (:func:`fracid.data.dic.rigid.fit_rigid_motion` with the frame's covariance).

    Parameters
    ----------
    field : FieldBlock
    model : array_like, shape (field.data.n_y,)
        The model's values of the block's entries [mm] (e.g. the field observation's at an estimate).

    Returns
    -------
    ndarray (n_frames, 3)
        (t_x [mm], t_y [mm], theta [rad]) of every frame, for ``rigid_motion`` of :func:`opening_profile`.
    """
    model = np.asarray(model, float)
    if model.shape != field.data.y.shape:
        raise DataError(f"model has shape {model.shape}; give the model's value of every entry of the field block, "
                        f"shape {field.data.y.shape}")
    n = len(field.components) * len(field.points)
    residual = np.full(field.keep.size, np.nan)
    residual[field.keep] = field.data.y - model
    position = np.cumsum(field.keep) - 1  # entry of each kept value
    motions = []
    for k in range(len(field.frames)):
        kept = field.keep[k * n:(k + 1) * n]
        covariance = field.data.covariance.take(position[k * n:(k + 1) * n][kept])
        motions.append(fit_rigid_motion(field.points, field.components, residual[k * n:(k + 1) * n], covariance)[0])
    return np.array(motions)


__all__ = ["DerivedBlock", "derived_block", "field_normals", "frame_rigid_motions", "opening_profile",
           "process_zone_width"]
