"""Per-frame point clouds in the camera frame assembled into a :class:`~fracid.data.dic.data.DicData`.

Shared by the readers: the reference points checked equal in every frame, points of low correlation quality
set missing, camera units and axes placed on the specimen (:class:`~fracid.data.dic.placement.CameraPlacement`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from fracid.data.arguments import real_number
from fracid.data.dic.data import DicData
from fracid.data.dic.placement import CameraPlacement
from fracid.data.errors import DataError, DataTypeError

#: units of the camera coordinates
COORDINATE_UNITS = ("mm", "px")


@dataclass(frozen=True)
class FrameCloud:
    """One frame's point cloud as read, in the camera frame [camera units].

    Parameters
    ----------
    source : str
        The file.
    points : ndarray (n, 2)
        Reference coordinates X, Y.
    u : ndarray (n, 2)
        Displacements U, V (NaN if missing).
    rows : ndarray of int (n,)
        File row (line) of each point, for messages (the point's index for files without rows).
    std : ndarray (n,) or None
        Per-point displacement std (same unit), NaN if unknown.
    quality : ndarray (n,) or None
        Correlation quality (NaN: unknown, taken as missing when a threshold is set).
    """

    source: str
    points: np.ndarray
    u: np.ndarray
    rows: np.ndarray
    std: np.ndarray | None = None
    quality: np.ndarray | None = None


def check_options(coordinate_unit, placement, min_quality) -> tuple[CameraPlacement | None, float | None]:
    """The placement and quality threshold checked against the coordinate unit."""
    if coordinate_unit not in COORDINATE_UNITS:
        raise DataError(f"coordinate_unit = {coordinate_unit!r}: give one of {COORDINATE_UNITS}")
    if placement is not None and not isinstance(placement, CameraPlacement):
        raise DataTypeError(f"placement must be a CameraPlacement (see fit_placement) or None, got "
                            f"{type(placement).__name__}")
    if coordinate_unit == "px" and placement is None:
        raise DataError("coordinate_unit = 'px' needs a placement giving the scale in mm per px: "
                        "CameraPlacement(scale=...) or fit_placement(camera_points, specimen_points)")
    threshold = None if min_quality is None else real_number(min_quality, "min_quality")
    return placement, threshold


def check_same_points(reference: FrameCloud, cloud: FrameCloud, tolerance: float) -> None:
    """Refuse a frame whose reference points differ from the first frame's (count, or X, Y beyond
    ``tolerance`` [camera units]), naming the file, the row and the mismatch."""
    if len(cloud.points) != len(reference.points):
        raise DataError(f"{cloud.source}: {len(cloud.points)} points, but {reference.source} has "
                        f"{len(reference.points)}; every frame must hold the same reference points (a hole is a "
                        "NaN displacement, not a missing row)")
    distance = np.max(np.abs(cloud.points - reference.points), axis=1)
    bad = np.flatnonzero(distance > tolerance)
    if len(bad):
        i = int(bad[0])
        raise DataError(f"{cloud.source}: row {cloud.rows[i]}: reference point (X, Y) = "
                        f"{tuple(cloud.points[i].tolist())} differs from {tuple(reference.points[i].tolist())} of "
                        f"{reference.source} row {reference.rows[i]} by {distance[i]:.3g} (tolerance {tolerance:g}); "
                        f"{len(bad)} points differ: every frame must hold the same points in the same order")


def _low_quality(cloud: FrameCloud, threshold: float | None) -> np.ndarray:
    """Points of ``cloud`` whose quality is below the threshold or unknown (none without a threshold)."""
    if threshold is None or cloud.quality is None:
        return np.zeros(len(cloud.points), dtype=bool)
    with np.errstate(invalid="ignore"):
        return ~(cloud.quality >= threshold)


def assemble(clouds, frames, load, *, placement=None, coordinate_unit="mm", min_quality=None,
             point_tolerance=1e-6, notes=()) -> DicData:
    """The :class:`DicData` of per-frame clouds (see the module's description).

    Parameters
    ----------
    clouds : sequence of FrameCloud
        One per frame, in the order of ``frames``.
    frames : sequence of int
        Frame numbers.
    load : dict of str -> array
        Load data over frames.
    placement : CameraPlacement or None
        The camera frame on the specimen; None: the camera frame is the specimen frame (mm only).
    coordinate_unit : {"mm", "px"}
        Unit of the camera coordinates and displacements.
    min_quality : float or None
        Points of quality below it (or NaN) are set missing at that frame.
    point_tolerance : float
        Largest difference of X or Y between frames [camera units].
    notes : sequence of str
        Notes of the reader, kept first.
    """
    placement, threshold = check_options(coordinate_unit, placement, min_quality)
    tolerance = real_number(point_tolerance, "point_tolerance")
    if not clouds:
        raise DataError("no frames to read: the frame table or the list of files is empty")
    notes = list(notes)
    for cloud in clouds[1:]:
        check_same_points(clouds[0], cloud, tolerance)
    u = np.stack([cloud.u for cloud in clouds])
    for k, cloud in enumerate(clouds):
        low = _low_quality(cloud, threshold)
        if low.any():
            u[k, low] = np.nan
            notes.append(f"{cloud.source}: {int(low.sum())} of {len(low)} points with quality below {threshold:g} "
                         "(or none) set missing")
    has_std = any(cloud.std is not None for cloud in clouds)
    std = np.stack([np.full(len(c.points), np.nan) if c.std is None else c.std for c in clouds]) if has_std else None
    points = clouds[0].points
    if placement is not None:
        points, u = placement.to_specimen(points), placement.displacements_to_specimen(u)
        std = None if std is None else std * placement.scale
        notes.append(f"coordinates and displacements in {coordinate_unit} placed on the specimen in mm: "
                     f"{placement.describe()}")
        notes.extend(placement.notes)
    else:
        notes.append("no placement: the camera frame (mm) is taken as the specimen frame")
    std = None if std is None else np.repeat(std[:, :, None], 2, axis=2)
    return DicData(points, tuple(frames), u, std, load, tuple(cloud.source for cloud in clouds), tuple(notes))
