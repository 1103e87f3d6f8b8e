"""Reader of DIC exports as CSV: a frame table and one point cloud per frame (DICe-like tools).

The frame table (e.g. ``frames.csv``) has a column of frame numbers (integers), a column of point-cloud files
(relative to the table) and the load data of each frame (e.g. ``cmod_mm``, ``force_N``). Each point cloud has
a header row and the columns X, Y (reference coordinates in the camera frame), U, V (displacements in the
camera frame), optionally a per-point displacement std and a correlation quality; the unit of all of them is
``coordinate_unit`` ("mm" or "px"). A missing displacement, std or quality is an empty cell, ``NaN`` or
``nan``; the reference coordinates must be numbers. Every frame holds the same points in the same order.
A frame table may also list VTU/VTK files (``.vtu``, ``.vtk``: read by
:func:`fracid.data.dic.vtk_frames.read_vtk_cloud`, the displacement array named by ``displacement``).
The CSV cells are read by :mod:`fracid.data.table` (its separators, comments above the header, messages).
"""

from __future__ import annotations

import math
import os
from dataclasses import replace

import numpy as np

from fracid.data.arguments import column_name, file_path
from fracid.data.cells import check_cell_count, parse_cell
from fracid.data.dic.assemble import FrameCloud, assemble
from fracid.data.dic.vtk_frames import read_vtk_cloud
from fracid.data.errors import DataError
from fracid.data.table import check_format, column_indices, parse_table, read_table
from fracid.settings.checks import show

#: cells read as a missing value in the columns that may have holes
MISSING_CELLS = ("", "nan")


def _table(path: str, columns: list[str], what: str, delimiter: str = ",", decimal: str = "."):
    """:func:`read_table` of ``path`` with an unreadable or missing file named, as ``what``."""
    try:
        return read_table(path, delimiter, decimal, columns=columns)
    except OSError as error:
        raise DataError(f"{what} {path}: cannot be read ({error.strerror or error})") from None


def _holey_columns(table, names: list[str], indices: list[int], delimiter: str = ",", decimal: str = ".") -> np.ndarray:
    """Values (n_rows, n_columns) of columns that may have holes: an empty cell or NaN is NaN."""
    values = np.empty((len(table.rows), len(names)))
    for r, (line, cells) in enumerate(table.rows):
        check_cell_count(table.path, line, cells, table.header, delimiter, decimal)
        for c, (name, index) in enumerate(zip(names, indices)):
            text = cells[index].strip() if index < len(cells) else ""
            values[r, c] = (math.nan if text.lower() in MISSING_CELLS
                            else parse_cell(table.path, line, name, text, decimal, delimiter))
    return values


def read_cloud(path: str, columns: dict, delimiter: str = ",", decimal: str = ".",
               failed_sigma: bool = False) -> FrameCloud:
    """One frame's point cloud; ``columns`` maps "x", "y", "u", "v" and optionally "sigma", "quality" to the
    file's column names (None: absent); cells separated by ``delimiter``, numbers with the ``decimal`` mark.
    ``failed_sigma``: a negative sigma marks a failed point (its values set missing; DICe's SIGMA = -1), else it
    is refused."""
    wanted = {key: name for key, name in columns.items() if name is not None}
    table = _table(path, list(wanted.values()), "point cloud", delimiter, decimal)
    indices = dict(zip(wanted, column_indices(table, list(wanted.values()), delimiter)))
    xy, rows = parse_table(table, [wanted["x"], wanted["y"]], [indices["x"], indices["y"]], decimal, delimiter)
    if len(rows) == 0:
        raise DataError(f"{path}: no data rows below the header (line {table.header_line})")
    holey = [key for key in ("u", "v", "sigma", "quality") if key in wanted]
    values = _holey_columns(table, [wanted[k] for k in holey], [indices[k] for k in holey], delimiter, decimal)
    by_key = dict(zip(holey, values.T))
    sigma = by_key.get("sigma")
    if sigma is not None and failed_sigma:
        failed = sigma < 0.0
        for key in ("u", "v", "sigma"):
            by_key[key] = np.where(failed, np.nan, by_key[key])
        sigma = by_key["sigma"]
    if sigma is not None and np.any(sigma < 0.0):
        r = int(np.flatnonzero(sigma < 0.0)[0])
        raise DataError(f"{path}: row {rows[r]}, column {show(wanted['sigma'])}: {sigma[r]:g} is negative; a "
                        "standard deviation is >= 0")
    return FrameCloud(path, xy, np.column_stack([by_key["u"], by_key["v"]]), rows, sigma, by_key.get("quality"))


