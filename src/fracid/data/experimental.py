"""The measured vector y_exp and its covariance C_exp, built from curves by documented rules.

y_exp holds forces [N] at n_y equally spaced values of the control quantity [mm] (the thesis's choice,
docs/theory.md, section 3.1; the one nearest the measured peak is moved onto it, so the data keep the
peak), or at the measured points themselves (``sampling="measured"``), optionally followed by local data
(e.g. FPZ width [mm]). Its covariance is diagonal per
block, from the scatter of repeated tests, from a min/max envelope, or from a standard deviation
the user gives; several blocks (specimens, local data) are stacked block-diagonally.

Every rule applied is written to ``ExperimentalData.notes``: the sampling, the scatter rule, the
standard-deviation floor, the points dropped while reading. Curves are interpolated linearly and never
extrapolated.

Standard-deviation floor: a standard deviation below ``std_floor`` times the peak |y| of the block
(default 1 %) is raised to that value and the points concerned are listed in the notes; without it, a
point where the repeats or the envelope happen to coincide (s = 0) would get an infinite weight.
"""

from __future__ import annotations

import math
import operator
import re
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, replace
from importlib import resources
from pathlib import Path

import numpy as np
import scipy.linalg

from fracid.data.arguments import integer_at_least, numeric_array, real_number, shown
from fracid.data.curves import Curve, read_curve_csv
from fracid.data.errors import DataError, DataTypeError

#: default standard-deviation floor, fraction of the peak |y| of a block
DEFAULT_STD_FLOOR = 0.01

#: relative slack on range checks (rounding of the control values), fraction of the requested span
_RANGE_SLACK = 1e-12


@dataclass(frozen=True, eq=False)
class ExperimentalData:
    """Measured vector y_exp, its sampling points and covariance C_exp.

    Parameters
    ----------
    control : array_like, shape (n_y,)
        Control value [mm] at which each entry of ``y`` is taken.
    y : array_like, shape (n_y,)
        Measured values: forces [N] (global blocks) or local quantities (e.g. width [mm]).
    covariance : array_like, shape (n_y, n_y)
        Covariance C_exp [N^2, or the local unit squared], symmetric positive definite.
    blocks : tuple of (str, int, int)
        (name, start, stop) of each stacked block: ``y[start:stop]``; contiguous, covering all of
        ``y``, names unique.
    notes : tuple of str
        Every rule applied to build the data.

    Raises
    ------
    DataError
        If shapes disagree, values are not finite, the covariance is not symmetric positive definite
        or the blocks do not tile ``y``.
    """

    control: np.ndarray
    y: np.ndarray
    covariance: np.ndarray
    blocks: tuple[tuple[str, int, int], ...]
    notes: tuple[str, ...] = ()

    def __post_init__(self):
        control = np.array(self.control, dtype=float)
        y = np.array(self.y, dtype=float)
        cov = np.array(self.covariance, dtype=float)
        if y.ndim != 1 or y.size == 0:
            raise DataError(f"y must be a non-empty one-dimensional array, got shape {y.shape}")
        n = y.size
        if control.shape != (n,):
            raise DataError(f"control must have shape ({n},) like y, got {control.shape}")
        if cov.shape != (n, n):
            raise DataError(f"covariance must have shape ({n}, {n}), got {cov.shape}")
        for what, array in (("control", control), ("y", y), ("covariance", cov)):
            if not np.all(np.isfinite(array)):
                raise DataError(f"{what} holds non-finite values")
        if not np.allclose(cov, cov.T, rtol=0.0, atol=1e-12 * float(np.max(np.abs(cov)))):
            raise DataError("covariance is not symmetric")
        try:
            np.linalg.cholesky(cov)
        except np.linalg.LinAlgError:
            raise DataError("covariance is not positive definite (a zero or negative variance?)") from None
        blocks = _check_blocks(self.blocks, n)
        for array in (control, y, cov):
            array.setflags(write=False)
        object.__setattr__(self, "control", control)
        object.__setattr__(self, "y", y)
        object.__setattr__(self, "covariance", cov)
        object.__setattr__(self, "blocks", blocks)
        object.__setattr__(self, "notes", tuple(str(note) for note in self.notes))

    @property
    def n_y(self) -> int:
        """Number of entries of y."""
        return int(self.y.size)

    @property
    def std(self) -> np.ndarray:
        """Standard deviation of each entry, sqrt(diag(covariance)) [N or the local unit]."""
        return np.sqrt(np.diag(self.covariance))

    def weighted(self, weights: dict) -> "ExperimentalData":
        """The data with block weights p_b: f = sum_b p_b f_b (docs/theory.md, section 3.3, e.g. p1 global, p2 local).

        The objective f = r^T C^-1 r of a block times p_b is the objective with its covariance
        divided by p_b, so the Kalman filter and KNN see the same weighting.

        Parameters
        ----------
        weights : dict of str -> float
            Block name -> p_b > 0; blocks not named keep p = 1.
        """
        scale = np.ones(self.n_y)
        names = [b[0] for b in self.blocks]
        for name, p in weights.items():
            if name not in names:
                raise DataError(f"weight for block {name!r}: no such block; blocks: {', '.join(names)}")
            if not (np.isfinite(p) and p > 0):
                raise DataError(f"weight of block {name!r} = {p!r}: it must be a number > 0")
            scale[self.block(name)] = 1.0 / np.sqrt(p)
        notes = [f"block {name!r} weighted p = {p:g} (covariance divided by p)" for name, p in weights.items() if p != 1]
        return replace(self, covariance=self.covariance * np.outer(scale, scale), notes=self.notes + tuple(notes))

    def block(self, name: str) -> slice:
        """Slice of ``y`` holding the block ``name``."""
        for block_name, start, stop in self.blocks:
            if block_name == name:
                return slice(start, stop)
        raise KeyError(f"no block {name!r}; blocks: {', '.join(b[0] for b in self.blocks)}")


