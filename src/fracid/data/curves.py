"""Measured curves (control quantity, force) read from CSV files, checked row by row.

A :class:`Curve` always has a strictly increasing control quantity [mm] and a force [N]. Files are read
by :func:`read_curve_csv`, which names the file, the row and the column of every defect it finds.
Rows are counted as the lines of the file: with the header on line 1, the first data row is row 2.

Backtracking rule (the only point-dropping rule; it is always reported in ``Curve.notes``): a row is
kept only if its control value exceeds the maximum control value of all earlier rows (the running
maximum). A row lying more than ``backtrack_tolerance`` below that running maximum is not noise but a
defect (unloading, a spliced file, a wrong column) and raises :class:`DataError`; smaller backtracks,
and repeated control values, are measurement noise and the row is dropped.

Cell separator and decimal mark: ``delimiter`` is ``","`` (default), ``";"``, ``"\\t"`` or ``" "``
(any run of spaces and tabs); ``decimal`` is ``"."`` (default) or ``","`` (decimal commas, e.g.
``0,001``; then a ``"."`` in a number is refused: it would be a thousands separator). A file read
with the wrong separator or decimal mark gets a message saying which one it seems to use; a number
written with a thousands separator (``"1,234.5"``, ``1 234,5``, ``1.234,5``) is refused, naming its row,
column and the separator to remove.

Lines above the header (:func:`read_table`): a first line ``sep=;`` (Excel's declaration of the cell
separator) is skipped if it agrees with ``delimiter`` and refused if it does not; the header is the first
line naming all the requested columns among the lines above the first data row, so that comment lines
(``# ...``, also a header written ``# cmod,F`` by ``numpy.savetxt``) and text lines of a test machine's
export (``Test 1, 2026-01-01``) above it are skipped, and listed in ``Curve.notes``. Without a line naming
them, the header is the first line that is neither blank nor a comment, and a missing column names the
line that looks like the header instead. Empty cells after the last column (``0.1,2.0,``) are ignored.

Direction of the control, checked before the backtracking rule, so that the message names the cause: a
control that is mostly negative (a test recorded with a negative sign) is refused with the advice to
negate it; a control decreasing throughout (rows in reverse order) with the advice to sort the rows; a
control that rises and falls back while a force column increases throughout with the advice to swap the
columns. None of these is corrected silently.
"""

from __future__ import annotations

import csv
import difflib
import math
import numbers
import operator
import os
import re
import reprlib
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

#: default backtrack tolerance as a fraction of the control range of the file
DEFAULT_BACKTRACK_FRACTION = 0.01

#: a control falling back from its peak by this fraction of its range, beside a force column increasing
#: throughout, is taken for swapped columns
_SWAPPED_FALL = 0.2

#: how a column is negated (no key of [[experiments]] does it)
_NEGATE = ('set negate = ["{column}"] in its [[experiments]] block, or multiply it by -1 in the file (from Python: '
           'read_curve_csv(..., {scale}=-1))')

#: the advice for a number written with thousands separators
_REMOVE_THOUSANDS = "remove the thousands separators ({}; in a spreadsheet: a number format without them)"

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

#: decimal mark -> a number with thousands separators (group 1) and that decimal mark: ``1,234.5``, ``1 234,5``
_THOUSANDS = {
    ".": re.compile(r"^[+-]?[1-9]\d{0,2}([, \u00a0\u202f'])\d{3}(?:\1\d{3})*(?:\.\d*)?$"),
    ",": re.compile(r"^[+-]?[1-9]\d{0,2}([. \u00a0\u202f'])\d{3}(?:\1\d{3})*(?:,\d*)?$"),
}

#: the pieces of ``1,234.5`` split at its thousands separator by a comma-separated file
_THOUSANDS_HEAD = re.compile(r"^[+-]?[1-9]\d{0,2}$")
_THOUSANDS_TAIL = re.compile(r"^\d{3}(?:\.\d*)?$")

#: thousands separators as named in messages
_SEPARATOR_NAMES = {",": "','", ".": "'.'", " ": "spaces", "\u00a0": "non-breaking spaces",
                    "\u202f": "narrow non-breaking spaces", "'": "apostrophes"}

