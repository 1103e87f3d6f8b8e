"""A testing machine's log: time, control (CMOD, stroke ...) and force as the machine exports them, read into
seconds, millimetres and newtons, and its values interpolated at given times (the DIC frames').

The file is a CSV read by :func:`fracid.data.table.read_table` (any ``delimiter``, decimal commas, the text lines
a machine writes above the column names: test name, date, operator). Rows of text between the column names and
the first number (a units row such as ``s;kN;mm``, a line of dashes) are skipped. A unit the file declares for a
column (in its units row, or in brackets in its name, ``Force [kN]``) must agree with the unit given: a log read
in N when it says kN would be 1000 times off. The time must increase strictly (a machine restarting its clock,
two tests in one file, or a sorted export are refused, naming the row).
"""

from __future__ import annotations

import re
from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np

from fracid.data.cells import is_number
from fracid.data.errors import DataError
from fracid.data.table import check_format, column_indices, parse_table, read_table
from fracid.settings.checks import show

#: time unit -> multiplier to s
TIME_UNITS = {"s": 1.0, "ms": 1e-3, "min": 60.0}
#: length unit (control, opening, displacement) -> multiplier to mm
LENGTH_UNITS = {"mm": 1.0, "um": 1e-3, "m": 1e3}
#: force unit -> multiplier to N
FORCE_UNITS = {"N": 1.0, "kN": 1e3}
#: the quantity of every unit, and the unit a log's column is read into
_KINDS = {**{u: "time" for u in TIME_UNITS}, **{u: "length" for u in LENGTH_UNITS},
          **{u: "force" for u in FORCE_UNITS}}
_SCALES = {**TIME_UNITS, **LENGTH_UNITS, **FORCE_UNITS}
_BASE = {"time": "s", "length": "mm", "force": "N"}
#: other spellings of the units found in machines' exports
_ALIASES = {"sec": "s", "secs": "s", "µm": "um", "μm": "um", "micron": "um", "kn": "kN", "n": "N"}
#: a unit in brackets in a column name or a units row: ``Force [kN]``, ``Zeit (s)``
_BRACKETED = re.compile(r"[\[(]\s*([^\])]+?)\s*[\])]")


def unit_scale(unit: str, what: str) -> float:
    """The multiplier turning ``unit`` into s, mm or N (``what`` names the argument in the message).

    Raises
    ------
    DataError
        If ``unit`` is not one of :data:`TIME_UNITS`, :data:`LENGTH_UNITS`, :data:`FORCE_UNITS`.
    """
    if unit not in _SCALES:
        raise DataError(f"{what} = {show(unit)}: give a unit of {', '.join(map(repr, _SCALES))}")
    return _SCALES[unit]


def declared_unit(text: str) -> str | None:
    """The unit a cell declares (``"kN"``, ``"[kN]"``, ``"Force (kN)"``, ``"µm"``), None if it names none."""
    found = _BRACKETED.search(text)
    word = (found.group(1) if found else text).strip()
    word = _ALIASES.get(word, _ALIASES.get(word.lower(), word))
    return word if word in _SCALES else None


@dataclass(frozen=True)
class MachineLog:
    """A testing machine's log in s, mm and N.

    Parameters
    ----------
    path : str
        The file read.
    time : numpy.ndarray, shape (n,)
        The time of every sample [s], strictly increasing.
    columns : dict of str -> numpy.ndarray
        The other columns read, by their name in the file, in mm (lengths) or N (forces).
    units : dict of str -> str
        The unit of each of ``columns`` after reading: "mm" or "N".
    rows : numpy.ndarray of int
        The file line of every sample (for messages).
    time_column : str
        The name of the time column in the file.
    notes : tuple of str
        What was done while reading (lines skipped, units converted).
    """

    path: str
    time: np.ndarray
    columns: dict = field(default_factory=dict)
    units: dict = field(default_factory=dict)
    rows: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=int))
    time_column: str = "time"
    notes: tuple = ()

    def at(self, times, labels=None, what: str = "frame") -> dict:
        """Every column interpolated (linearly) at ``times`` [s].

        Parameters
        ----------
        times : array_like, shape (m,)
            Times on the log's clock [s].
        labels : sequence or None
            What each time is, for messages (frame numbers); None: its position.
        what : str
            The word for one of them in messages.

        Raises
        ------
        DataError
            If a time is outside the log's time range, naming it, its time and the range.
        """
        times = np.asarray(times, dtype=float)
        labels = list(range(len(times))) if labels is None else list(labels)
        outside = np.flatnonzero((times < self.time[0]) | (times > self.time[-1]) | ~np.isfinite(times))
        if outside.size:
            k = int(outside[0])
            listed = ", ".join(f"{what} {labels[j]} at t = {times[j]:.6g} s" for j in outside[:5])
            raise DataError(f"{self.path}: {listed} outside the log's time range {self.time[0]:.6g} to "
                            f"{self.time[-1]:.6g} s (column {show(self.time_column)}, rows {self.rows[0]} to "
                            f"{self.rows[-1]}); the {what}s must be taken while the machine logs: check the "
                            f"synchronisation (offset, frame rate) or leave {what} {labels[k]} out")
        return {name: np.interp(times, self.time, values) for name, values in self.columns.items()}


