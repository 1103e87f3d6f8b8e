"""Measured curves (control quantity, force) read from CSV files, checked row by row.

A :class:`Curve` always has a strictly increasing control quantity [mm] and a force [N]. Files are read
by :func:`read_curve_csv`, which names the file, the row and the column of every defect it finds.
Rows are counted as in the file: the header is row 1, the first data row is row 2.

Backtracking rule (the only point-dropping rule; it is always reported in ``Curve.notes``): a row is
kept only if its control value exceeds the maximum control value of all earlier rows (the running
maximum). A row lying more than ``backtrack_tolerance`` below that running maximum is not noise but a
defect (unloading, a spliced file, a wrong column) and raises :class:`DataError`; smaller backtracks,
and repeated control values, are measurement noise and the row is dropped.

Cell separator and decimal mark: ``delimiter`` is ``","`` (default), ``";"``, ``"\\t"`` or ``" "``
(any run of spaces and tabs); ``decimal`` is ``"."`` (default) or ``","`` (decimal commas, e.g.
``0,001``; then a ``"."`` in a number is refused: it would be a thousands separator). A file read
with the wrong separator or decimal mark gets a message saying which one it seems to use.
"""

from __future__ import annotations

import csv
import math
import operator
import os
import re
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

#: default backtrack tolerance as a fraction of the control range of the file
DEFAULT_BACKTRACK_FRACTION = 0.01

#: how many dropped rows a note lists explicitly
_MAX_LISTED_ROWS = 10

#: cell separators read by :func:`read_curve_csv`; " " splits at any run of spaces and tabs
DELIMITERS = (",", ";", "\t", " ")

#: decimal marks read by :func:`read_curve_csv`
DECIMALS = (".", ",")

#: a number written with a decimal comma (``0,001``, ``-12,5e3``)
_DECIMAL_COMMA = re.compile(r"^[+-]?\d*,\d+(?:[eE][+-]?\d+)?$")

#: a run of digits: the pieces a comma-separated file makes of decimal-comma numbers
_DIGITS = re.compile(r"^[+-]?\d+(?:[eE][+-]?\d+)?$")


class DataError(ValueError):
    """Experimental data that cannot be used as given (bad file, bad values, impossible request)."""


def _readonly_vector(values, what: str) -> np.ndarray:
    try:
        array = np.array(values, dtype=float)
    except (TypeError, ValueError):
        raise DataError(f"{what} must be an array of numbers, got {values!r}") from None
    if array.ndim != 1:
        raise DataError(f"{what} must be one-dimensional, got shape {array.shape}")
    if not np.all(np.isfinite(array)):
        bad = int(np.flatnonzero(~np.isfinite(array))[0])
        raise DataError(f"{what} holds a non-finite value ({float(array[bad]):g}) at index {bad}")
    array.setflags(write=False)
    return array


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
        control = _readonly_vector(self.control, f"control of curve {self.source!r}")
        force = _readonly_vector(self.force, f"force of curve {self.source!r}")
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


def _row_list(rows: np.ndarray) -> str:
    listed = ", ".join(str(int(r)) for r in rows[:_MAX_LISTED_ROWS])
    more = len(rows) - _MAX_LISTED_ROWS
    return listed + (f" and {more} more" if more > 0 else "")


