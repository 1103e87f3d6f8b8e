"""The control values [mm] at which a block of y_exp is taken, chosen from the measured curves.

Two samplings (:data:`SAMPLINGS`):

- ``"equally-spaced"`` (default): n_y equally spaced values of the control quantity (the thesis's choice,
  docs/theory.md, section 3.1); the one nearest the measured peak is moved onto it, so the data keep the
  peak. Curves are interpolated linearly between their measured points.
- ``"measured"``: the measured points themselves, all of them when there are no more than n_y, else n_y of
  them chosen by arc length along the normalised curve, the ends and the peak kept (:func:`decimate`).

Curves are never extrapolated: the points lie inside every curve.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from fracid.data.arguments import integer_at_least, real_number, shown
from fracid.data.curves import Curve
from fracid.data.errors import DataError, DataTypeError

#: relative slack on range checks (rounding of the control values), fraction of the requested span
RANGE_SLACK = 1e-12


def sample_points(start: float, stop: float, n: int) -> np.ndarray:
    """n equally spaced control values from ``start`` to ``stop`` inclusive [mm].

    Raises
    ------
    DataError
        If n < 2 or not start < stop.
    """
    n = integer_at_least(n, 2, "the number of points")
    a, b = real_number(start, "the start of the control range"), real_number(stop, "the end of the control range")
    if not (math.isfinite(a) and math.isfinite(b) and a < b):
        raise DataError(f"the control range needs finite start < stop, got [{start!r}, {stop!r}] mm")
    return np.linspace(a, b, n)


#: the ``sampling`` values: equally spaced control values (the measured peak kept), or the measured points
SAMPLINGS = ("equally-spaced", "measured")


def _control_range(curves: Sequence[Curve], control_range) -> tuple[float, float, str]:
    """(start, stop, how): the sampled range inside every curve (never extrapolate)."""
    lo = max(curve.control[0] for curve in curves)
    hi = min(curve.control[-1] for curve in curves)
    if control_range is None:
        if not lo < hi:
            ranges = "; ".join(f"{c.source}: [{c.control[0]:g}, {c.control[-1]:g}] mm" for c in curves)
            raise DataError(f"the curves share no control range ({ranges})")
        return lo, hi, "the common control range of the curves"
    try:
        a, b = (real_number(v, "control_range") for v in control_range)
    except (TypeError, ValueError):
        raise DataTypeError(f"control_range must be a pair of numbers (start, stop) [mm], got "
                            f"{shown(control_range)}") from None
    sample_points(a, b, 2)  # finite start < stop
    slack = RANGE_SLACK * (b - a)
    for curve in curves:
        c0, c1 = curve.control_range
        if a < c0 - slack or b > c1 + slack:
            raise DataError(
                f"the requested control range [{a:g}, {b:g}] mm exceeds the data of {curve.source} "
                f"([{c0:g}, {c1:g}] mm); data are never extrapolated"
            )
    return max(a, lo), min(b, hi), "the requested control range"


def _measured_curve(curves: Sequence[Curve], a: float, b: float, ends: bool) -> tuple[np.ndarray, np.ndarray]:
    """The measured control values of ``curves`` in [a, b] (and a, b themselves if ``ends``) and the mean of
    the curves there: piecewise linear between these knots, so its peak is at one of them."""
    knots = np.unique(np.concatenate([c.control[(c.control >= a) & (c.control <= b)] for c in curves]
                                     + ([np.array([a, b])] if ends else [])))
    return knots, np.mean([interpolate(curve, knots) for curve in curves], axis=0)


def _with_peak(points: np.ndarray, peak: float) -> np.ndarray:
    """``points`` with the interior point nearest ``peak`` moved onto it (the count and the order kept)."""
    if np.any(points == peak) or points.size < 3:
        return points
    i = int(np.clip(np.argmin(np.abs(points - peak)), 1, points.size - 2))
    out = points.copy()
    out[i] = peak
    return out


def decimate(control, y, n: int, keep: int) -> np.ndarray:
    """Indices of n of the points (control, y), chosen by arc length along the normalised curve.

    The curve is normalised by its ranges, so more points fall where it bends or changes fast; the
    first, the last and the ``keep``-th point are always among them.

    Parameters
    ----------
    control, y : array_like, shape (m,)
        The points of the curve, ``control`` increasing [mm].
    n : int
        Number of points to keep.
    keep : int
        Index of a point to keep (e.g. the peak).

    Returns
    -------
    numpy.ndarray of int
        The kept indices, increasing; all of them when m <= n.

    Examples
    --------
    >>> decimate([0.0, 1.0, 2.0, 3.0, 4.0], [0.0, 1.0, 2.0, 1.0, 0.0], 3, keep=2).tolist()
    [0, 2, 4]
    """
    control, y = np.asarray(control, float), np.asarray(y, float)
    if control.size <= n:
        return np.arange(control.size)
    u = (control - control[0]) / (control[-1] - control[0])
    v = y / max(float(np.max(np.abs(y))), np.finfo(float).tiny)
    s = np.concatenate([[0.0], np.cumsum(np.hypot(np.diff(u), np.diff(v)))])
    must = sorted({0, control.size - 1, int(keep)})
    targets = list(np.linspace(0.0, s[-1], n))
    for i in must:  # each kept point takes the place of the target nearest to it
        targets.pop(int(np.argmin(np.abs(np.array(targets) - s[i]))))
    taken = set(must)
    for t in targets:
        taken.add(_nearest_free(s, t, taken))
    return np.array(sorted(taken))


def _nearest_free(s: np.ndarray, target: float, taken: set) -> int:
    """The index of s (increasing) nearest ``target`` that is not taken."""
    hi = int(np.searchsorted(s, target))
    lo = hi - 1
    while lo >= 0 and lo in taken:
        lo -= 1
    while hi < s.size and hi in taken:
        hi += 1
    if hi >= s.size or (lo >= 0 and target - s[lo] <= s[hi] - target):
        return lo
    return hi


def resolve_points(curves: Sequence[Curve], n_points: int, control_range, sampling: str = "equally-spaced",
                   reference: Sequence[Curve] | None = None) -> tuple[np.ndarray, str]:
    """The control values of a block, inside every curve, and a note saying where they come from.

    Parameters
    ----------
    curves : sequence of Curve
        The curves the block is built from; the points lie inside each of them (never extrapolate).
    n_points : int
        Number of points n_y (at most, for ``"measured"``).
    control_range : (float, float) or None
        (start, stop) [mm]; None for the common range of the curves.
    sampling : {"equally-spaced", "measured"}
        See the module docstring.
    reference : sequence of Curve, optional
        The curves whose mean is the measured curve (default all): its peak is always one of the
        points, so the data keep the measured peak exactly.

    Returns
    -------
    points : numpy.ndarray, shape (n,)
        Control values [mm], increasing.
    note : str
        The sampling rule, for ``ExperimentalData.notes``.

    Raises
    ------
    DataError
        If ``sampling`` is unknown, the range exceeds a curve or holds fewer than 2 measured points.
    """
    if sampling not in SAMPLINGS:
        raise DataError(f"sampling = {sampling!r}; choose " + " or ".join(map(repr, SAMPLINGS)))
    a, b, how = _control_range(curves, control_range)
    n = integer_at_least(n_points, 2, "the number of points")
    measured = sampling == "measured"
    knots, values = _measured_curve(reference or curves, a, b, ends=not measured)
    if knots.size < 2:
        raise DataError(f"sampling = 'measured': fewer than 2 measured points in [{a:g}, {b:g}] mm")
    peak = int(np.argmax(np.abs(values)))
    if measured:
        return _measured_points(knots, n, peak, values, how)
    return _equally_spaced_points(a, b, n, knots[peak], abs(values[peak]), how)


def _measured_points(knots: np.ndarray, n: int, peak: int, values: np.ndarray, how: str) -> tuple[np.ndarray, str]:
    """(points, note): n of the measured ``knots`` by :func:`decimate`, the ends and the ``peak``-th kept."""
    kept = decimate(knots, values, n, peak)
    points = knots[kept]
    chosen = (f"all the {knots.size} measured points" if kept.size == knots.size else
              f"{kept.size} of the {knots.size} measured points, chosen by arc length along the normalised "
              "curve (the ends and the peak kept)")
    return points, (f"{chosen} from {points[0]:.6g} to {points[-1]:.6g} mm ({how}); no interpolation of the "
                    "mean curve")


def _equally_spaced_points(a: float, b: float, n: int, peak: float, peak_y: float, how: str) -> tuple[np.ndarray, str]:
    """(points, note): n equally spaced values from a to b [mm], the nearest interior one moved onto ``peak``."""
    grid = sample_points(a, b, n)
    points = _with_peak(grid, peak)
    moved = "is one of them" if np.array_equal(points, grid) else "replaces the nearest of them"
    return points, (
        f"{len(points)} equally spaced control points from {points[0]:.6g} to {points[-1]:.6g} mm "
        f"(step {(b - a) / (n - 1):.6g} mm, {how}); the measured peak ({peak:.6g} mm, |y| = "
        f"{peak_y:.6g}) {moved}; curves interpolated linearly, never extrapolated"
    )


def interpolate(curve: Curve, points: np.ndarray) -> np.ndarray:
    """The force of ``curve`` at ``points`` [mm], interpolated linearly (``points`` inside the curve)."""
    return np.interp(points, curve.control, curve.force)