def _skip_units_rows(table, decimal: str):
    """The table without the text rows between its header and its first number row, and those rows."""
    k = 0
    while k < len(table.rows) and not any(is_number(c, decimal) for c in table.rows[k][1] if c.strip()):
        k += 1
    return table.rows[:k], table.rows[k:]


def _check_declared(path: str, header: list[str], units_rows, name: str, index: int, unit: str) -> None:
    """Refuse ``unit`` for column ``name`` if the file declares another (in its name or its units rows)."""
    places = [(f"its name {show(name)}", declared_unit(name))]
    places += [(f"line {line}", declared_unit(cells[index])) for line, cells in units_rows if index < len(cells)]
    for where, declared in places:
        if declared is None or declared == unit:
            continue
        kind, given = _KINDS[declared], _KINDS[unit]
        why = (f"a {kind}, not a {given}: is it the right column?" if kind != given else
               f"reading it as {unit} would be {_SCALES[declared] / _SCALES[unit]:g} times off: give {declared!r}")
        raise DataError(f"{path}: column {show(name)} is declared in {declared} ({where}) but read in {unit}; {why}")


def _check_increasing(path: str, name: str, time: np.ndarray, rows: np.ndarray, unit: str) -> None:
    """Refuse a time column (in the file's ``unit``) that does not increase strictly, naming the first row where it
    does not."""
    bad = np.flatnonzero(np.diff(time) <= 0.0)
    if bad.size:
        k = int(bad[0])
        raise DataError(f"{path}: column {show(name)} must increase strictly, but row {rows[k + 1]} ({time[k + 1]:g} "
                        f"{unit}) does not follow row {rows[k]} ({time[k]:g} {unit}){'' if bad.size == 1 else f' ({bad.size} rows)'}; "
                        "a log with two tests or a restarted clock is split into one file per test")


def read_machine_log(path, time_column: str, columns: Mapping[str, str], time_unit: str = "s",
                     delimiter: str = ",", decimal: str = ".") -> MachineLog:
    """Read a testing machine's export.

    Parameters
    ----------
    path : str or os.PathLike
        The CSV file.
    time_column : str
        The column of the time.
    columns : mapping of str -> str
        The other columns to read and their unit (``{"CMOD": "um", "Force": "kN"}``): lengths in
        :data:`LENGTH_UNITS` (read into mm), forces in :data:`FORCE_UNITS` (read into N).
    time_unit : str
        The unit of the time column, one of :data:`TIME_UNITS`.
    delimiter, decimal : str
        Cell separator and decimal mark (:func:`fracid.data.table.check_format`).

    Returns
    -------
    MachineLog

    Raises
    ------
    DataError
        Naming the file, column and row: a missing column, a cell that is not a number, a unit the file declares
        otherwise, a time that does not increase strictly, fewer than 2 rows.
    """
    path = str(path)
    delimiter, decimal = check_format(delimiter, decimal)
    if _KINDS.get(time_unit) != "time":
        raise DataError(f"time unit {show(time_unit)}: give one of {', '.join(map(repr, TIME_UNITS))}")
    for name, unit in columns.items():
        if _KINDS.get(unit) not in ("length", "force"):
            raise DataError(f"column {show(name)}: unit {show(unit)} is not a length ({', '.join(LENGTH_UNITS)}) or a "
                            f"force ({', '.join(FORCE_UNITS)})")
    units = {time_column: time_unit, **columns}
    try:
        table = read_table(path, delimiter, decimal, columns=list(units))
    except OSError as error:
        raise DataError(f"machine log {path}: cannot be read ({error.strerror or error})") from None
    indices = column_indices(table, list(units), delimiter)
    units_rows, rows = _skip_units_rows(table, decimal)
    for (name, unit), index in zip(units.items(), indices):
        _check_declared(path, table.header, units_rows, name, index, unit)
    values, lines = parse_table(type(table)(table.path, table.header, table.header_line, rows), list(units), indices,
                                decimal, delimiter)
    if len(lines) < 2:
        raise DataError(f"{path}: {len(lines)} data row(s) below the header (line {table.header_line}); a log needs at "
                        "least 2")
    _check_increasing(path, time_column, values[:, 0], lines, time_unit)
    values = values * np.array([_SCALES[unit] for unit in units.values()])
    skipped = [line for line, _ in units_rows]
    notes = (*table.notes(), *([f"{path}: line(s) {skipped} below the header skipped (units)"] if skipped else []),
             f"{path}: {len(lines)} samples, {time_column} in {time_unit}, " +
             ", ".join(f"{name} in {unit}" for name, unit in columns.items()) + " (read into s, mm, N)")
    return MachineLog(path, values[:, 0], {name: values[:, 1 + k] for k, name in enumerate(columns)},
                      {name: _BASE[_KINDS[unit]] for name, unit in columns.items()}, lines, time_column, notes)


__all__ = ["FORCE_UNITS", "LENGTH_UNITS", "MachineLog", "TIME_UNITS", "declared_unit", "read_machine_log", "unit_scale"]
