"""The standard deviation s of each point of a block and its diagonal covariance diag(s^2).

Standard-deviation floor: a standard deviation below ``std_floor`` times the peak ``|y|`` of the block
(default :data:`DEFAULT_STD_FLOOR`, 1 %) is raised to that value and the points concerned are listed in
the notes; without it, a point where the repeats or the envelope happen to coincide (s = 0) would get an
infinite weight.

Envelope rule ``"range/k"``: s = (max - min)/k per point; k = 4 reads a min/max envelope as mean -/+ 2 s.
"""

from __future__ import annotations

import math
import re

import numpy as np

from fracid.data.arguments import real_number
from fracid.data.covariance_matrix import Diagonal
from fracid.data.dataset import ExperimentalData
from fracid.data.errors import DataError

#: default standard-deviation floor, fraction of the peak |y| of a block
DEFAULT_STD_FLOOR = 0.01

#: the smallest and largest standard deviation whose square is a finite positive normal float (any unit)
STD_RANGE = (math.sqrt(np.finfo(float).tiny), math.sqrt(np.finfo(float).max) * (1.0 - 1e-15))

#: what a standard deviation may be, in words (for messages)
STD_ALLOWED = (f"> 0 with a square that is a normal number: between {STD_RANGE[0]:.3g} and {STD_RANGE[1]:.3g} in "
               "the unit of the values")

_RULE = re.compile(r"^range/(\d+(?:\.\d*)?)$")


def check_floor(std_floor) -> float:
    """``std_floor`` as a float, checked finite and >= 0 (a fraction of the peak ``|y|``)."""
    value = real_number(std_floor, "std_floor")
    if not (math.isfinite(value) and value >= 0.0):
        raise DataError(f"std_floor must be a finite fraction >= 0, got {std_floor!r}")
    return value


def apply_floor(s: np.ndarray, y: np.ndarray, points: np.ndarray, std_floor: float) -> tuple[np.ndarray, list[str]]:
    """Raise s to std_floor * peak ``|y|`` where it is smaller.

    Parameters
    ----------
    s, y, points : numpy.ndarray, shape (n,)
        Standard deviations, values and control values [mm] of the block.
    std_floor : float
        The floor, a fraction of the peak ``|y|`` (checked by :func:`check_floor`).

    Returns
    -------
    s : numpy.ndarray, shape (n,)
        The floored standard deviations.
    notes : list of str
        One note listing the points raised, or none.
    """
    floor = std_floor * float(np.max(np.abs(y)))
    low = np.flatnonzero(s < floor)
    if low.size == 0:
        return s, []
    listed = ", ".join(f"{points[i]:.4g}" for i in low[:10]) + (" ..." if low.size > 10 else "")
    note = (
        f"standard deviation floor {std_floor:g} x peak |y| = {floor:.4g}: s raised to it at "
        f"{low.size} of {s.size} points (control {listed} mm) where it was smaller "
        f"(smallest {float(s[low].min()):.4g}); s = 0 would give a point infinite weight"
    )
    return np.maximum(s, floor), [note]


def unusable_variances(var) -> np.ndarray:
    """True where a variance [units of y squared] cannot enter a covariance: not finite, or not a positive normal
    float (a std whose square underflows to 0 or to a subnormal number gives an infinite or inexact weight)."""
    var = np.asarray(var, dtype=float)
    with np.errstate(invalid="ignore"):
        return ~(np.isfinite(var) & (var >= np.finfo(float).tiny))


def usable_std(value) -> bool:
    """Whether the standard deviation ``value`` is > 0 and its square a finite positive normal float:
    between :data:`STD_RANGE`'s bounds (about 1.5e-154 and 1.3e154 in any unit)."""
    return bool(STD_RANGE[0] <= value <= STD_RANGE[1])


def check_positive_std(s, what: str) -> None:
    """Raise DataError, naming ``what`` (e.g. "block 'global': std"), the first bad value and how many there are,
    unless every standard deviation in ``s`` is > 0 with a square that is a finite positive normal float
    (:func:`unusable_variances`)."""
    s = np.atleast_1d(np.asarray(s, dtype=float))
    with np.errstate(over="ignore", under="ignore", invalid="ignore"):
        bad = np.flatnonzero(unusable_variances(np.square(s)) | ~(s > 0.0))
    if bad.size:
        i = int(bad[0])
        where = f" (at {bad.size} of {s.size} values, the first at index {i})" if s.size > 1 else ""
        raise DataError(f"{what} = {s[i]:.3g}{where}: every standard deviation must be {STD_ALLOWED} (a zero "
                        "variance gives infinite weight; a std beyond that range is a unit mistake)")


def envelope_divisor(rule: str) -> float:
    """k of the envelope rule ``"range/k"`` (k > 0); DataError for any other rule."""
    match = _RULE.match(str(rule).replace(" ", ""))
    if not match or float(match.group(1)) <= 0.0:
        raise DataError(f"unknown envelope rule {rule!r}; use 'range/k' with k > 0, e.g. 'range/4' (s = (max - min)/4)")
    return float(match.group(1))


def diagonal_data(points, y, s, name: str, notes: list[str]) -> ExperimentalData:
    """One block ``name``: y at ``points`` [mm] with covariance diag(s^2); DataError if some s is zero."""
    if np.any(s <= 0.0):
        raise DataError(
            f"block {name!r}: a standard deviation is zero (the scatter vanishes at some point); "
            "use std_floor > 0 or give the standard deviation explicitly"
        )
    check_positive_std(s, f"block {name!r}: std")
    return ExperimentalData(
        control=points, y=y, covariance=Diagonal(s**2), blocks=((str(name), 0, len(y)),), notes=tuple(notes)
    )