def _check_blocks(blocks, n: int) -> tuple[tuple[str, int, int], ...]:
    try:
        checked = tuple((str(name), operator.index(start), operator.index(stop)) for name, start, stop in blocks)
    except (TypeError, ValueError):
        raise DataError(f"blocks must be (name, start, stop) triples with integer bounds, got {blocks!r}") from None
    if not checked:
        raise DataError("blocks is empty: give at least one (name, start, stop)")
    expected = 0
    for name, start, stop in checked:
        if start != expected or stop <= start:
            raise DataError(f"blocks must tile y contiguously from 0 to {n}; block {name!r} is [{start}, {stop})")
        expected = stop
    if expected != n:
        raise DataError(f"blocks must tile y contiguously from 0 to {n}; they end at {expected}")
    names = [b[0] for b in checked]
    if len(set(names)) != len(names):
        raise DataError(f"block names must be unique, got {names}")
    return checked


# ------------------------------------------------------------------------------------- sampling


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
    slack = _RANGE_SLACK * (b - a)
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
    return knots, np.mean([_interpolate(curve, knots) for curve in curves], axis=0)


def _with_peak(points: np.ndarray, peak: float) -> np.ndarray:
    """``points`` with the interior point nearest ``peak`` moved onto it (the count and the order kept)."""
    if np.any(points == peak) or points.size < 3:
        return points
    i = int(np.clip(np.argmin(np.abs(points - peak)), 1, points.size - 2))
    out = points.copy()
    out[i] = peak
    return out


def decimate(control, y, n: int, keep: int) -> np.ndarray:
    """Indices of n of the points (control, y), chosen by arc length along the curve normalised by its
    ranges (more points where it bends or changes fast), the first, the last and ``keep`` among them.

    All the indices when there are no more than n points.
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


def _resolve_points(curves: Sequence[Curve], n_points: int, control_range, sampling: str = "equally-spaced",
                    reference: Sequence[Curve] | None = None) -> tuple[np.ndarray, str]:
    """Sampling points inside every curve and a note saying where they come from (never extrapolate).

    ``reference``: the curves whose mean is the measured curve (default all): its peak is always a
    sampling point, so the data keep the measured peak exactly.
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
        kept = decimate(knots, values, n, peak)
        points = knots[kept]
        chosen = (f"all the {knots.size} measured points" if kept.size == knots.size else
                  f"{kept.size} of the {knots.size} measured points, chosen by arc length along the normalised "
                  "curve (the ends and the peak kept)")
        return points, (f"{chosen} from {points[0]:.6g} to {points[-1]:.6g} mm ({how}); no interpolation of the "
                        "mean curve")
    grid = sample_points(a, b, n)
    points = _with_peak(grid, knots[peak])
    moved = "is one of them" if np.array_equal(points, grid) else "replaces the nearest of them"
    return points, (
        f"{len(points)} equally spaced control points from {points[0]:.6g} to {points[-1]:.6g} mm "
        f"(step {(b - a) / (n - 1):.6g} mm, {how}); the measured peak ({knots[peak]:.6g} mm, |y| = "
        f"{abs(values[peak]):.6g}) {moved}; curves interpolated linearly, never extrapolated"
    )


