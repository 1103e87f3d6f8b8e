"""Builders of y_exp and C_exp from measured curves, by documented rules.

A block of y_exp holds forces [N] at the control values [mm] chosen by :mod:`fracid.data.sampling`
(equally spaced with the measured peak kept, or the measured points themselves), or local data (e.g. FPZ
width [mm], :func:`local_block`). Its covariance is diagonal, from the scatter of repeated tests
(:func:`from_repeats`), from a min/max envelope (:func:`from_envelope`), or from a standard deviation the
user gives (:func:`with_std`); blocks are stacked block-diagonally by :func:`stack`
(:mod:`fracid.data.dataset`).

Every rule applied is written to ``ExperimentalData.notes``: the sampling, the scatter rule, the
standard-deviation floor, the points dropped while reading. Curves are interpolated linearly and never
extrapolated.

The standard deviations, their floor (``std_floor``) and the covariance: :mod:`fracid.data.covariance`.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence

import numpy as np

from fracid.data.arguments import numeric_array, shown
from fracid.data.covariance import (
    DEFAULT_STD_FLOOR,
    apply_floor,
    check_floor,
    check_positive_std,
    diagonal_data,
    envelope_divisor,
)
from fracid.data.curves import Curve
from fracid.data.dataset import ExperimentalData
from fracid.data.errors import DataError, DataTypeError
from fracid.data.sampling import RANGE_SLACK, interpolate, resolve_points


def _curve_notes(curves: Sequence[Curve]) -> list[str]:
    """Notes of the curves, each once, in order."""
    return list(dict.fromkeys(note for curve in curves for note in curve.notes))


def _as_curves(curves) -> list[Curve]:
    """``curves`` (a Curve or an iterable of them) as a list of Curve; DataError or DataTypeError otherwise."""
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
        Floor on the standard deviation as a fraction of the peak ``|mean|`` (see module docstring).
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
    points, sampling = resolve_points(curves, n_points, control_range, sampling)
    forces = np.array([interpolate(curve, points) for curve in curves])
    y = forces.mean(axis=0)
    s = forces.std(axis=0, ddof=1)
    s, floor_notes = apply_floor(s, y, points, check_floor(std_floor))
    sources = "; ".join(curve.source for curve in curves)
    notes = [
        *_curve_notes(curves),
        sampling,
        f"y = mean of {len(curves)} repeated curves ({sources})",
        f"s = sample standard deviation of the {len(curves)} repeats (ddof = 1); covariance diag(s^2)",
        *floor_notes,
    ]
    return diagonal_data(points, y, s, name, notes)


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
        Floor on s as a fraction of the peak ``|mean|`` (see module docstring).
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
    divisor = envelope_divisor(rule)
    curves = _as_curves([mean_curve, lower_curve, upper_curve])
    points, sampling = resolve_points(curves, n_points, control_range, sampling, reference=curves[:1])
    y, lower, upper = (interpolate(curve, points) for curve in curves)
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
    s, floor_notes = apply_floor(s, y, points, check_floor(std_floor))
    return diagonal_data(points, y, s, name, [*notes, *floor_notes])


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
        Standard deviation: absolute [N] (> 0), or with ``relative=True`` a fraction of ``|y|`` at each point.
    n_points : int
        Number of sampling points n_y.
    control_range : (float, float), optional
        (start, stop) [mm]; default the whole curve.
    name : str
        Block name.
    relative : bool
        Read ``std`` as a fraction of ``|y|`` per point; the floor then applies (``|y|`` may vanish).
    std_floor : float
        Floor on s as a fraction of the peak ``|y|``, relative std only.
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
    points, sampling = resolve_points([curve], n_points, control_range, sampling)
    y = interpolate(curve, points)
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
        s, floor_notes = apply_floor(s, y, points, check_floor(std_floor))
        notes += floor_notes
    else:
        check_positive_std(given, f"block {name!r}: std")
        s = np.array(given, dtype=float)
        text = f"{float(given[0]):g} N" if np.ndim(std) == 0 else "per-point values [N]"
        notes.append(f"s = {text} given by the user (absolute); covariance diag(s^2)")
    return diagonal_data(points, y, s, name, notes)


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
        slack = RANGE_SLACK * (c1 - c0)
        if sample.min() < c0 - slack or sample.max() > c1 + slack:
            raise DataError(
                f"points [{sample.min():g}, {sample.max():g}] mm exceed the local series {series.source} "
                f"([{c0:g}, {c1:g}] mm); data are never extrapolated"
            )
        y = interpolate(series, np.clip(sample, c0, c1))
        notes.append(f"{len(y)} local values interpolated linearly at the given points ({series.source})")
    given = numeric_array(std, "std")
    s = np.full(y.shape, float(given)) if given.ndim == 0 else given
    if s.shape != y.shape or not np.all(np.isfinite(s)):
        raise DataError(f"std must be a finite number or have shape ({len(y)},), got {np.shape(std)}")
    check_positive_std(s, f"block {name!r}: std")
    notes.append("s given by the user (absolute); covariance diag(s^2)")
    return diagonal_data(sample, y, s, name, notes)


# ------------------------------------------------------------------------------------ removed names


def _moved(old: str, new: str):
    """A marker for a removed name: calling it raises TypeError naming where the bundled data are now."""
    def removed(*args, **kwargs):
        raise TypeError(f"fracid.data.{old}() was removed: the bundled data have one home and one loader, "
                        f"fracid.datasets; use {new}")
    removed.__name__ = removed.__qualname__ = old
    removed.__doc__ = f"Removed: use {new} (:mod:`fracid.datasets`); calling it raises TypeError."
    return removed


gregoire2013_beam4 = _moved(
    "gregoire2013_beam4", "fracid.datasets.load('gregoire2013-beam4') (the demo's data), or from_envelope on "
    "the curves of read_curve_csv(fracid.datasets.path('gregoire2013-beam4'), control_column='cmod_mm', "
    "force_columns=['load_mean_N', 'load_min_N', 'load_max_N'])")
gregoire2013_beam4_path = _moved("gregoire2013_beam4_path", "fracid.datasets.path('gregoire2013-beam4')")
