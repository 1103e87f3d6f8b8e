"""Fit diagnostics: where the curve computed at the estimate departs from the measured one.

The RMS error alone hides a model that is stiffer than the test or whose peak is well below the
measured one. :func:`fit_diagnostics` compares, per force block, the elastic slope and the peak of the
data and of the computed curve, and locates the worst residual; :func:`diagnostic_warnings` turns
departures larger than :data:`SLOPE_TOLERANCE` and :data:`PEAK_TOLERANCE` (and than
:data:`SIGNIFICANCE` standard deviations of the data) into warnings that name the likely causes.

Every function is pure, over arrays: ``control`` [mm] (or None: the point index stands for it),
measured ``y``, computed ``y_fit`` and the data's ``std`` (unit of y: N for forces), and the data
``blocks`` ``(name, start, stop)``. The computed values are known only at the data's control values
(the forward operator samples its runs there), so the computed slope and peak are those of the
computed curve at the data points: a computed peak between two data points is not seen.
"""

from __future__ import annotations

import math

import numpy as np

from fracid.inverse.core.observations import FORCE

#: relative difference of the elastic slopes (computed / measured - 1) above which a warning is given [-]
SLOPE_TOLERANCE = 0.10
#: relative difference of the peak forces (computed / measured - 1) above which a warning is given [-]
PEAK_TOLERANCE = 0.10
#: the elastic part of a block: the points of its rising branch (before the measured peak) whose
#: |force| is at most this fraction of the measured peak's [-]
ELASTIC_FRACTION = 0.35
#: a difference of slopes or peaks is warned about only when it also exceeds this many standard
#: deviations of the data (of the fitted slope, or at the peak) [-]: a few noisy points give no warning
SIGNIFICANCE = 2.0
#: what the diagnostics can see of the computed curve
SAMPLING_NOTE = ("the computed curve is known at the data's control values only: its slope and peak are "
                 "those at the data points")


def measures_force(quantity: str | None) -> bool:
    """Whether a data block of the observed ``quantity`` holds forces [N]: its quantity is the force, or unknown
    (a result that records none: the force is a block's default quantity). The block's name is not read."""
    return not quantity or quantity == FORCE


def block_peak(y) -> int | None:
    """Index of the value of largest magnitude among the finite values of ``y`` (None if there is none)."""
    y = np.asarray(y, float)
    finite = np.isfinite(y)
    return int(np.argmax(np.where(finite, np.abs(y), -np.inf))) if finite.any() else None


def elastic_points(y, fraction: float = ELASTIC_FRACTION) -> np.ndarray:
    """Indices of the elastic part of a measured force block: the points before its peak whose |y| is at
    most ``fraction`` of |peak|, and at least the first two points of the rising branch (none when the
    peak is the first point)."""
    y = np.asarray(y, float)
    peak = block_peak(y)
    if peak is None or peak < 1:
        return np.array([], int)
    rising = np.arange(peak + 1)
    low = rising[np.abs(y[rising]) <= fraction * abs(y[peak])]
    return low if low.size >= 2 else rising[:2]


def line_slope(x, y, std=None) -> tuple[float, float]:
    """Least-squares slope of y against x (with an intercept, weights 1 / std^2) and its standard
    deviation from ``std`` (NaN without it). Units: those of y per those of x (N/mm for forces).
    NaN when fewer than two distinct x or a non-finite value."""
    x, y = np.asarray(x, float), np.asarray(y, float)
    w = np.ones_like(x) if std is None else 1.0 / np.asarray(std, float) ** 2
    if x.size < 2 or not np.all(np.isfinite(np.concatenate([x, y, w]))):
        return math.nan, math.nan
    centred = x - np.sum(w * x) / np.sum(w)
    spread = float(np.sum(w * centred**2))
    if spread <= 0:
        return math.nan, math.nan
    slope = float(np.sum(w * centred * y) / spread)
    return slope, (math.sqrt(1.0 / spread) if std is not None else math.nan)