def _interpolate(curve: Curve, points: np.ndarray) -> np.ndarray:
    return np.interp(points, curve.control, curve.force)


def _curve_notes(curves: Sequence[Curve]) -> list[str]:
    """Notes of the curves, each once, in order."""
    return list(dict.fromkeys(note for curve in curves for note in curve.notes))


def _check_floor(std_floor) -> float:
    value = real_number(std_floor, "std_floor")
    if not (math.isfinite(value) and value >= 0.0):
        raise DataError(f"std_floor must be a finite fraction >= 0, got {std_floor!r}")
    return value


def _apply_floor(s: np.ndarray, y: np.ndarray, points: np.ndarray, std_floor: float) -> tuple[np.ndarray, list[str]]:
    """Raise s to std_floor * peak |y| where it is smaller; note which points."""
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


def _check_positive_std(s: np.ndarray, what: str) -> None:
    if not np.all(s > 0.0):
        raise DataError(f"{what}: every standard deviation must be > 0 (a zero variance gives infinite weight)")


def _diagonal_data(points, y, s, name: str, notes: list[str]) -> ExperimentalData:
    if np.any(s <= 0.0):
        raise DataError(
            f"block {name!r}: a standard deviation is zero (the scatter vanishes at some point); "
            "use std_floor > 0 or give the standard deviation explicitly"
        )
    return ExperimentalData(
        control=points, y=y, covariance=np.diag(s**2), blocks=((str(name), 0, len(y)),), notes=tuple(notes)
    )


def _as_curves(curves) -> list[Curve]:
    if isinstance(curves, Curve):
        curves = [curves]
    if isinstance(curves, (str, bytes)) or not isinstance(curves, Iterable):
        raise DataTypeError(f"expected a list of Curve objects, got {shown(curves)}")
    curves = list(curves)
    for curve in curves:
        if not isinstance(curve, Curve):
            raise DataError(f"expected Curve objects, got {type(curve).__name__}")
    return curves


# ---------------------------------------------------------------------------------- builders


def from_repeats(
    curves: Sequence[Curve],
    n_points: int,
    control_range: tuple[float, float] | None = None,
    name: str = "global",
    *,
    std_floor: float = DEFAULT_STD_FLOOR,
    sampling: str = "equally-spaced",
) -> ExperimentalData:
    """y_exp and C_exp from repeated tests: mean and sample variance at the sampling points.

    Parameters
    ----------
    curves : sequence of Curve
        Repeated tests on nominally equal specimens, at least 2.
    n_points : int
        Number of sampling points n_y.
    control_range : (float, float), optional
        (start, stop) [mm]; default the common range of all curves. Must lie inside every curve.
    name : str
        Block name.
    std_floor : float
        Floor on the standard deviation as a fraction of the peak |mean| (see module docstring).
    sampling : {"equally-spaced", "measured"}
        See :func:`with_std`; the measured points are those of all the repeats (the knots of their mean).

    Returns
    -------
    ExperimentalData
        y = mean over the curves [N], covariance = diag(s^2) with s the sample standard deviation
        (ddof = 1) [N], floored.

    Raises
    ------
    DataError
        With fewer than 2 curves, or a range beyond the data.
    """
    curves = _as_curves(curves)
    if len(curves) < 2:
        raise DataError(
            f"from_repeats needs at least 2 curves to estimate a covariance, got {len(curves)}; "
            "a covariance needs repeats, or a min/max envelope (from_envelope), or an explicit std (with_std)"
        )
    points, sampling = _resolve_points(curves, n_points, control_range, sampling)
    forces = np.array([_interpolate(curve, points) for curve in curves])
    y = forces.mean(axis=0)
    s = forces.std(axis=0, ddof=1)
    s, floor_notes = _apply_floor(s, y, points, _check_floor(std_floor))
    sources = "; ".join(curve.source for curve in curves)
    notes = [
        *_curve_notes(curves),
        sampling,
        f"y = mean of {len(curves)} repeated curves ({sources})",
        f"s = sample standard deviation of the {len(curves)} repeats (ddof = 1); covariance diag(s^2)",
        *floor_notes,
    ]
    return _diagonal_data(points, y, s, name, notes)


