"""The checks of a measured curve before use: the sign and direction of its control, the backtracking rule.

Direction of the control, checked before the backtracking rule, so that the message names the cause: a
control that is mostly negative (a test recorded with a negative sign) is refused with the advice to
negate it; a control decreasing throughout (rows in reverse order) with the advice to sort the rows; a
control that rises and falls back while a force column increases throughout with the advice to swap the
columns. None of these is corrected silently.

Backtracking rule (the only point-dropping rule; it is always reported in ``Curve.notes``): a row is
kept only if its control value exceeds the maximum control value of all earlier rows (the running
maximum). A row lying more than ``backtrack_tolerance`` below that running maximum is not noise but a
defect (unloading, a spliced file, a wrong column) and raises :class:`~fracid.data.errors.DataError`;
smaller backtracks, and repeated control values, are measurement noise and the row is dropped.

Forces: a curve whose forces are all <= 0 is refused by :func:`require_positive_force`.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from fracid.data.arguments import real_number
from fracid.data.errors import DataError

if TYPE_CHECKING:
    from fracid.data.curves import Curve

#: default backtrack tolerance as a fraction of the control range of the file
DEFAULT_BACKTRACK_FRACTION = 0.01

#: a control falling back from its peak by this fraction of its range, beside a force column increasing
#: throughout, is taken for swapped columns
_SWAPPED_FALL = 0.2

#: how a column is negated (no key of [[experiments]] does it)
_NEGATE = ('set negate = ["{column}"] in its [[experiments]] block, or multiply it by -1 in the file (from Python: '
           'read_curve_csv(..., {scale}=-1))')

#: how many dropped rows a note lists explicitly
_MAX_LISTED_ROWS = 10


@dataclass(frozen=True)
class Labels:
    """How the direction checks name the data: ``where`` (file or source), the control and force
    columns, and what a point is (``"row"`` of a file, ``"index"`` of an array)."""

    where: str
    control: str
    forces: tuple[str, ...]
    unit: str


def _check_tolerance(backtrack_tolerance, control: np.ndarray, where: str) -> float:
    """The backtrack tolerance [mm]: ``backtrack_tolerance`` checked, or by default 1 % of the control range."""
    if backtrack_tolerance is None:
        return DEFAULT_BACKTRACK_FRACTION * float(np.max(control) - np.min(control))
    tolerance = real_number(backtrack_tolerance, f"{where}: backtrack_tolerance")
    if not (math.isfinite(tolerance) and tolerance >= 0.0):
        raise DataError(f"{where}: backtrack_tolerance must be a finite value >= 0 [mm], got {backtrack_tolerance!r}")
    return tolerance


def checked_curve(control: np.ndarray, forces: np.ndarray, rows: np.ndarray, backtrack_tolerance,
                  labels: Labels) -> tuple[np.ndarray, tuple[str, ...]]:
    """The direction checks, then the backtracking rule: the mask of kept points and its note."""
    tolerance = _check_tolerance(backtrack_tolerance, control, labels.where)
    _check_direction(control, forces, rows, tolerance, labels)
    return _monotonic_mask(control, rows, tolerance, labels.where, labels.unit)


def _check_direction(control: np.ndarray, forces: np.ndarray, rows: np.ndarray, tolerance: float,
                     labels: Labels) -> None:
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
    labels : Labels
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


def _check_control_sign(control: np.ndarray, forces: np.ndarray, rows: np.ndarray, labels: Labels) -> None:
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