def block_diagnostics(x, y, std, y_fit) -> dict:
    """Elastic slope and peak of one force block, measured and computed at the same points.

    Parameters
    ----------
    x : ndarray
        Control values [mm] (or point indices) of the block.
    y, std, y_fit : ndarray
        Measured values, their std and the computed values (N).

    Returns
    -------
    dict
        ``elastic_points`` (how many), ``slope_data``, ``slope_model`` [N/mm], ``slope_std`` (of the
        data's slope), ``slope_ratio`` (model / data), ``peak_data``, ``peak_model`` [N],
        ``peak_std`` (the data's std at its peak), ``peak_ratio``, ``control_peak_data``,
        ``control_peak_model`` [mm] (NaN where not computed).
    """
    points = elastic_points(y)
    slope_data, slope_std = line_slope(x[points], y[points], std[points])
    slope_model, _ = line_slope(x[points], y_fit[points])
    i, j = block_peak(y), block_peak(y_fit)
    peak_data = float(y[i]) if i is not None else math.nan
    peak_model = float(y_fit[j]) if j is not None else math.nan
    return {"elastic_points": int(points.size), "slope_data": slope_data, "slope_model": slope_model,
            "slope_std": slope_std, "slope_ratio": _ratio(slope_model, slope_data),
            "peak_data": peak_data, "peak_model": peak_model, "peak_std": float(std[i]) if i is not None else math.nan,
            "peak_ratio": _ratio(peak_model, peak_data),
            "control_peak_data": float(x[i]) if i is not None else math.nan,
            "control_peak_model": float(x[j]) if j is not None else math.nan}


def _ratio(a: float, b: float) -> float:
    return a / b if math.isfinite(a) and math.isfinite(b) and b != 0 else math.nan


def worst_residual(control, y, std, y_fit, blocks) -> dict | None:
    """The point of largest |computed - measured| / std: ``index`` in y, ``block``, ``control``,
    ``measured``, ``computed`` and ``residual_std`` (signed, in units of the data's std); None when no
    point has a finite residual and a std > 0."""
    scaled = (np.asarray(y_fit, float) - y) / np.where(std > 0, std, np.nan)
    if not np.any(np.isfinite(scaled)):
        return None
    k = int(np.nanargmax(np.abs(scaled)))
    block = next((name for name, start, stop in blocks if start <= k < stop), "")
    return {"index": k, "block": block, "control": float(control[k]), "measured": float(y[k]),
            "computed": float(y_fit[k]), "residual_std": float(scaled[k])}


def fit_diagnostics(control, y, std, y_fit, blocks=(), quantities=()) -> dict:
    """Diagnostics of a fit: per force block :func:`block_diagnostics`, and the worst residual.

    Parameters
    ----------
    control : array_like or None
        Control value of every entry of y [mm]; None: the point index in its block stands for it
        (slopes are then per point, and their ratio holds for evenly spaced points only).
    y, std, y_fit : array_like, shape (n,)
        Measured values, their standard deviations and the values computed at the estimate (unit of
        y: N for forces, mm for widths).
    blocks : sequence of (name, start, stop)
        Data blocks of y (one block ``"data"`` when empty).
    quantities : sequence of str
        Observed quantity of each block (``"force"``, ``"fpz_width"``, ...: the observations' ``quantity``);
        a block of unknown quantity is taken for a force (:func:`measures_force`).

    Returns
    -------
    dict
        ``blocks``: per force block ``{"block", ...}`` of :func:`block_diagnostics`; ``worst``:
        :func:`worst_residual`; ``control``: ``"mm"`` or ``"index"``; ``note``: :data:`SAMPLING_NOTE`.
    """
    y, std, y_fit = (np.asarray(a, float) for a in (y, std, y_fit))
    blocks = [(str(b[0]), int(b[1]), int(b[2])) for b in (blocks or [])] or [("data", 0, y.size)]
    x = np.concatenate([np.arange(b - a, dtype=float) for _, a, b in blocks]) if control is None \
        else np.asarray(control, float)
    quantities = list(quantities or []) + [None] * len(blocks)
    out = []
    for (name, start, stop), quantity in zip(blocks, quantities):
        if measures_force(quantity) and stop > start:
            part = slice(start, stop)
            out.append({"block": name, **block_diagnostics(x[part], y[part], std[part], y_fit[part])})
    return {"blocks": out, "worst": worst_residual(x, y, std, y_fit, blocks),
            "control": "index" if control is None else "mm", "note": SAMPLING_NOTE}


