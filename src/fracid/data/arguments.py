"""Checks of the arguments of :mod:`fracid.data`'s functions: numbers, arrays, integers, column names, paths.

Each check returns the value as the function uses it, or raises a :class:`~fracid.data.errors.DataTypeError`
(an argument of the wrong type, also a ``TypeError``) or a :class:`~fracid.data.errors.DataError` (a value
out of range), naming the argument.
"""

from __future__ import annotations

import math
import numbers
import operator
import os
import reprlib
from collections.abc import Sequence

import numpy as np

from fracid.data.errors import DataError, DataTypeError

def shown(value) -> str:
    """A short repr of an argument, and its type, for messages."""
    return f"{reprlib.repr(value)} ({type(value).__name__})"


def real_number(value, what: str) -> float:
    """``value`` as a float if it is a real number (not a bool, not a str), else a DataTypeError."""
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise DataTypeError(f"{what} must be a number, got {shown(value)}")
    return float(value)


def numeric_array(values, what: str) -> np.ndarray:
    """A float copy of ``values`` if they are numbers (int or float; no str, bool or complex)."""
    try:
        raw = np.asarray(values)
    except (TypeError, ValueError):  # ragged nested sequences
        raise DataTypeError(f"{what} must be an array of numbers, got {shown(values)}") from None
    numeric = raw.dtype.kind in "iuf" or (
        raw.dtype.kind == "O" and all(isinstance(v, numbers.Real) and not isinstance(v, bool) for v in raw.flat)
    )
    if not numeric:
        raise DataTypeError(f"{what} must be an array of numbers (int or float), got {shown(values)} "
                            f"of dtype {raw.dtype}")
    return raw.astype(float)


def readonly_vector(values, what: str) -> np.ndarray:
    """A read-only float copy of ``values``, one-dimensional and finite, else an error naming ``what``."""
    array = numeric_array(values, what)
    if array.ndim != 1:
        raise DataError(f"{what} must be one-dimensional, got shape {array.shape}")
    if not np.all(np.isfinite(array)):
        bad = int(np.flatnonzero(~np.isfinite(array))[0])
        raise DataError(f"{what} holds a non-finite value ({float(array[bad]):g}) at index {bad}")
    array.setflags(write=False)
    return array


def integer_at_least(value, minimum: int, what: str) -> int:
    """``value`` as an int, or a DataError naming ``what`` if it is not an integer >= ``minimum``."""
    try:
        value = operator.index(value)
    except TypeError:
        raise DataTypeError(f"{what} must be an integer, got {shown(value)}") from None
    if value < minimum:
        raise DataError(f"{what} must be >= {minimum}, got {value}")
    return value


def unit_scale(value, name: str) -> float:
    """A unit multiplier: a finite non-zero number (negative: the column is negated)."""
    scale = real_number(value, name)
    if not math.isfinite(scale) or scale == 0.0:
        raise DataError(f"{name} must be a finite non-zero number (negative to negate the column), got {value!r}")
    return scale


def column_name(value, what: str) -> str:
    """A column name: a non-empty str, else a DataTypeError (DataError if empty) naming ``what``."""
    if not isinstance(value, str):
        raise DataTypeError(f"{what} must be a column name (str), got {shown(value)}")
    if not value.strip():
        raise DataError(f"{what} must be a column name, got an empty string")
    return value


def force_column_names(force_columns) -> list[str]:
    """The ``force_columns`` argument as a list of column names (one name, or a non-empty sequence of them)."""
    if isinstance(force_columns, str):
        return [column_name(force_columns, "force_columns")]
    if not isinstance(force_columns, Sequence):
        raise DataTypeError(f"force_columns must be a column name (str) or a list of names, "
                            f"got {shown(force_columns)}")
    if not force_columns:
        raise DataError("force_columns is empty: give a column name or a list of names")
    return [column_name(name, f"force_columns[{k}]") for k, name in enumerate(force_columns)]


def file_path(path) -> str:
    """``path`` as a str (from str, bytes or os.PathLike), else a DataTypeError."""
    try:
        return os.fsdecode(os.fspath(path))
    except TypeError:
        raise DataTypeError(f"path must be a file path (str or os.PathLike), got {shown(path)}") from None