_RULE = re.compile(r"^range/(\d+(?:\.\d*)?)$")


def _envelope_divisor(rule: str) -> float:
    match = _RULE.match(str(rule).replace(" ", ""))
    if not match or float(match.group(1)) <= 0.0:
        raise DataError(f"unknown envelope rule {rule!r}; use 'range/k' with k > 0, e.g. 'range/4' (s = (max - min)/4)")
    return float(match.group(1))


def from_envelope(
    mean_curve: Curve,
    lower_curve: Curve,
    upper_curve: Curve,
    n_points: int,
    control_range: tuple[float, float] | None = None,
    rule: str = "range/4",
    name: str = "global",
    *,
    std_floor: float = DEFAULT_STD_FLOOR,
    sampling: str = "equally-spaced",
) -> ExperimentalData:
    """y_exp and C_exp from a mean curve and its min/max envelope.

    Parameters
    ----------
    mean_curve, lower_curve, upper_curve : Curve
        Mean, lower (min) and upper (max) envelope of the repeated tests [N].
    n_points : int
        Number of sampling points n_y.
    control_range : (float, float), optional
        (start, stop) [mm]; default the common range of the three curves.
    rule : str
        ``"range/k"``: s = (max - min)/k per point; the default k = 4 reads the envelope as
        mean -/+ 2 s.
    name : str
        Block name.
    std_floor : float
        Floor on s as a fraction of the peak |mean| (see module docstring).
    sampling : {"equally-spaced", "measured"}
        See :func:`with_std`; the measured points and the peak are the mean curve's.

    Returns
    -------
    ExperimentalData
        y = mean [N], covariance = diag(s^2) [N^2]; the rule is written in ``notes``.

    Raises
    ------
    DataError
        If the lower envelope exceeds the upper one, the rule is unknown or the range exceeds the data.
    """
    divisor = _envelope_divisor(rule)
    curves = _as_curves([mean_curve, lower_curve, upper_curve])
    points, sampling = _resolve_points(curves, n_points, control_range, sampling, reference=curves[:1])
    y, lower, upper = (_interpolate(curve, points) for curve in curves)
    width = upper - lower
    crossing = np.flatnonzero(width < -1e-12 * np.max(np.abs(y)))
    if crossing.size:
        i = int(crossing[0])
        raise DataError(
            f"the lower envelope ({lower_curve.source}) exceeds the upper one ({upper_curve.source}) "
            f"at control {points[i]:g} mm ({lower[i]:g} > {upper[i]:g} N); columns swapped?"
        )
    notes = [*_curve_notes(curves), sampling, f"y = {mean_curve.source}"]
    outside = np.flatnonzero((y < lower) | (y > upper))
    if outside.size:
        notes.append(f"the mean lies outside the envelope at {outside.size} of {len(points)} points")
    s = np.maximum(width, 0.0) / divisor
    notes.append(
        f"s = (max - min)/{divisor:g} from the min/max envelope (rule {rule!r}; lower {lower_curve.source}, "
        f"upper {upper_curve.source}); covariance diag(s^2)"
    )
    s, floor_notes = _apply_floor(s, y, points, _check_floor(std_floor))
    return _diagonal_data(points, y, s, name, [*notes, *floor_notes])