def _monotonic_mask(
    control: np.ndarray, rows: np.ndarray, tolerance: float, where: str, unit_label: str
) -> tuple[np.ndarray, tuple[str, ...]]:
    """Apply the backtracking rule; return the mask of kept points and the note describing it.

    ``rows`` labels each point in messages (file rows, or indices), ``where`` names the data.
    """
    running = np.maximum.accumulate(control)
    previous_max = np.concatenate(([-np.inf], running[:-1]))
    keep = control > previous_max
    backtrack = np.where(keep, 0.0, previous_max - control)
    too_far = np.flatnonzero(backtrack > tolerance)
    if too_far.size:
        i = int(too_far[0])
        j = int(np.argmax(control[:i]))
        raise DataError(
            f"{where}: control goes backwards at {unit_label} {rows[i]}: {float(control[i]):.6g} mm is "
            f"{backtrack[i]:.6g} mm below the maximum {float(control[j]):.6g} mm reached at {unit_label} {rows[j]}, "
            f"more than the noise tolerance {tolerance:.6g} mm (backtrack_tolerance: the key of "
            "[[experiments]] in a configuration, in its control_unit, or the argument of read_curve_csv "
            "in mm; default 1 % of the control range); unloading branches or spliced series must be cut "
            "before use, or a larger backtrack_tolerance drops them as noise"
        )
    dropped = np.flatnonzero(~keep)
    if dropped.size == 0:
        return keep, ()
    plural = "s" if dropped.size > 1 else ""
    note = (
        f"{where}: {dropped.size} backtracking point{plural} dropped "
        f"(rule: keep a point only if its control exceeds the maximum of all earlier points; "
        f"backtracks up to {tolerance:.6g} mm are noise, larger ones are errors; "
        f"largest backtrack here {backtrack.max():.6g} mm) at {unit_label}{plural} {_row_list(rows[dropped])}"
    )
    return keep, (note,)


def _check_tolerance(backtrack_tolerance, control: np.ndarray, where: str) -> float:
    if backtrack_tolerance is None:
        return DEFAULT_BACKTRACK_FRACTION * float(np.max(control) - np.min(control))
    tolerance = float(backtrack_tolerance)
    if not (math.isfinite(tolerance) and tolerance >= 0.0):
        raise DataError(f"{where}: backtrack_tolerance must be a finite value >= 0 [mm], got {backtrack_tolerance!r}")
    return tolerance


def curve_from_arrays(control, force, *, source: str = "arrays", backtrack_tolerance: float | None = None) -> Curve:
    """Build a :class:`Curve` from arrays, applying the backtracking rule of this module.

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
    DataError
        If the control goes backwards by more than the tolerance, or the arrays are invalid.
    """
    c = _readonly_vector(control, f"control of {source!r}")
    f = _readonly_vector(force, f"force of {source!r}")
    if c.shape != f.shape:
        raise DataError(f"{source!r}: control has {c.size} values but force has {f.size}")
    if c.size < 2:
        raise DataError(f"{source!r}: needs at least 2 points, got {c.size}")
    tolerance = _check_tolerance(backtrack_tolerance, c, repr(source))
    keep, notes = _monotonic_mask(c, np.arange(c.size), tolerance, repr(source), "index")
    return Curve(control=c[keep], force=f[keep], source=source, notes=notes)


# --------------------------------------------------------------------------------------------- CSV


def _check_scale(value, name: str, positive: bool) -> float:
    try:
        scale = float(value)
    except (TypeError, ValueError):
        raise DataError(f"{name} must be a number, got {value!r}") from None
    if not math.isfinite(scale) or scale == 0.0 or (positive and scale < 0.0):
        need = "a finite number > 0 (the control must increase)" if positive else "a finite non-zero number"
        raise DataError(f"{name} must be {need}, got {value!r}")
    return scale


def _column_names(force_columns) -> list[str]:
    names = [force_columns] if isinstance(force_columns, str) else list(force_columns)
    if not names:
        raise DataError("force_columns is empty: give a column name or a list of names")
    for name in names:
        if not isinstance(name, str):
            raise DataError(f"force_columns must hold column names (str), got {name!r}")
    return names


def check_format(delimiter, decimal) -> tuple[str, str]:
    """``delimiter`` and ``decimal`` checked: a separator of :data:`DELIMITERS` (or any other single
    character) and a decimal mark of :data:`DECIMALS`, the two different.

    Raises
    ------
    DataError
        If the delimiter is not one character, the decimal mark not "." or ",", or both are ",".
    """
    if not isinstance(delimiter, str) or len(delimiter) != 1:
        raise DataError(f"delimiter = {delimiter!r}: give one character, e.g. ',' ';' '\\t' or ' ' (whitespace)")
    if decimal not in DECIMALS:
        raise DataError(f"decimal = {decimal!r}: give '.' or ','")
    if decimal == delimiter:
        raise DataError(f"decimal = {decimal!r} and delimiter = {delimiter!r}: a comma cannot both separate the cells "
                        "and mark the decimals; files with decimal commas are separated by ';' or tabs")
    return delimiter, decimal