def _departs(ratio: float, tolerance: float, difference: float, std: float) -> bool:
    """A departure above ``tolerance`` and, when the data's std is known, above SIGNIFICANCE std."""
    if not math.isfinite(ratio) or abs(ratio - 1.0) <= tolerance:
        return False
    return not (math.isfinite(std) and abs(difference) <= SIGNIFICANCE * std)


def slope_warning(d: dict, tolerance: float = SLOPE_TOLERANCE) -> str | None:
    """The warning of a block whose computed elastic slope departs from the measured one, or None."""
    ratio = d["slope_ratio"]
    if not _departs(ratio, tolerance, d["slope_model"] - d["slope_data"], d["slope_std"]):
        return None
    way = "stiffer" if ratio > 1 else "softer"
    return (f"the model is {100 * abs(ratio - 1):.0f} % {way} than the data in block {d['block']!r} (elastic slope "
            f"{d['slope_model']:.4g} against {d['slope_data']:.4g} measured, over the first {d['elastic_points']} "
            f"points "
            f"below {100 * ELASTIC_FRACTION:.0f} % of the peak; above {100 * tolerance:g} %): check the specimen's "
            "geometry (e.g. the notch depth, the ligament, the thickness, the span or length), E, and the units "
            "(force_unit, control_unit); a soft start of the test (seating, the machine's compliance in the "
            "measured control) lowers the measured slope")


def peak_warning(d: dict, tolerance: float = PEAK_TOLERANCE) -> str | None:
    """The warning of a block whose computed peak departs from the measured one, or None."""
    ratio = d["peak_ratio"]
    if not _departs(ratio, tolerance, d["peak_model"] - d["peak_data"], d["peak_std"]):
        return None
    way = "below" if ratio < 1 else "above"
    return (f"the model's peak is {100 * abs(ratio - 1):.0f} % {way} the measured one in block {d['block']!r} "
            f"({d['peak_model']:.4g} at control {d['control_peak_model']:.4g} against {d['peak_data']:.4g} at "
            f"{d['control_peak_data']:.4g}; above {100 * tolerance:g} %): likely causes: the strength parameters "
            "(e.g. ft, kappa_i) fixed or bounded away from the data's (an estimate at a bound), a model that cannot "
            "give this peak and this softening together (the filter traded the peak for the post-peak points, "
            "which are more numerous), the specimen's size or thickness, or the units (force_unit)")


def diagnostic_warnings(diagnostics: dict, slope_tolerance: float = SLOPE_TOLERANCE,
                        peak_tolerance: float = PEAK_TOLERANCE) -> list[str]:
    """The slope and peak warnings of :func:`fit_diagnostics`'s blocks, block by block."""
    out = []
    for d in diagnostics.get("blocks", []):
        out += [w for w in (slope_warning(d, slope_tolerance), peak_warning(d, peak_tolerance)) if w]
    return out


def diagnostics_lines(diagnostics: dict) -> list[str]:
    """The diagnostics in a few lines of text (the summary's): per force block the elastic slopes and
    peaks, computed against measured, then the worst residual."""
    unit = "mm" if diagnostics.get("control") == "mm" else "(point index)"
    lines = []
    for d in diagnostics.get("blocks", []):
        lines.append(f"{d['block']}: elastic slope model/data {_percent(d['slope_ratio'])}, peak {d['peak_model']:.4g} "
                     f"at {d['control_peak_model']:.4g} against {d['peak_data']:.4g} at {d['control_peak_data']:.4g} "
                     f"{unit} measured (model/data {_percent(d['peak_ratio'])})")
    worst = diagnostics.get("worst")
    if worst:
        lines.append(f"worst residual: {worst['residual_std']:+.3g} std at point {worst['index']} (block "
                     f"{worst['block']!r}, control {worst['control']:.4g} {unit}: computed {worst['computed']:.4g}, "
                     f"measured {worst['measured']:.4g})")
    return lines


def _percent(ratio: float) -> str:
    return f"{100 * ratio:.0f} %" if math.isfinite(ratio) else "n/a"


__all__ = ["ELASTIC_FRACTION", "PEAK_TOLERANCE", "SAMPLING_NOTE", "SIGNIFICANCE", "SLOPE_TOLERANCE",
           "block_diagnostics", "block_peak", "diagnostic_warnings", "diagnostics_lines", "elastic_points",
           "fit_diagnostics", "measures_force", "line_slope", "worst_residual"]
