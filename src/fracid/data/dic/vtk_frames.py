"""Reader of DIC fields as VTU/VTK point data (through meshio): one file per frame.

Each file's points are the reference points (X, Y in the camera frame; a third coordinate is ignored) and a
point-data array holds the displacements (U, V, and a third component ignored); optional arrays give a
per-point std and a correlation quality. Units, placement and quality as in
:func:`fracid.data.dic.csv_frames.read_dic_frames`.
"""

from __future__ import annotations

import os

import numpy as np

from fracid.data.arguments import file_path
from fracid.data.dic.assemble import FrameCloud, assemble
from fracid.data.errors import DataError
from fracid.fem.mesh.meshio_files import UnreadableFile, meshio_read

#: displacement arrays tried in turn when no name is given
DISPLACEMENT_NAMES = ("displacement", "U")


def _read_mesh(path: str):
    """meshio's mesh of ``path`` (:func:`~fracid.fem.mesh.meshio_files.meshio_read`, the guard of meshio's
    errors and exits), with a missing, unreadable or truncated file named."""
    if not os.path.isfile(path):
        raise DataError(f"VTK file {path}: cannot be read (the file does not exist)")
    try:
        return meshio_read(path)
    except UnreadableFile as error:
        if error.os_error:
            raise DataError(f"VTK file {path}: cannot be read ({error.reason})") from None
        raise DataError(f"VTK file {path}: not a readable VTU/VTK file ({error.reason}); is it truncated, or of "
                        "another format?") from None


def _array(mesh, path: str, names: tuple, what: str) -> np.ndarray:
    """The first point-data array of ``names`` present, else a DataError naming the arrays found."""
    for name in names:
        if name in mesh.point_data:
            values = np.asarray(mesh.point_data[name], dtype=float)
            return values if values.ndim > 1 else values[:, None]
    found = ", ".join(repr(n) for n in mesh.point_data) or "none"
    raise DataError(f"VTK file {path}: no point-data array {' or '.join(map(repr, names))} ({what}); "
                    f"arrays found: {found}")


def read_vtk_cloud(path: str, displacement: str | None, sigma, quality) -> FrameCloud:
    """The point cloud of one VTU/VTK file: its points, the point-data array ``displacement`` (None: the first
    of :data:`DISPLACEMENT_NAMES`), and the arrays ``sigma`` and ``quality`` if named."""
    mesh = _read_mesh(path)
    points = np.asarray(mesh.points, dtype=float)[:, :2]
    u = _array(mesh, path, DISPLACEMENT_NAMES if displacement is None else (displacement,), "the displacements")
    if u.shape[1] < 2:
        raise DataError(f"VTK file {path}: the displacement array has {u.shape[1]} component; give U, V (2 or 3)")
    std = None if sigma is None else _array(mesh, path, (sigma,), "the displacement std")[:, 0]
    q = None if quality is None else _array(mesh, path, (quality,), "the correlation quality")[:, 0]
    if not np.all(np.isfinite(points)):
        raise DataError(f"VTK file {path}: point {int(np.flatnonzero(~np.isfinite(points).all(1))[0])} has a "
                        "non-finite reference coordinate")
    return FrameCloud(path, points, u[:, :2].copy(), np.arange(len(points)), std, q)


def read_dic_vtk(paths, frames, *, displacement=None, sigma=None, quality=None, min_quality=None,
                 coordinate_unit="mm", load=None, placement=None, point_tolerance=1e-6):
    """Read DIC fields from VTU/VTK files (one per frame), placed on the specimen.

    Parameters
    ----------
    paths : sequence of str or os.PathLike
        One file per frame.
    frames : sequence of int
        Frame numbers of the files.
    displacement : str or None
        Point-data array of the displacements; None: "displacement", else "U".
    sigma, quality : str or None
        Point-data arrays of the per-point std and of the correlation quality, if any.
    min_quality : float or None
        Points of quality below it (or NaN) are set missing at that frame (needs ``quality``).
    coordinate_unit : {"mm", "px"}
        Unit of the coordinates, displacements and std; "px" needs a ``placement``.
    load : dict of str -> array_like or None
        Load data over frames (e.g. ``{"cmod_mm": ..., "force_N": ...}``).
    placement : CameraPlacement or None
        The camera frame on the specimen; None: the camera frame is the specimen frame.
    point_tolerance : float
        Largest difference of X or Y of a point between files [camera units].

    Returns
    -------
    DicData

    Raises
    ------
    DataError
        For a missing or unreadable file, a missing array (naming the arrays found), files with different
        points, or as many frames as files not given. The "row" of a point in messages is its index.
    """
    paths = [file_path(p) for p in ([paths] if isinstance(paths, str) else paths)]
    frames = list(frames)
    if len(frames) != len(paths):
        raise DataError(f"{len(paths)} files but {len(frames)} frame numbers: give one frame number per file")
    if min_quality is not None and quality is None:
        raise DataError("min_quality is given but no quality array: give quality = the array's name")
    clouds = [read_vtk_cloud(path, displacement, sigma, quality) for path in paths]
    return assemble(clouds, frames, dict(load or {}), placement=placement, coordinate_unit=coordinate_unit,
                    min_quality=min_quality, point_tolerance=point_tolerance)