def iter_rows(handle, delimiter: str):
    """(file row, cells) of every line of an open text file; ``delimiter`` " " splits at any run of
    whitespace, any other is read by :mod:`csv` (quotes allowed)."""
    if delimiter == " ":
        for number, line in enumerate(handle, start=1):
            yield number, line.split()
        return
    reader = csv.reader(handle, delimiter=delimiter)
    for cells in reader:
        yield reader.line_num, cells


def delimiter_hint(header: Sequence[str], delimiter: str) -> str | None:
    """The separator a file seems to use when its header, split by ``delimiter``, is one cell
    holding another separator (``"cmod_mm;F_N"`` read with ","); None otherwise."""
    if len(header) != 1:
        return None
    cell = header[0].strip()
    for candidate in (";", "\t", ",", " "):
        if candidate != delimiter and candidate in cell:
            return candidate
    return None


def decimal_comma_hint(cells: Sequence[str], delimiter: str, decimal: str, n_header: int) -> str | None:
    """Why the numbers of a data row cannot be read if they seem to have decimal commas, else None.

    Either cells such as ``0,001`` read with decimal ".", or (delimiter ",") a row split into more
    cells than the header, all of them digits: the pieces of decimal-comma numbers.
    """
    if decimal != ".":
        return None
    texts = [cell.strip() for cell in cells if cell.strip()]
    if delimiter != "," and any(_DECIMAL_COMMA.match(text) for text in texts):
        example = next(text for text in texts if _DECIMAL_COMMA.match(text))
        return f'numbers such as {example!r} have decimal commas: set decimal = ","'
    if delimiter == "," and len(cells) > n_header and texts and all(_DIGITS.match(text) for text in texts):
        return ("the row has more cells than the header, all digits: the numbers seem to have decimal commas, "
                "which a comma-separated file cannot hold; save the file separated by ';' and set "
                'delimiter = ";" and decimal = ","')
    return None


def _to_float(text: str, decimal: str) -> float:
    """``float`` of a stripped cell with the given decimal mark (ValueError if it is not a number)."""
    if decimal == ",":
        if "." in text:
            raise ValueError(text)
        text = text.replace(",", ".")
    return float(text)


def _is_number(text: str, decimal: str = ".") -> bool:
    try:
        _to_float(text.strip(), decimal)
    except ValueError:
        return False
    return True


def _read_rows(path: str, delimiter: str, decimal: str = ".") -> tuple[list[str], list[tuple[int, list[str]]]]:
    """Header cells and (file row, cells) of every data row; blank lines after the data are ignored."""
    try:
        with open(path, newline="", encoding="utf-8-sig") as handle:
            rows = list(iter_rows(handle, delimiter))
    except UnicodeDecodeError as error:
        raise DataError(f"{path}: not a UTF-8 text file ({error})") from None
    except csv.Error as error:
        raise DataError(f"{path}: not a readable CSV file ({error})") from None
    blank = [not any(cell.strip() for cell in cells) for _, cells in rows]
    while rows and blank[-1]:
        rows.pop()
        blank.pop()
    first = next((k for k, is_blank in enumerate(blank) if not is_blank), None)
    if first is None:
        raise DataError(f"{path}: the file is empty (no header row, no data)")
    header_line, header = rows[first]
    header = [cell.strip() for cell in header]
    if all(_is_number(cell, decimal) for cell in header if cell):
        raise DataError(
            f"{path}: row {header_line} looks like data ({', '.join(header)}); a header row naming the columns is required"
        )
    data = rows[first + 1 :]
    for (line, _), is_blank in zip(data, blank[first + 1 :]):
        if is_blank:
            raise DataError(f"{path}: row {line} is empty, between data rows")
    return header, data