def with_std(
    curve: Curve,
    std,
    n_points: int,
    control_range: tuple[float, float] | None = None,
    name: str = "global",
    *,
    relative: bool = False,
    std_floor: float = DEFAULT_STD_FLOOR,
    sampling: str = "equally-spaced",
) -> ExperimentalData:
    """y_exp from a single curve with a standard deviation given by the user.

    Parameters
    ----------
    curve : Curve
        The measured curve.
    std : float or array_like, shape (n_points,)
        Standard deviation: absolute [N] (> 0), or with ``relative=True`` a fraction of |y| at each point.
    n_points : int
        Number of sampling points n_y.
    control_range : (float, float), optional
        (start, stop) [mm]; default the whole curve.
    name : str
        Block name.
    relative : bool
        Read ``std`` as a fraction of |y| per point; the floor then applies (|y| may vanish).
    std_floor : float
        Floor on s as a fraction of the peak |y|, relative std only.
    sampling : {"equally-spaced", "measured"}
        ``"equally-spaced"`` (default): n_points equally spaced control values, the one nearest the
        measured peak moved onto it (the data keep the peak exactly). ``"measured"``: the measured points
        themselves, all of them when there are no more than n_points, else n_points of them chosen by arc
        length along the normalised curve, the ends and the peak kept (:func:`decimate`).

    Returns
    -------
    ExperimentalData
        y = the curve at the points [N], covariance = diag(s^2).
    """
    curve = _as_curves([curve])[0]
    points, sampling = _resolve_points([curve], n_points, control_range, sampling)
    y = _interpolate(curve, points)
    given = numeric_array(std, "std")
    if given.ndim == 0:
        given = np.full(y.shape, float(given))
    if given.shape != y.shape:
        raise DataError(f"std must be a number or have shape ({len(y)},) like the points, got {given.shape}")
    if not np.all(np.isfinite(given)) or np.any(given < 0.0):
        raise DataError("std must hold finite values >= 0")
    notes = [*_curve_notes([curve]), sampling, f"y = {curve.source}"]
    if relative:
        s = given * np.abs(y)
        text = f"{float(given[0]):g}" if np.ndim(std) == 0 else "per-point fractions"
        notes.append(f"s = {text} x |y| given by the user (relative); covariance diag(s^2)")
        s, floor_notes = _apply_floor(s, y, points, _check_floor(std_floor))
        notes += floor_notes
    else:
        _check_positive_std(given, f"block {name!r}")
        s = np.array(given, dtype=float)
        text = f"{float(given[0]):g} N" if np.ndim(std) == 0 else "per-point values [N]"
        notes.append(f"s = {text} given by the user (absolute); covariance diag(s^2)")
    return _diagonal_data(points, y, s, name, notes)


def local_block(values_series, std, name: str = "local", *, points=None) -> ExperimentalData:
    """A block of local data (e.g. FPZ width [mm]) with a standard deviation given by the user.

    Parameters
    ----------
    values_series : Curve or (control, values) pair
        The local quantity against the control [mm]; control strictly increasing. For a
        :class:`Curve`, its ``force`` field holds the local values (in their own unit).
    std : float or array_like
        Standard deviation of the values, absolute (same unit), > 0; one number or one per point.
    name : str
        Block name.
    points : array_like, optional
        Control values [mm] to sample at (linear interpolation, never extrapolation), e.g. the
        points of the global block; default the series' own control values.

    Returns
    -------
    ExperimentalData
        y = the values, covariance = diag(std^2).
    """
    if isinstance(values_series, Curve):
        series = values_series
    else:
        try:
            control, values = values_series
        except (TypeError, ValueError):
            raise DataError("values_series must be a Curve or a (control, values) pair of arrays") from None
        series = Curve(control=control, force=values, source=f"local series {name!r}")
    notes = list(series.notes)
    if points is None:
        sample = np.array(series.control)
        y = np.array(series.force)
        notes.append(f"{len(y)} local values at their own control points ({series.source})")
    else:
        sample = numeric_array(points, "points")
        if sample.ndim != 1 or sample.size == 0 or not np.all(np.isfinite(sample)):
            raise DataError("points must be a non-empty one-dimensional array of finite values [mm]")
        c0, c1 = series.control_range
        slack = _RANGE_SLACK * (c1 - c0)
        if sample.min() < c0 - slack or sample.max() > c1 + slack:
            raise DataError(
                f"points [{sample.min():g}, {sample.max():g}] mm exceed the local series {series.source} "
                f"([{c0:g}, {c1:g}] mm); data are never extrapolated"
            )
        y = _interpolate(series, np.clip(sample, c0, c1))
        notes.append(f"{len(y)} local values interpolated linearly at the given points ({series.source})")
    given = numeric_array(std, "std")
    s = np.full(y.shape, float(given)) if given.ndim == 0 else given
    if s.shape != y.shape or not np.all(np.isfinite(s)):
        raise DataError(f"std must be a finite number or have shape ({len(y)},), got {np.shape(std)}")
    _check_positive_std(s, f"block {name!r}")
    notes.append("s given by the user (absolute); covariance diag(s^2)")
    return _diagonal_data(sample, y, s, name, notes)