#: Excel's first line declaring the cell separator, ``sep=;`` (quoted or followed by separators after a re-save)
_SEP_LINE = re.compile(r'^"?sep=(.)"?\1*\s*$')


class DataError(ValueError):
    """Experimental data that cannot be used as given (bad file, bad values, impossible request)."""


class DataTypeError(DataError, TypeError):
    """An argument of the wrong type (a str where a number is expected, None where a column name is):
    both a :class:`DataError` and a ``TypeError``."""


def _shown(value) -> str:
    """A short repr of an argument, and its type, for messages."""
    return f"{reprlib.repr(value)} ({type(value).__name__})"


def _real(value, what: str) -> float:
    """``value`` as a float if it is a real number (not a bool, not a str), else a DataTypeError."""
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise DataTypeError(f"{what} must be a number, got {_shown(value)}")
    return float(value)


def _numeric_array(values, what: str) -> np.ndarray:
    """A float copy of ``values`` if they are numbers (int or float; no str, bool or complex)."""
    try:
        raw = np.asarray(values)
    except (TypeError, ValueError):  # ragged nested sequences
        raise DataTypeError(f"{what} must be an array of numbers, got {_shown(values)}") from None
    numeric = raw.dtype.kind in "iuf" or (
        raw.dtype.kind == "O" and all(isinstance(v, numbers.Real) and not isinstance(v, bool) for v in raw.flat)
    )
    if not numeric:
        raise DataTypeError(f"{what} must be an array of numbers (int or float), got {_shown(values)} "
                            f"of dtype {raw.dtype}")
    return raw.astype(float)


def _readonly_vector(values, what: str) -> np.ndarray:
    array = _numeric_array(values, what)
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