def read_frame_table(path: str, frame_column: str, file_column: str, load_columns, delimiter: str = ",",
                     decimal: str = ".") -> tuple:
    """Frame numbers, point-cloud paths (resolved against the table's folder) with their table rows, and the
    load columns of the frame table (all other columns if ``load_columns`` is None)."""
    requested = [frame_column, file_column, *(load_columns or [])]
    table = _table(path, requested, "frame table", delimiter, decimal)
    if load_columns is None:
        load_columns = [name for name in table.header if name not in (frame_column, file_column)]
    names = [frame_column, *load_columns]
    file_index, *numeric = column_indices(table, [file_column, *names], delimiter)
    values, rows = parse_table(table, names, numeric, decimal, delimiter)
    if len(rows) == 0:
        raise DataError(f"{path}: the frame table has no data rows below the header (line {table.header_line})")
    frames = []
    for line, number in zip(rows, values[:, 0]):
        if number != int(number):
            raise DataError(f"{path}: row {line}, column {show(frame_column)}: {number:g} is not an integer frame number")
        frames.append(int(number))
    folder = os.path.dirname(path)
    files = []
    for line, cells in table.rows:
        name = cells[file_index].strip()
        if not name:
            raise DataError(f"{path}: row {line}, column {show(file_column)}: empty cell; give the point-cloud file")
        files.append((os.path.join(folder, name), line))
    load = {name: values[:, 1 + k] for k, name in enumerate(load_columns)}
    return frames, files, load, table.notes()


def read_dic_frames(table_path, *, x="X", y="Y", u="U", v="V", sigma=None, quality=None, min_quality=None,
                    coordinate_unit="mm", load_columns=None, placement=None, frame_column="frame",
                    file_column="file", point_tolerance=1e-6, displacement=None, delimiter=",", decimal=".",
                    failed_sigma=False):
    """Read a DIC export: a frame table and the point cloud of every frame, placed on the specimen.

    Parameters
    ----------
    table_path : str or os.PathLike
        The frame table (CSV).
    x, y, u, v : str
        Column names of the reference coordinates and displacements in the point clouds.
    sigma, quality : str or None
        Column names of the per-point displacement std and of the correlation quality, if any.
    min_quality : float or None
        Points of quality below it (or without one) are set missing at that frame (needs ``quality``).
    coordinate_unit : {"mm", "px"}
        Unit of X, Y, U, V and sigma; "px" needs a ``placement`` with the scale [mm/px].
    load_columns : sequence of str or None
        Load columns of the frame table (e.g. ``["cmod_mm", "force_N"]``); None: all but frame and file.
    placement : CameraPlacement or None
        The camera frame on the specimen (:func:`~fracid.data.dic.placement.fit_placement`); None: the camera
        frame is the specimen frame.
    frame_column, file_column : str
        Column names of the frame number and of the point-cloud file in the frame table.
    point_tolerance : float
        Largest difference of X or Y of a point between frames [camera units].
    displacement : str or None
        For frames in VTU/VTK files: the point-data array of the displacements (None: "displacement", else
        "U"); ``sigma`` and ``quality`` then name point-data arrays, ``x``, ``y``, ``u``, ``v`` are not used.
    delimiter, decimal : str
        Cell separator and decimal mark of the frame table and the CSV point clouds
        (:func:`fracid.data.table.check_format`): a European export reads with ``";"`` and ``","``.
    failed_sigma : bool
        A negative sigma marks a failed point, set missing at that frame and counted in a note (DICe's SIGMA =
        -1: :mod:`fracid.data.dic.formats`); False: a negative sigma is refused.

    Returns
    -------
    DicData
        Points and displacements in the specimen frame [mm], ``std`` [mm] if ``sigma`` is given.

    Raises
    ------
    DataError
        Naming the file, row, column and value: a missing file or column, a value that is not a number,
        frames with different points, a frame number that is not an integer.
    """
    table_path = file_path(table_path)
    delimiter, decimal = check_format(delimiter, decimal)
    columns = {"x": x, "y": y, "u": u, "v": v, "sigma": sigma, "quality": quality}
    for key, name in columns.items():
        if name is not None or key in "xyuv":
            column_name(name, key)
    if min_quality is not None and quality is None:
        raise DataError("min_quality is given but no quality column: give quality = the column's name")
    if load_columns is not None:
        load_columns = [column_name(name, f"load_columns[{k}]") for k, name in enumerate(load_columns)]
    frames, files, load, notes = read_frame_table(table_path, column_name(frame_column, "frame_column"),
                                                  column_name(file_column, "file_column"), load_columns, delimiter,
                                                  decimal)
    clouds = []
    for path, line in files:
        if not os.path.isfile(path):
            raise DataError(f"{table_path}: row {line}, column {show(file_column)}: the point-cloud file {path} does "
                            "not exist (paths are relative to the frame table's folder)")
        vtk = path.lower().endswith((".vtu", ".vtk"))
        clouds.append(read_vtk_cloud(path, displacement, sigma, quality) if vtk
                      else read_cloud(path, columns, delimiter, decimal, failed_sigma))
    if failed_sigma and sigma is not None:
        failed = [int(np.count_nonzero(np.isnan(c.std))) if c.std is not None else 0 for c in clouds]
        notes = (*notes, f"{sum(failed)} of {sum(len(c.points) for c in clouds)} point values over {len(clouds)} "
                 f"frames dropped: failed correlation (sigma < 0 in column {show(sigma)}); per frame {failed}")
    data = assemble(clouds, frames, load, placement=placement, coordinate_unit=coordinate_unit,
                    min_quality=min_quality, point_tolerance=point_tolerance, notes=notes)
    return replace(data, source=(table_path, *data.source))