def _column_indices(path: str, header: list[str], wanted: list[str], delimiter: str = ",") -> list[int]:
    indices = []
    for name in wanted:
        hits = [k for k, cell in enumerate(header) if cell == name]
        if not hits:
            guess = delimiter_hint(header, delimiter)
            if guess is not None:
                raise DataError(
                    f"{path}: the header is one cell {header[0]!r} when split by delimiter = {delimiter!r}: the file "
                    f"seems to be separated by {guess!r}; give delimiter = {guess!r} (and decimal = \",\" for "
                    "decimal commas)"
                )
            available = ", ".join(repr(cell) for cell in header)
            raise DataError(f"{path}: the header has no column {name!r}; available columns: {available}")
        if len(hits) > 1:
            raise DataError(f"{path}: the header names column {name!r} {len(hits)} times; it is ambiguous")
        indices.append(hits[0])
    return indices


def _parse_cell(path: str, line: int, column: str, text: str, decimal: str = ".", delimiter: str = ",") -> float:
    stripped = text.strip()
    if not stripped:
        raise DataError(f"{path}: row {line}, column {column!r}: empty cell (missing value)")
    try:
        value = _to_float(stripped, decimal)
    except ValueError:
        hint = decimal_comma_hint([stripped], delimiter, decimal, 1)
        if decimal == "," and "." in stripped:
            hint = 'with decimal = "," a "." is not allowed in a number (a thousands separator?)'
        raise DataError(
            f"{path}: row {line}, column {column!r}: {stripped!r} is not a number" + (f"; {hint}" if hint else "")
        ) from None
    if math.isnan(value):
        raise DataError(f"{path}: row {line}, column {column!r}: missing value ({stripped!r})")
    if math.isinf(value):
        raise DataError(f"{path}: row {line}, column {column!r}: {stripped!r} is not finite")
    return value


def _parse_table(
    path: str,
    header: list[str],
    data: list[tuple[int, list[str]]],
    names: list[str],
    indices: list[int],
    decimal: str = ".",
    delimiter: str = ",",
) -> tuple[np.ndarray, np.ndarray]:
    """Values (n_rows, n_columns) of the requested columns and the file row of each data row."""
    values = np.empty((len(data), len(names)))
    lines = np.empty(len(data), dtype=int)
    for r, (line, cells) in enumerate(data):
        if len(cells) != len(header):
            hint = decimal_comma_hint(cells, delimiter, decimal, len(header))
            raise DataError(
                f"{path}: row {line} has {len(cells)} cells but the header has {len(header)} "
                f"({', '.join(repr(cell) for cell in header)})" + (f"; {hint}" if hint else "")
            )
        lines[r] = line
        for c, (name, index) in enumerate(zip(names, indices)):
            values[r, c] = _parse_cell(path, line, name, cells[index], decimal, delimiter)
    return values, lines


