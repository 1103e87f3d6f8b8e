"""The camera frame placed on the specimen: a similarity transform, given or fitted from marked points.

Specimen coordinates [mm] of a camera point X (in camera units: mm or px)::

    x = s R(theta) (X - X0) + x0

with ``s`` the scale [mm per camera unit], ``theta`` the rotation [rad] (counter-clockwise), ``X0`` a point in
the camera frame and ``x0`` the same point in the specimen frame [mm]. Displacements are only rotated and
scaled: ``u = s R(theta) U``. A mirror image (a camera whose Y axis points down while the specimen's points up)
is not a similarity: negate the camera's Y column before (the fit says so when a mirror fits better).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from fracid.data.arguments import numeric_array, real_number
from fracid.data.errors import DataError

#: singular-value ratio below which marked points are taken as collinear
COLLINEAR_RATIO = 1e-8


def rotation_matrix(theta: float) -> np.ndarray:
    """The 2 x 2 counter-clockwise rotation by ``theta`` [rad]."""
    c, s = math.cos(theta), math.sin(theta)
    return np.array([[c, -s], [s, c]])


def planar_points(values, what: str) -> np.ndarray:
    """``values`` as a float array of shape (n, 2), finite, else a DataError naming ``what``."""
    array = numeric_array(values, what)
    if array.ndim != 2 or array.shape[1] != 2:
        raise DataError(f"{what} must have shape (n, 2) (x, y of each point), got shape {array.shape}")
    if not np.all(np.isfinite(array)):
        row = int(np.flatnonzero(~np.all(np.isfinite(array), axis=1))[0])
        raise DataError(f"{what}: row {row} is not finite ({array[row].tolist()})")
    return array


@dataclass(frozen=True)
class CameraPlacement:
    """The camera frame on the specimen, ``x = scale R(rotation) (X - origin_camera) + origin_specimen``.

    Parameters
    ----------
    scale : float
        Millimetres per camera unit (1 if the camera data are already in mm; e.g. 0.05 mm/px), > 0.
    rotation : float
        Angle [rad] of the camera axes in the specimen frame, counter-clockwise.
    origin_camera : (float, float)
        A point in the camera frame [camera units].
    origin_specimen : (float, float)
        The same point in the specimen frame [mm].
    fit_rms : float or None
        RMS residual [mm] of the marked points if the placement was fitted (:func:`fit_placement`), else None.
    notes : tuple of str
        How the placement was found (a fit, a large residual).
    """

    scale: float
    rotation: float = 0.0
    origin_camera: tuple = (0.0, 0.0)
    origin_specimen: tuple = (0.0, 0.0)
    fit_rms: float | None = None
    notes: tuple = ()

    def __post_init__(self):
        scale = real_number(self.scale, "scale")
        if not math.isfinite(scale) or scale <= 0.0:
            raise DataError(f"scale = {self.scale!r} [mm per camera unit]: give a finite number > 0")
        rotation = real_number(self.rotation, "rotation")
        if not math.isfinite(rotation):
            raise DataError(f"rotation = {self.rotation!r} [rad]: give a finite angle")
        object.__setattr__(self, "scale", scale)
        object.__setattr__(self, "rotation", rotation)
        for name in ("origin_camera", "origin_specimen"):
            point = planar_points(np.reshape(numeric_array(getattr(self, name), name), (1, -1)), name)[0]
            object.__setattr__(self, name, (float(point[0]), float(point[1])))
        object.__setattr__(self, "notes", tuple(self.notes))

    @property
    def matrix(self) -> np.ndarray:
        """``scale R(rotation)``: the 2 x 2 linear part [mm per camera unit]."""
        return self.scale * rotation_matrix(self.rotation)

    def to_specimen(self, points) -> np.ndarray:
        """Specimen coordinates [mm] of camera points (n, 2) [camera units]."""
        points = planar_points(points, "points")
        return (points - np.asarray(self.origin_camera)) @ self.matrix.T + np.asarray(self.origin_specimen)

    def displacements_to_specimen(self, u) -> np.ndarray:
        """Displacements [mm] in the specimen frame of camera displacements (..., 2) [camera units]: rotated
        and scaled, not shifted. NaN (missing) values stay NaN."""
        u = numeric_array(u, "u")
        if u.ndim == 0 or u.shape[-1] != 2:
            raise DataError(f"u must have a last axis of length 2 (U, V), got shape {u.shape}")
        return u @ self.matrix.T

    def to_camera(self, points) -> np.ndarray:
        """Camera coordinates [camera units] of specimen points (n, 2) [mm]: the inverse of :meth:`to_specimen`."""
        points = planar_points(points, "points")
        return (points - np.asarray(self.origin_specimen)) @ np.linalg.inv(self.matrix).T + np.asarray(self.origin_camera)

    def displacements_to_camera(self, u) -> np.ndarray:
        """Camera displacements [camera units] of specimen displacements (..., 2) [mm]: the inverse of
        :meth:`displacements_to_specimen`."""
        u = numeric_array(u, "u")
        if u.ndim == 0 or u.shape[-1] != 2:
            raise DataError(f"u must have a last axis of length 2 (u, v), got shape {u.shape}")
        return u @ np.linalg.inv(self.matrix).T

    def describe(self) -> str:
        """One line: the transform in words (for notes)."""
        return (f"camera -> specimen: scale {self.scale:.6g} mm per camera unit, rotation "
                f"{math.degrees(self.rotation):.6g} deg, camera point {self.origin_camera} at specimen point "
                f"{self.origin_specimen} mm")


def _check_spread(points: np.ndarray, what: str) -> None:
    """Refuse marked points that are coincident or collinear (no rotation and scale from them)."""
    centred = points - points.mean(axis=0)
    singular = np.linalg.svd(centred, compute_uv=False)
    if singular[0] == 0.0 or singular[1] <= COLLINEAR_RATIO * singular[0]:
        raise DataError(f"{what}: the {len(points)} marked points are collinear or coincident "
                        f"({points.tolist()}); give at least 3 points not on one line")


def _umeyama(camera: np.ndarray, specimen: np.ndarray) -> tuple[float, float, bool]:
    """Scale, rotation and whether a mirror image would fit better, of the least-squares similarity
    (Umeyama 1991) mapping centred ``camera`` points onto centred ``specimen`` points."""
    a = camera - camera.mean(axis=0)
    b = specimen - specimen.mean(axis=0)
    U, D, Vt = np.linalg.svd(b.T @ a / len(a))
    mirror = np.linalg.det(U) * np.linalg.det(Vt) < 0.0
    S = np.diag([1.0, -1.0 if mirror else 1.0])
    R = U @ S @ Vt
    scale = float(np.sum(D * np.diag(S)) / np.mean(np.sum(a * a, axis=1)))
    return scale, math.atan2(R[1, 0], R[0, 0]), bool(mirror)


def fit_placement(camera_points, specimen_points, *, max_rms: float | None = None) -> CameraPlacement:
    """The least-squares similarity transform (scale, rotation, origin) from marked points (Umeyama).

    Parameters
    ----------
    camera_points : array_like, shape (n, 2)
        The marked points in the camera frame [camera units], n >= 3, not collinear.
    specimen_points : array_like, shape (n, 2)
        The same points in the specimen frame [mm].
    max_rms : float or None
        RMS residual [mm] above which the fit gets a warning note; default 1 % of the RMS distance of the
        specimen points from their centroid.

    Returns
    -------
    CameraPlacement
        With ``fit_rms`` the RMS residual [mm] and ``notes`` on the fit (a warning if the residual is large).

    Raises
    ------
    DataError
        For fewer than 3 points, different counts, collinear or coincident points, or a scale <= 0.
    """
    camera = planar_points(camera_points, "camera_points")
    specimen = planar_points(specimen_points, "specimen_points")
    if len(camera) != len(specimen):
        raise DataError(f"camera_points has {len(camera)} points but specimen_points {len(specimen)}: give the "
                        "same marked points in both frames, in the same order")
    if len(camera) < 3:
        raise DataError(f"{len(camera)} marked points: the placement needs at least 3 points (not collinear)")
    _check_spread(camera, "camera_points")
    _check_spread(specimen, "specimen_points")
    scale, theta, mirror = _umeyama(camera, specimen)
    if scale <= 0.0:
        raise DataError("the fitted scale is not positive: the marked points do not match")
    placement = CameraPlacement(scale, theta, tuple(camera.mean(axis=0)), tuple(specimen.mean(axis=0)))
    residual = placement.to_specimen(camera) - specimen
    rms = float(np.sqrt(np.mean(np.sum(residual**2, axis=1))))
    spread = float(np.sqrt(np.mean(np.sum((specimen - specimen.mean(axis=0)) ** 2, axis=1))))
    limit = 0.01 * spread if max_rms is None else real_number(max_rms, "max_rms")
    notes = [f"placement fitted to {len(camera)} marked points: RMS residual {rms:.3g} mm; {placement.describe()}"]
    if rms > limit:
        worst = int(np.argmax(np.sum(residual**2, axis=1)))
        notes.append(f"WARNING: the RMS residual of the placement, {rms:.3g} mm, exceeds {limit:.3g} mm; the worst "
                     f"marked point is number {worst} (residual {np.hypot(*residual[worst]):.3g} mm): check the "
                     "marked points" + ("; a mirror image fits better: negate the camera's Y" if mirror else ""))
    return CameraPlacement(placement.scale, placement.rotation, placement.origin_camera, placement.origin_specimen,
                           fit_rms=rms, notes=tuple(notes))