def _unique_name(name: str, used: set[str]) -> str:
    if name not in used:
        return name
    k = 2
    while f"{name}_{k}" in used:
        k += 1
    return f"{name}_{k}"


def stack(*datasets: ExperimentalData) -> ExperimentalData:
    """Stack datasets into one y_exp with a block-diagonal covariance.

    Block names are made unique by appending ``_2``, ``_3``, ... to repeated names (noted); each
    dataset's notes are kept, prefixed by its (final) block names.

    Raises
    ------
    DataError
        If no dataset is given or an argument is not ExperimentalData.
    """
    if not datasets:
        raise DataError("stack needs at least one ExperimentalData")
    for k, data in enumerate(datasets):
        if not isinstance(data, ExperimentalData):
            raise DataError(f"stack argument {k + 1} is {type(data).__name__}, not ExperimentalData")
    used: set[str] = set()
    blocks, renames, notes_per_data = [], [], []
    offset = 0
    for k, data in enumerate(datasets):
        final = []
        for name, start, stop in data.blocks:
            new = _unique_name(name, used)
            used.add(new)
            if new != name:
                renames.append(f"block {name!r} of dataset {k + 1} renamed {new!r} (block names must be unique)")
            blocks.append((new, start + offset, stop + offset))
            final.append(new)
        notes_per_data.append([f"[{'+'.join(final)}] {note}" for note in data.notes])
        offset += data.n_y
    layout = ", ".join(f"{name} [{start}:{stop})" for name, start, stop in blocks)
    notes = [f"stacked {len(datasets)} datasets, block-diagonal covariance: {layout}", *renames]
    for data_notes in notes_per_data:
        notes += data_notes
    return ExperimentalData(
        control=np.concatenate([d.control for d in datasets]),
        y=np.concatenate([d.y for d in datasets]),
        covariance=scipy.linalg.block_diag(*[d.covariance for d in datasets]),
        blocks=tuple(blocks),
        notes=tuple(notes),
    )


# ------------------------------------------------------------------------------------ bundled data


def gregoire2013_beam4_path() -> Path:
    """Path of the bundled load-CMOD CSV of Gregoire et al. (2013), beam 4 (see its README.md).

    Columns: ``cmod_mm`` [mm], ``load_mean_N``, ``load_min_N``, ``load_max_N`` [N].
    """
    ref = resources.files("fracid.data") / "gregoire2013_beam4" / "load_cmod.csv"
    path = Path(str(ref))
    if not path.is_file():
        raise DataError(
            f"bundled data file missing: {path}; the package data of fracid.data was not installed "
            "(pyproject [tool.setuptools.package-data])"
        )
    return path


def gregoire2013_beam4(n_points: int = 40, control_range: tuple[float, float] | None = None,
                       sampling: str = "equally-spaced") -> ExperimentalData:
    """The bundled real test of Gregoire, Rojas-Solano & Pijaudier-Cabot (2013) as y_exp.

    Notched three-point bending beam, D = 50 mm; control CMOD [mm], force = load [N]. Built with
    :func:`from_envelope` on the mean, min and max columns, rule s = (max - min)/4.

    Parameters
    ----------
    n_points : int
        Number of CMOD values (equally spaced, the measured peak kept, by default).
    control_range : (float, float), optional
        CMOD range [mm]; default the whole recorded range.
    sampling : {"equally-spaced", "measured"}
        See :func:`with_std`.

    Returns
    -------
    ExperimentalData
        One block ``"gregoire2013_beam4"``; notes hold the envelope rule and the backtracking row.
    """
    mean, lower, upper = read_curve_csv(
        gregoire2013_beam4_path(),
        control_column="cmod_mm",
        force_columns=["load_mean_N", "load_min_N", "load_max_N"],
    )
    return from_envelope(mean, lower, upper, n_points, control_range, rule="range/4", name="gregoire2013_beam4",
                         sampling=sampling)