def _backtracks(control: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Mask of the points above the running maximum of the earlier ones, and each point's backtrack
    below that maximum [mm] (0 for the kept points)."""
    running = np.maximum.accumulate(control)
    previous_max = np.concatenate(([-np.inf], running[:-1]))
    keep = control > previous_max
    return keep, np.where(keep, 0.0, previous_max - control)


def _first_backtrack(values: np.ndarray, tolerance: float) -> int | None:
    """Index of the first value more than ``tolerance`` below the maximum of the earlier ones, or None."""
    beyond = np.flatnonzero(_backtracks(values)[1] > tolerance)
    return int(beyond[0]) if beyond.size else None


def _monotonic_mask(
    control: np.ndarray, rows: np.ndarray, tolerance: float, where: str, unit_label: str
) -> tuple[np.ndarray, tuple[str, ...]]:
    """Apply the backtracking rule; return the mask of kept points and the note describing it.

    ``rows`` labels each point in messages (file rows, or indices), ``where`` names the data.
    """
    keep, backtrack = _backtracks(control)
    i = _first_backtrack(control, tolerance)
    if i is not None:
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


@dataclass(frozen=True)
class _Labels:
    """How the direction checks name the data: ``where`` (file or source), the control and force
    columns, and what a point is (``"row"`` of a file, ``"index"`` of an array)."""

    where: str
    control: str
    forces: tuple[str, ...]
    unit: str


def _check_direction(control: np.ndarray, forces: np.ndarray, rows: np.ndarray, tolerance: float,
                     labels: _Labels) -> None:
    """Refuse, before the backtracking rule, a control that is negative, in reverse order, or a force.

    Parameters
    ----------
    control : ndarray, shape (n,)
        Control values [mm] in file order.
    forces : ndarray, shape (n, m)
        Force columns [N].
    rows : ndarray of int, shape (n,)
        File row (or index) of every point, for messages.
    tolerance : float
        Backtrack tolerance [mm] of the backtracking rule.
    labels : _Labels
        Names used in the messages.

    Raises
    ------
    DataError
        If the control is mostly negative (advice: negate it), decreases throughout (the rows are in
        reverse order) or rises and falls back while a force column increases throughout (the columns
        look swapped).
    """
    _check_control_sign(control, forces, rows, labels)
    if _first_backtrack(control, tolerance) is None:
        return
    if control[-1] < control[0] and _first_backtrack(control[::-1], tolerance) is None:
        raise DataError(
            f"{labels.where}: the control column {labels.control} decreases throughout, from "
            f"{control[0]:.6g} mm at {labels.unit} {rows[0]} to {control[-1]:.6g} mm at {labels.unit} {rows[-1]}: "
            "the rows are in reverse order (the last measured first); sort them by increasing control"
        )
    peak = int(np.argmax(control))
    falls_back = control[-1] < control[peak] - _SWAPPED_FALL * float(np.ptp(control))
    increasing = [name for name, force in zip(labels.forces, forces.T) if force[-1] > force[0]
                  and _first_backtrack(force, DEFAULT_BACKTRACK_FRACTION * float(np.ptp(force))) is None]
    if falls_back and increasing:
        raise DataError(
            f"{labels.where}: the control column {labels.control} rises to {control[peak]:.6g} at {labels.unit} "
            f"{rows[peak]} and falls back to {control[-1]:.6g}, as a force does, while the force column "
            f"{increasing[0]} increases throughout, as a control does: the columns look swapped; if so, "
            f"give control_column = {increasing[0]} and {labels.control} as the force column"
        )


def _check_control_sign(control: np.ndarray, forces: np.ndarray, rows: np.ndarray, labels: _Labels) -> None:
    """Refuse a control that is mostly negative, decreasing from about 0 (its largest excursion below 0 [mm],
    reached after the first row): a test recorded with a negative sign, named with the negative force
    columns too. An increasing control with a negative offset is left to the other checks."""
    low = int(np.argmin(control))
    if not (control[low] < 0.0 < -control[low] - max(float(control.max()), 0.0) and control[-1] < control[0]):
        return
    negative = [name for name, force in zip(labels.forces, forces.T) if -force.min() > force.max()]
    also = (f"; the force column{'s' if len(negative) > 1 else ''} {', '.join(negative)} "
            f"{'are' if len(negative) > 1 else 'is'} negative too: negate {'them' if len(negative) > 1 else 'it'} "
            f"as well ({_NEGATE.format(column='force', scale='force_unit_scale')})" if negative else "")
    raise DataError(
        f"{labels.where}: the control column {labels.control} is negative: it runs from {control[0] + 0.0:.6g} mm "
        f"at {labels.unit} {rows[0]} to {control[low]:.6g} mm at {labels.unit} {rows[low]}, while a test's control "
        "(CMOD, deflection, elongation) grows from 0 to positive values: the machine records it with a negative "
        f"sign; negate the column: {_NEGATE.format(column='control', scale='control_unit_scale')}" + also
    )


def _check_tolerance(backtrack_tolerance, control: np.ndarray, where: str) -> float:
    if backtrack_tolerance is None:
        return DEFAULT_BACKTRACK_FRACTION * float(np.max(control) - np.min(control))
    tolerance = _real(backtrack_tolerance, f"{where}: backtrack_tolerance")
    if not (math.isfinite(tolerance) and tolerance >= 0.0):
        raise DataError(f"{where}: backtrack_tolerance must be a finite value >= 0 [mm], got {backtrack_tolerance!r}")
    return tolerance


def _checked_curve(control: np.ndarray, forces: np.ndarray, rows: np.ndarray, backtrack_tolerance,
                   labels: _Labels) -> tuple[np.ndarray, tuple[str, ...]]:
    """The direction checks, then the backtracking rule: the mask of kept points and its note."""
    tolerance = _check_tolerance(backtrack_tolerance, control, labels.where)
    _check_direction(control, forces, rows, tolerance, labels)
    return _monotonic_mask(control, rows, tolerance, labels.where, labels.unit)


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
    DataTypeError
        If an array holds something else than numbers, or ``backtrack_tolerance`` is not a number.
    DataError
        If the arrays are not one-dimensional, differ in length or hold non-finite values; if the control
        is negative, decreases throughout, looks like the force (see :func:`read_curve_csv`) or goes
        backwards by more than the tolerance.
    """
    source = str(source)
    c = _readonly_vector(control, f"control of {source!r}")
    f = _readonly_vector(force, f"force of {source!r}")
    if c.shape != f.shape:
        raise DataError(f"{source!r}: control has {c.size} values but force has {f.size}")
    if c.size < 2:
        raise DataError(f"{source!r}: needs at least 2 points, got {c.size}")
    labels = _Labels(repr(source), "'control'", ("'force'",), "index")
    keep, notes = _checked_curve(c, f[:, None], np.arange(c.size), backtrack_tolerance, labels)
    return Curve(control=c[keep], force=f[keep], source=source, notes=notes)


# --------------------------------------------------------------------------------------------- CSV


def _check_scale(value, name: str) -> float:
    """A unit multiplier: a finite non-zero number (negative: the column is negated)."""
    scale = _real(value, name)
    if not math.isfinite(scale) or scale == 0.0:
        raise DataError(f"{name} must be a finite non-zero number (negative to negate the column), got {value!r}")
    return scale


def _column_name(value, what: str) -> str:
    """A column name: a non-empty str, else a DataTypeError (DataError if empty) naming ``what``."""
    if not isinstance(value, str):
        raise DataTypeError(f"{what} must be a column name (str), got {_shown(value)}")
    if not value.strip():
        raise DataError(f"{what} must be a column name, got an empty string")
    return value


def _column_names(force_columns) -> list[str]:
    if isinstance(force_columns, str):
        return [_column_name(force_columns, "force_columns")]
    if not isinstance(force_columns, Sequence):
        raise DataTypeError(f"force_columns must be a column name (str) or a list of names, "
                            f"got {_shown(force_columns)}")
    if not force_columns:
        raise DataError("force_columns is empty: give a column name or a list of names")
    return [_column_name(name, f"force_columns[{k}]") for k, name in enumerate(force_columns)]


def _file_path(path) -> str:
    """``path`` as a str (from str, bytes or os.PathLike), else a DataTypeError."""
    try:
        return os.fsdecode(os.fspath(path))
    except TypeError:
        raise DataTypeError(f"path must be a file path (str or os.PathLike), got {_shown(path)}") from None


def check_format(delimiter, decimal) -> tuple[str, str]:
    """``delimiter`` and ``decimal`` checked: a separator of :data:`DELIMITERS` (or any other single
    character) and a decimal mark of :data:`DECIMALS`, the two different.

    Raises
    ------
    DataError
        If the delimiter is not one character, the decimal mark not "." or ",", or both are ",".
    """
    if not isinstance(delimiter, str) or not isinstance(decimal, str):
        raise DataTypeError(f"delimiter and decimal must be str, got {_shown(delimiter)} and {_shown(decimal)}")
    if len(delimiter) != 1:
        raise DataError(f"delimiter = {delimiter!r}: give one character, e.g. ',' ';' '\\t' or ' ' (whitespace)")
    if decimal not in DECIMALS:
        raise DataError(f"decimal = {decimal!r}: give '.' or ','")
    if decimal == delimiter:
        raise DataError(f"decimal = {decimal!r} and delimiter = {delimiter!r}: a comma cannot both separate the cells "
                        "and mark the decimals; files with decimal commas are separated by ';' or tabs")
    return delimiter, decimal


def iter_rows(lines, delimiter: str, first_line: int = 1):
    """(first file line, cells) of every row of an iterable of text lines (an open file) whose first line is
    line ``first_line``; ``delimiter`` " " splits at any run of whitespace, any other is read by
    :mod:`csv` (quotes allowed)."""
    if delimiter == " ":
        for number, line in enumerate(lines, start=first_line):
            yield number, line.split()
        return
    reader = csv.reader(lines, delimiter=delimiter)
    end = 0  # the last line of the previous row: a row with a quoted line break spans several lines
    for cells in reader:
        yield end + first_line, cells
        end = reader.line_num


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


def _trimmed(cells: Sequence[str]) -> list[str]:
    """The cells without the empty cells at the end of the row (``0.1,2.0,,`` written by spreadsheets)."""
    cells = list(cells)
    while cells and not cells[-1].strip():
        cells.pop()
    return cells


def decimal_comma_hint(cells: Sequence[str], delimiter: str, decimal: str, n_header: int) -> str | None:
    """Why the numbers of a data row cannot be read if they seem to have decimal commas, else None.

    Either cells such as ``0,001`` read with decimal ".", or (delimiter ",") a row split into more
    cells than the header, all of them digits: the pieces of decimal-comma numbers.
    """
    if decimal != ".":
        return None
    cells = _trimmed(cells)
    texts = [cell.strip() for cell in cells if cell.strip()]
    if delimiter != "," and any(_DECIMAL_COMMA.match(text) for text in texts):
        example = next(text for text in texts if _DECIMAL_COMMA.match(text))
        return f'numbers such as {example!r} have decimal commas: set decimal = ","'
    if delimiter == "," and len(cells) > n_header and texts and all(_DIGITS.match(text) for text in texts):
        return ("the row has more cells than the header, all digits: the numbers seem to have decimal commas, "
                "which a comma-separated file cannot hold; save the file separated by ';' and set "
                'delimiter = ";" and decimal = ","')
    return None


def _split_thousands_hint(cells: Sequence[str], delimiter: str, n_header: int) -> str | None:
    """Why a comma-separated row has more cells than the header if an unquoted number such as
    ``1,234.5`` was split at its thousands separator, else None."""
    texts = [cell.strip() for cell in _trimmed(cells)]
    if delimiter != "," or len(texts) <= n_header:
        return None
    for head, tail in zip(texts, texts[1:]):
        if _THOUSANDS_HEAD.match(head) and _THOUSANDS_TAIL.match(tail):
            return (f"numbers such as '{head},{tail}' seem written with a thousands separator ',', which splits them "
                    f"into two cells; {_REMOVE_THOUSANDS.format(',')}")
    return None


def _thousands_hint(text: str, decimal: str) -> str | None:
    """Advice for a cell that is a number written with a thousands separator (``1,234.5``, ``1 234,5``,
    ``1.234,5``), else None."""
    for mark, pattern in _THOUSANDS.items():
        found = pattern.match(text)
        if found is None:
            continue
        separator = found.group(1)
        advice = _REMOVE_THOUSANDS.format(_SEPARATOR_NAMES.get(separator, repr(separator)))
        if mark != decimal and mark in text:
            advice += f" and set decimal = {mark!r}"
        return f"{text!r} seems written with a thousands separator: {advice}"
    return None


def _number_hint(text: str, delimiter: str, decimal: str) -> str | None:
    """Why a cell is not a number, if a decimal mark or a thousands separator explains it, else None."""
    hint = decimal_comma_hint([text], delimiter, decimal, 1) or _thousands_hint(text, decimal)
    if hint is None and decimal == "," and "." in text:
        hint = 'with decimal = "," a "." is not allowed in a number; if the file has decimal points, set decimal = "."'
    elif decimal == "," and "." in text:
        hint = f'with decimal = "," a "." is not allowed in a number: {hint}'
    return hint


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


# ------------------------------------------------------------------------------------- the table


@dataclass(frozen=True)
class CsvTable:
    """The cells of a data file as :func:`read_table` found them.

    Parameters
    ----------
    path : str
        The file.
    header : list of str
        Header cells, stripped (a comment header ``# a,b`` without its ``#``), trailing empty cells removed.
    header_line : int
        File line of the header (1-based).
    rows : list of (int, list of str)
        File line and cells of every data row (the lines after the header; blank lines at the end removed).
    skipped : tuple of int
        Lines above the header that were skipped: a ``sep=`` line, comments, text lines.
    other_header : (int, list of str) or None
        The last text line above the first data row when it is not the header: the line that looks like
        the header if a requested column is missing.
    """

    path: str
    header: list
    header_line: int
    rows: list
    skipped: tuple = ()
    other_header: tuple | None = None

    def notes(self) -> tuple[str, ...]:
        """The note on the skipped lines (empty if none)."""
        if not self.skipped:
            return ()
        lines = ", ".join(map(str, self.skipped))
        return (f"{self.path}: line{'s' if len(self.skipped) > 1 else ''} {lines} above the header (line "
                f"{self.header_line}) skipped (a sep= line, comments, text of the export)",)

    def missing_column(self, name: str) -> str:
        """Why ``name`` is not a column: the header's line and columns, and the line that looks like
        the header instead if there is one."""
        available = ", ".join(repr(cell) for cell in self.header)
        text = f"the header (line {self.header_line}) has no column {name!r}; available columns: {available}"
        close = difflib.get_close_matches(name, self.header, n=1)
        if close:
            text += f"; did you mean {close[0]!r}?"
        if self.other_header is not None:
            line, cells = self.other_header
            text += (f"; if the header is not on line {self.header_line}: line {line}, the last text line above the "
                     f"data, looks like it ({', '.join(repr(cell) for cell in cells)}) but names no column {name!r} "
                     "either; give the column names as written there (lines above the line naming them are skipped)")
        return text


def _text_lines(path: str) -> list[str]:
    """The lines of a UTF-8 text file (a BOM removed), line ends kept for :mod:`csv`."""
    try:
        with open(path, newline="", encoding="utf-8-sig") as handle:
            return handle.readlines()
    except UnicodeDecodeError as error:
        raise DataError(f"{path}: not a UTF-8 text file ({error}); {_encoding_hint(path)}") from None


def _encoding_hint(path: str) -> str:
    """What to do with a file that is not UTF-8: UTF-16 (Excel's "Unicode Text") or another encoding."""
    with open(path, "rb") as handle:
        start = handle.read(2)
    if start in (b"\xff\xfe", b"\xfe\xff"):
        return "it is UTF-16 (a spreadsheet's 'Unicode Text'): save it as 'CSV UTF-8'"
    return "save it as 'CSV UTF-8' (a spreadsheet's Latin-1 or Windows-1252 text, e.g. with 'µm', is not read)"


def _declared_separator(path: str, lines: list[str], delimiter: str) -> int:
    """1 if the first line is Excel's ``sep=X`` agreeing with ``delimiter`` (skip it), 0 if there is none.

    Raises
    ------
    DataError
        If the declared separator is not ``delimiter``.
    """
    found = _SEP_LINE.match(lines[0].rstrip("\r\n")) if lines else None
    if found is None:
        return 0
    declared = found.group(1)
    if declared == delimiter or (delimiter == " " and declared == "\t"):
        return 1
    raise DataError(f"{path}: line 1 ({lines[0].rstrip(chr(13) + chr(10))!r}) declares the cell separator {declared!r} (a spreadsheet's "
                    f"'sep=' line), but the file is read with delimiter = {delimiter!r}: set delimiter = {declared!r}")


def _check_line_breaks(path: str, rows: list) -> None:
    """Refuse a row spanning several lines: a quote that is not closed, or a quoted cell with a line break."""
    for line, cells in rows:
        if any("\n" in cell or "\r" in cell for cell in cells):
            raise DataError(f"{path}: the row of line {line} runs over several lines: a quote '\"' opened on line "
                            f"{line} is not closed, or a quoted cell holds a line break; remove it")


def _row_kind(cells: list[str], decimal: str) -> str:
    """"blank", "comment" (first cell starts with #), "data" (all non-empty cells numbers) or "text"."""
    texts = [cell.strip() for cell in cells if cell.strip()]
    if not texts:
        return "blank"
    if texts[0].startswith("#"):
        return "comment"
    return "data" if all(_is_number(text, decimal) for text in texts) else "text"


def _row_kinds(rows: list, decimal: str) -> list[str]:
    """:func:`_row_kind` of every row up to the first data row; after it, "blank" or "data" (the cells are
    read later)."""
    kinds, seen_data = [], False
    for _, cells in rows:
        if seen_data:
            kinds.append("data" if any(cell.strip() for cell in cells) else "blank")
        else:
            kinds.append(_row_kind(cells, decimal))
            seen_data = kinds[-1] == "data"
    return kinds


def _header_cells(cells: list[str]) -> list[str]:
    """Stripped header cells, a leading ``#`` (comment header) and trailing empty cells removed."""
    names = [cell.strip() for cell in _trimmed(cells)]
    if names and names[0].startswith("#"):
        names[0] = names[0].lstrip("#").strip()
    return names


def _find_header(path: str, rows: list, kinds: list[str], columns: Sequence[str]) -> tuple[int, tuple | None]:
    """Index of the header among ``rows`` and the other line that looks like a header (see
    :class:`CsvTable`)."""
    first_data = next((k for k, kind in enumerate(kinds) if kind == "data"), len(rows))
    above = [k for k in range(first_data) if kinds[k] in ("text", "comment")]
    named = [k for k in above if columns and set(columns) <= set(_header_cells(rows[k][1]))]
    texts = [k for k in above if kinds[k] == "text"]
    if named:
        return named[0], None
    if not texts:
        if first_data == len(rows):
            raise DataError(f"{path}: the file is empty (no header row, no data)")
        line, cells = rows[first_data]
        comments = " (lines starting with # are comments)" if above else ""
        raise DataError(f"{path}: row {line} looks like data ({', '.join(cell.strip() for cell in cells)}); a header "
                        f"row naming the columns is required{comments}")
    other = rows[texts[-1]] if texts[-1] != texts[0] else None
    return texts[0], None if other is None else (other[0], _header_cells(other[1]))


def read_table(path: str, delimiter: str = ",", decimal: str = ".", columns: Sequence[str] = ()) -> CsvTable:
    """The header and data rows of a CSV file, with the lines above the header skipped.

    Parameters
    ----------
    path : str
        The file (UTF-8, a BOM allowed).
    delimiter, decimal : str
        Cell separator and decimal mark, checked by :func:`check_format`.
    columns : sequence of str
        The requested column names: the header is the first line above the data naming them all.

    Returns
    -------
    CsvTable

    Raises
    ------
    DataError
        If the file is not UTF-8 or not CSV, empty, has no header, a ``sep=`` line contradicting
        ``delimiter``, or a blank line between data rows.
    """
    lines = _text_lines(path)
    start = _declared_separator(path, lines, delimiter)
    try:
        rows = list(iter_rows(lines[start:], delimiter, first_line=start + 1))
    except csv.Error as error:
        unclosed = "; a quote '\"' that is not closed makes the rest of the file one cell" if "limit" in str(error) \
            else ""
        raise DataError(f"{path}: not a readable CSV file ({error}){unclosed}") from None
    _check_line_breaks(path, rows)
    kinds = _row_kinds(rows, decimal)
    while kinds and kinds[-1] == "blank":
        rows.pop()
        kinds.pop()
    k, other = _find_header(path, rows, kinds, columns)
    for (line, _), kind in zip(rows[k + 1:], kinds[k + 1:]):
        if kind == "blank":
            raise DataError(f"{path}: row {line} is empty, between data rows")
    skipped = (*range(1, start + 1), *(line for (line, _), kind in zip(rows[:k], kinds[:k]) if kind != "blank"))
    return CsvTable(path, _header_cells(rows[k][1]), rows[k][0], rows[k + 1:], skipped, other)


def _column_indices(table: CsvTable, wanted: list[str], delimiter: str = ",") -> list[int]:
    indices = []
    for name in wanted:
        hits = [k for k, cell in enumerate(table.header) if cell == name]
        if not hits:
            guess = delimiter_hint(table.header, delimiter)
            if guess is not None:
                raise DataError(
                    f"{table.path}: the header is one cell {table.header[0]!r} when split by delimiter = "
                    f"{delimiter!r}: the file seems to be separated by {guess!r}; give delimiter = {guess!r} "
                    "(and decimal = \",\" for decimal commas)"
                )
            raise DataError(f"{table.path}: {table.missing_column(name)}")
        if len(hits) > 1:
            raise DataError(f"{table.path}: the header names column {name!r} {len(hits)} times; it is ambiguous")
        indices.append(hits[0])
    return indices


def _parse_cell(path: str, line: int, column: str, text: str, decimal: str = ".", delimiter: str = ",") -> float:
    stripped = text.strip()
    if not stripped:
        raise DataError(f"{path}: row {line}, column {column!r}: empty cell (missing value)")
    try:
        value = _to_float(stripped, decimal)
    except ValueError:
        hint = _number_hint(stripped, delimiter, decimal)
        raise DataError(
            f"{path}: row {line}, column {column!r}: {stripped!r} is not a number" + (f"; {hint}" if hint else "")
        ) from None
    if math.isnan(value):
        raise DataError(f"{path}: row {line}, column {column!r}: missing value ({stripped!r})")
    if math.isinf(value):
        raise DataError(f"{path}: row {line}, column {column!r}: {stripped!r} is not finite")
    return value


def _check_cell_count(path: str, line: int, cells: list[str], header: list[str], delimiter: str, decimal: str):
    """Refuse a row with fewer cells than the header, or more unless the extra cells are empty."""
    if len(header) in (len(cells), len(_trimmed(cells))):
        return
    hint = decimal_comma_hint(cells, delimiter, decimal, len(header)) or _split_thousands_hint(
        cells, delimiter, len(header))
    raise DataError(
        f"{path}: row {line} has {len(cells)} cells but the header has {len(header)} "
        f"({', '.join(repr(cell) for cell in header)})" + (f"; {hint}" if hint else "")
    )


def _parse_table(
    table: CsvTable,
    names: list[str],
    indices: list[int],
    decimal: str = ".",
    delimiter: str = ",",
) -> tuple[np.ndarray, np.ndarray]:
    """Values (n_rows, n_columns) of the requested columns and the file row of each data row."""
    values = np.empty((len(table.rows), len(names)))
    lines = np.empty(len(table.rows), dtype=int)
    for r, (line, cells) in enumerate(table.rows):
        _check_cell_count(table.path, line, cells, table.header, delimiter, decimal)
        lines[r] = line
        for c, (name, index) in enumerate(zip(names, indices)):
            values[r, c] = _parse_cell(table.path, line, name, cells[index], decimal, delimiter)
    return values, lines


def integer_at_least(value, minimum: int, what: str) -> int:
    """``value`` as an int, or a DataError naming ``what`` if it is not an integer >= ``minimum``."""
    try:
        value = operator.index(value)
    except TypeError:
        raise DataTypeError(f"{what} must be an integer, got {_shown(value)}") from None
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
        CSV file; the header is the first line naming the requested columns (lines above it skipped,
        see the module docstring), else the first line neither blank nor a comment.
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
        control range of the file. See the module docstring for the rule.

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
    path = _file_path(path)
    wanted = [_column_name(control_column, "control_column"), *_column_names(force_columns)]
    c_scale = _check_scale(control_unit_scale, "control_unit_scale")
    f_scale = _check_scale(force_unit_scale, "force_unit_scale")
    min_points = integer_at_least(min_points, 2, "min_points")
    delimiter, decimal = check_format(delimiter, decimal)

    table = read_table(path, delimiter, decimal, wanted)
    indices = _column_indices(table, wanted, delimiter)
    if len(table.rows) < min_points:
        raise DataError(f"{path}: {len(table.rows)} data rows, fewer than the {min_points} a curve needs")
    values, lines = _parse_table(table, wanted, indices, decimal, delimiter)
    labels = _Labels(f"{path} (control {control_column!r})", repr(control_column),
                     tuple(map(repr, wanted[1:])), "row")
    keep, notes = _checked_curve(values[:, 0] * c_scale, values[:, 1:] * f_scale, lines, backtrack_tolerance, labels)
    if keep.sum() < min_points:
        raise DataError(
            f"{path}: {int(keep.sum())} data rows left of {len(table.rows)} after dropping backtracking rows, "
            f"fewer than the {min_points} a curve needs"
        )
    scale_notes = list(table.notes())
    if c_scale != 1.0:
        scale_notes.append(f"{path}: control column {control_column!r} multiplied by {c_scale:g} to mm")
    return [
        Curve(
            control=values[keep, 0] * c_scale,
            force=values[keep, k + 1] * f_scale,
            source=f"{path}, column {name!r} against {control_column!r}",
            notes=(*scale_notes, *([f"{path}: force column {name!r} multiplied by {f_scale:g} to N"]
                                   if f_scale != 1.0 else []), *notes),
        )
        for k, name in enumerate(wanted[1:])
    ]


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
                f"negative, negate the column: {_NEGATE.format(column='force', scale='force_unit_scale')}"
            )
