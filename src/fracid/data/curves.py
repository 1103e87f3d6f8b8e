"""Measured curves (control quantity, force): the :class:`Curve`, and the curves of arrays or of a CSV file.

A :class:`Curve` always has a strictly increasing control quantity [mm] and a force [N]. Files are read by
:func:`read_curve_csv`, which names the file, the row and the column of every defect it finds; arrays by
:func:`curve_from_arrays`. Both apply the checks of :mod:`fracid.data.checks`: the sign and direction of the
control, then the backtracking rule (the only point-dropping rule, always reported in ``Curve.notes``).
How a file is read (separators, decimal marks, thousands separators, lines above the header, encodings) is
described in :mod:`fracid.data.table` and :mod:`fracid.data.cells`.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from fracid.data.arguments import (
    column_name,
    file_path,
    force_column_names,
    integer_at_least,
    readonly_vector,
    unit_scale,
)
from fracid.data.checks import Labels, checked_curve
from fracid.data.errors import DataError
from fracid.data.table import CsvTable, check_format, column_indices, parse_table, read_table
from fracid.settings.checks import show

__all__ = ["Curve", "curve_from_arrays", "read_curve_csv"]


@dataclass(frozen=True, eq=False)
class Curve:
    """One measured (or simulated) curve: force against a strictly increasing control quantity.

    Parameters
    ----------
    control : array_like, shape (n,)
        Control quantity [mm] (CMOD, deflection, elongation, ...), strictly increasing.
    force : array_like, shape (n,)
        Force [N] at each control value.
    source : str
        Where the curve comes from (file and columns), used in messages and notes.
    notes : tuple of str
        Every rule applied while reading (points dropped, unit scaling).

    Raises
    ------
    DataError
        If the arrays differ in length, hold fewer than 2 points or non-finite values, or if the
        control does not increase strictly (use :func:`curve_from_arrays` to apply the backtracking rule).
    """

    control: np.ndarray
    force: np.ndarray
    source: str = "arrays"
    notes: tuple[str, ...] = ()

    def __post_init__(self):
        control = readonly_vector(self.control, f"control of curve {self.source!r}")
        force = readonly_vector(self.force, f"force of curve {self.source!r}")
        if control.shape != force.shape:
            raise DataError(
                f"curve {self.source!r}: control has {control.size} values but force has {force.size}"
            )
        if control.size < 2:
            raise DataError(f"curve {self.source!r}: needs at least 2 points, got {control.size}")
        steps = np.diff(control)
        if np.any(steps <= 0.0):
            i = int(np.flatnonzero(steps <= 0.0)[0])
            raise DataError(
                f"curve {self.source!r}: control must increase strictly, but value {i + 1} "
                f"({float(control[i + 1]):.6g} mm) does not exceed value {i} ({float(control[i]):.6g} mm); "
                "curve_from_arrays() applies the documented backtracking rule"
            )
        notes = tuple(str(note) for note in self.notes)
        object.__setattr__(self, "control", control)
        object.__setattr__(self, "force", force)
        object.__setattr__(self, "source", str(self.source))
        object.__setattr__(self, "notes", notes)

    @property
    def n_points(self) -> int:
        """Number of points."""
        return int(self.control.size)

    @property
    def control_range(self) -> tuple[float, float]:
        """(first, last) control value [mm]."""
        return float(self.control[0]), float(self.control[-1])

    def peak(self) -> tuple[float, float]:
        """Control value [mm] and force [N] at the maximum force (first occurrence)."""
        i = int(np.argmax(self.force))
        return float(self.control[i]), float(self.force[i])


def curve_from_arrays(control, force, *, source: str = "arrays", backtrack_tolerance: float | None = None) -> Curve:
    """Build a :class:`Curve` from arrays, applying the checks of :mod:`fracid.data.checks`.

    Parameters
    ----------
    control : array_like, shape (n,)
        Control quantity [mm], increasing up to noise.
    force : array_like, shape (n,)
        Force [N].
    source : str
        Description used in messages and notes.
    backtrack_tolerance : float, optional
        Largest backtrack [mm] treated as noise; default 1 % of the control range.

    Returns
    -------
    Curve
        With the backtracking points dropped and reported in ``notes`` (indices 0-based).

    Raises
    ------
    DataTypeError
        If an array holds something else than numbers, or ``backtrack_tolerance`` is not a number.
    DataError
        If the arrays are not one-dimensional, differ in length or hold non-finite values; if the control
        is negative, decreases throughout, looks like the force (see :func:`read_curve_csv`) or goes
        backwards by more than the tolerance.
    """
    source = str(source)
    c = readonly_vector(control, f"control of {source!r}")
    f = readonly_vector(force, f"force of {source!r}")
    if c.shape != f.shape:
        raise DataError(f"{source!r}: control has {c.size} values but force has {f.size}")
    if c.size < 2:
        raise DataError(f"{source!r}: needs at least 2 points, got {c.size}")
    labels = Labels(repr(source), "'control'", ("'force'",), "index")
    keep, notes = checked_curve(c, f[:, None], np.arange(c.size), backtrack_tolerance, labels)
    return Curve(control=c[keep], force=f[keep], source=source, notes=notes)


def read_curve_csv(
    path: str | os.PathLike,
    *,
    control_column: str,
    force_columns: str | Sequence[str],
    control_unit_scale: float = 1.0,
    force_unit_scale: float = 1.0,
    delimiter: str = ",",
    decimal: str = ".",
    min_points: int = 10,
    backtrack_tolerance: float | None = None,
) -> list[Curve]:
    """Read force-control curves from a CSV file with a header row.

    Several force columns sharing one control column (repeated tests sampled at the same control
    values) give one curve each; for one file per repeat, call this once per file and join the lists.

    Parameters
    ----------
    path : str or path-like
        CSV file; the header is the first line naming the requested columns (lines above it skipped,
        see :mod:`fracid.data.table`), else the first line neither blank nor a comment.
    control_column : str
        Header name of the control quantity (CMOD, deflection, elongation, ...).
    force_columns : str or sequence of str
        Header name(s) of the force column(s).
    control_unit_scale : float
        Multiplier turning the control column into mm (e.g. 1e-3 for um); non-zero, negative to negate a
        control recorded with a negative sign (e.g. -1). No unit is guessed.
    force_unit_scale : float
        Multiplier turning the force column(s) into N (e.g. 1e3 for kN); non-zero, negative to negate.
    delimiter : str
        Cell separator: ``","`` (default), ``";"``, ``"\\t"``, or ``" "`` for any run of spaces and
        tabs. A header read as one cell holding another separator is reported as such.
    decimal : {".", ","}
        Decimal mark of the numbers; ``","`` (e.g. ``0,001``) needs a delimiter other than ``","``.
    min_points : int
        Fewest data rows accepted (before and after the backtracking rule), >= 2.
    backtrack_tolerance : float, optional
        Largest backtrack of the control [mm, after scaling] treated as noise; default 1 % of the
        control range of the file. See :mod:`fracid.data.checks` for the rule.

    Returns
    -------
    list of Curve
        One per force column, in the order given; ``notes`` record skipped lines, scaling and dropped rows.

    Raises
    ------
    DataTypeError
        (a DataError and a TypeError) If an argument has the wrong type: ``path`` not a path, a column
        name not a str, a scale or ``backtrack_tolerance`` not a number, ``min_points`` not an integer.
    DataError
        Naming the file, and the row (header = row 1) and column where relevant, if the file is
        empty, lacks a requested column, holds text, an empty or NaN cell, a number with a thousands
        separator, has fewer than ``min_points`` rows, a negative control, rows in reverse order,
        columns that look swapped, or a control going backwards by more than the tolerance; a wrong
        delimiter or decimal mark is named as such.

    Examples
    --------
    >>> curves = read_curve_csv("tests.csv", control_column="cmod_mm",
    ...                         force_columns=["F1_kN", "F2_kN"], force_unit_scale=1e3)  # doctest: +SKIP
    """
    path = file_path(path)
    wanted = [column_name(control_column, "control_column"), *force_column_names(force_columns)]
    scales = unit_scale(control_unit_scale, "control_unit_scale"), unit_scale(force_unit_scale, "force_unit_scale")
    min_points = integer_at_least(min_points, 2, "min_points")
    delimiter, decimal = check_format(delimiter, decimal)
    table = read_table(path, delimiter, decimal, wanted)
    values, lines = _parsed_rows(path, table, wanted, delimiter, decimal, min_points)
    keep, notes = _kept_rows(path, values, lines, wanted, scales, backtrack_tolerance, min_points)
    return _curves(path, table, values[keep], wanted, scales, notes)


def _parsed_rows(path, table: CsvTable, wanted: list, delimiter: str, decimal: str, min_points: int):
    """The numbers of the ``wanted`` columns of ``table`` (control first) and the file line of each row.

    Raises
    ------
    DataError
        A requested column missing, fewer than ``min_points`` rows, a cell that is not a number.
    """
    indices = column_indices(table, wanted, delimiter)
    if len(table.rows) < min_points:
        raise DataError(f"{path}: {len(table.rows)} data rows, fewer than the {min_points} a curve needs")
    return parse_table(table, wanted, indices, decimal, delimiter)


def _kept_rows(path, values, lines, wanted: list, scales: tuple, backtrack_tolerance, min_points: int):
    """The rows kept by the checks of :mod:`fracid.data.checks` on the scaled ``values``, and their notes.

    Parameters
    ----------
    values : ndarray, shape (n_rows, 1 + n_forces)
        Control then force columns, unscaled.
    lines : ndarray of int
        The file line of each row, for the messages.
    scales : (float, float)
        Multipliers of the control and force columns.

    Returns
    -------
    keep : ndarray of bool, shape (n_rows,)
    notes : tuple of str
    """
    control_column = wanted[0]
    labels = Labels(f"{path} (control {control_column!r})", repr(control_column),
                    tuple(map(repr, wanted[1:])), "row")
    keep, notes = checked_curve(values[:, 0] * scales[0], values[:, 1:] * scales[1], lines, backtrack_tolerance,
                                labels)
    if keep.sum() < min_points:
        raise DataError(
            f"{path}: {int(keep.sum())} data rows left of {len(values)} after dropping backtracking rows, "
            f"fewer than the {min_points} a curve needs"
        )
    return keep, notes


def _curves(path, table: CsvTable, values, wanted: list, scales: tuple, notes) -> list[Curve]:
    """One :class:`Curve` per force column of the kept rows ``values``, with the notes of the reading."""
    control_column, (c_scale, f_scale) = wanted[0], scales
    scale_notes = list(table.notes())
    if c_scale != 1.0:
        scale_notes.append(f"{path}: control column {show(control_column)} multiplied by {c_scale:g} to mm")
    return [
        Curve(
            control=values[:, 0] * c_scale,
            force=values[:, k + 1] * f_scale,
            source=f"{path}, column {show(name)} against {show(control_column)}",
            notes=(*scale_notes, *([f"{path}: force column {show(name)} multiplied by {f_scale:g} to N"]
                                   if f_scale != 1.0 else []), *notes),
        )
        for k, name in enumerate(wanted[1:])
    ]