def integer_at_least(value, minimum: int, what: str) -> int:
    """``value`` as an int, or a DataError naming ``what`` if it is not an integer >= ``minimum``."""
    try:
        value = operator.index(value)
    except TypeError:
        raise DataError(f"{what} must be an integer, got {value!r}") from None
    if value < minimum:
        raise DataError(f"{what} must be >= {minimum}, got {value}")
    return value


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
        CSV file; the first non-blank row is the header naming the columns.
    control_column : str
        Header name of the control quantity (CMOD, deflection, elongation, ...).
    force_columns : str or sequence of str
        Header name(s) of the force column(s).
    control_unit_scale : float
        Multiplier turning the control column into mm (e.g. 1e-3 for um); > 0. No unit is guessed.
    force_unit_scale : float
        Multiplier turning the force column(s) into N (e.g. 1e3 for kN); non-zero.
    delimiter : str
        Cell separator: ``","`` (default), ``";"``, ``"\\t"``, or ``" "`` for any run of spaces and
        tabs. A header read as one cell holding another separator is reported as such.
    decimal : {".", ","}
        Decimal mark of the numbers; ``","`` (e.g. ``0,001``) needs a delimiter other than ``","``.
    min_points : int
        Fewest data rows accepted (before and after the backtracking rule), >= 2.
    backtrack_tolerance : float, optional
        Largest backtrack of the control [mm, after scaling] treated as noise; default 1 % of the
        control range of the file. See the module docstring for the rule.

    Returns
    -------
    list of Curve
        One per force column, in the order given; ``notes`` record scaling and dropped rows.

    Raises
    ------
    DataError
        Naming the file, and the row (header = row 1) and column where relevant, if the file is
        empty, lacks a requested column, holds text, an empty or NaN cell, has fewer than
        ``min_points`` rows, or its control goes backwards by more than the tolerance; a wrong
        delimiter or decimal mark is named as such.

    Examples
    --------
    >>> curves = read_curve_csv("tests.csv", control_column="cmod_mm",
    ...                         force_columns=["F1_kN", "F2_kN"], force_unit_scale=1e3)  # doctest: +SKIP
    """
    path = os.fspath(path)
    names = _column_names(force_columns)
    c_scale = _check_scale(control_unit_scale, "control_unit_scale", positive=True)
    f_scale = _check_scale(force_unit_scale, "force_unit_scale", positive=False)
    min_points = integer_at_least(min_points, 2, "min_points")

    delimiter, decimal = check_format(delimiter, decimal)

    header, data = _read_rows(path, delimiter, decimal)
    wanted = [control_column, *names]
    indices = _column_indices(path, header, wanted, delimiter)
    if len(data) < min_points:
        raise DataError(f"{path}: {len(data)} data rows, fewer than the {min_points} a curve needs")
    values, lines = _parse_table(path, header, data, wanted, indices, decimal, delimiter)

    control = values[:, 0] * c_scale
    forces = values[:, 1:] * f_scale
    where = f"{path} (control {control_column!r})"
    tolerance = _check_tolerance(backtrack_tolerance, control, where)
    keep, notes = _monotonic_mask(control, lines, tolerance, where, "row")
    if keep.sum() < min_points:
        raise DataError(
            f"{path}: {int(keep.sum())} data rows left of {len(data)} after dropping backtracking rows, "
            f"fewer than the {min_points} a curve needs"
        )
    scale_notes = []
    if c_scale != 1.0:
        scale_notes.append(f"{path}: control column {control_column!r} multiplied by {c_scale:g} to mm")
    curves = []
    for k, name in enumerate(names):
        extra = [f"{path}: force column {name!r} multiplied by {f_scale:g} to N"] if f_scale != 1.0 else []
        curves.append(
            Curve(
                control=control[keep],
                force=forces[keep, k],
                source=f"{path}, column {name!r} against {control_column!r}",
                notes=(*scale_notes, *extra, *notes),
            )
        )
    return curves


def require_positive_force(curves: Sequence[Curve]) -> None:
    """Refuse force curves that are all <= 0: negated forces, or a column of zeros.

    A tension or bending test gives positive forces (the specimens' forces are positive); a
    machine that records them negative needs its column negated (e.g. ``force_unit_scale=-1``).

    Raises
    ------
    DataError
        Naming the curve's file and column, if every force of a curve is zero, or <= 0 with one below 0.
    """
    for curve in curves:
        force = curve.force
        if np.all(force == 0.0):
            raise DataError(f"{curve.source}: all forces are zero; is it the right column?")
        if np.all(force <= 0.0):
            lowest, highest = float(force.min()), float(force.max()) + 0.0  # + 0.0: -0 written 0
            raise DataError(
                f"{curve.source}: the forces are all negative (from {lowest:g} to {highest:g} N): "
                "a tension or bending test gives positive forces; if the sign convention of the machine is "
                "negative, negate the column"
            )
