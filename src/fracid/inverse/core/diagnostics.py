"""Fit diagnostics: where the curve computed at the estimate departs from the measured one.

The RMS error alone hides a model that is stiffer than the test or whose peak is well below the
measured one. :func:`fit_diagnostics` compares, per force block, the elastic slope and the peak of the
data and of the computed curve, and locates the worst residual; :func:`diagnostic_warnings` turns
departures larger than :data:`SLOPE_TOLERANCE` and :data:`PEAK_TOLERANCE` (and than
:data:`SIGNIFICANCE` standard deviations of the data) into warnings that name the likely causes.

Every function is pure, over arrays: ``control`` [mm] (or None: the point index stands for it),
measured ``y``, computed ``y_fit`` and the data's ``std`` (unit of y: N for forces), and the data
``blocks`` ``(name, start, stop)``. The computed curve is either the forward run's own (all its steps,
``curves``: the result of an identification keeps it) or, without it, its values at the data's control
values only (:data:`SAMPLING_NOTE`).

The elastic slope of a curve is its initial stiffness: the line through the origin (a run starts from
rest: no force at control 0; the data are taken to be zeroed the same way) fitted to the points of the
curve's *own* rising branch (before its own peak) up to :data:`ELASTIC_FRACTION` of its own peak. A model
twice as stiff as the test peaks earlier: at the data's points it may already be past its peak, so neither
the data's elastic points nor an intercept fit over two points say anything about its slope. When a curve
has no point that low (its first point is already higher up), the secant to its first point is a *lower
bound* of its initial slope (a rising branch that softens only lowers the secant): the comparison then
states only the direction that bound supports, and says when it cannot tell.
"""

from __future__ import annotations

import math

import numpy as np

from fracid.inverse.core.observations import FORCE

#: relative difference of the elastic slopes (computed / measured - 1) above which a warning is given [-]
SLOPE_TOLERANCE = 0.10
#: relative difference of the peak forces (computed / measured - 1) above which a warning is given [-]
PEAK_TOLERANCE = 0.10
#: the elastic part of a curve: the points of its rising branch (before its own peak) whose |force| is at
#: most this fraction of its own peak's [-]
ELASTIC_FRACTION = 0.35
#: a difference of slopes or peaks is warned about only when it also exceeds this many standard
#: deviations of the data (of the fitted slope, or at the peak) [-]: a few noisy points give no warning
SIGNIFICANCE = 2.0
#: what the diagnostics can see of the computed curve without the run's own curve
SAMPLING_NOTE = ("the computed curve is known at the data's control values only: its slope and peak are "
                 "those at the data points (a computed peak between two data points is not seen)")
#: ... and with it
RUN_CURVE_NOTE = ("the computed slope and peak are those of the forward run's own curve at the estimate (all "
                  "its steps up to the data's last control value)")


def measures_force(quantity: str | None) -> bool:
    """Whether a data block of the observed ``quantity`` holds forces [N]: its quantity is the force, or unknown
    (a result that records none: the force is a block's default quantity). The block's name is not read."""
    return not quantity or quantity == FORCE


def block_peak(y) -> int | None:
    """Index of the value of largest magnitude among the finite values of ``y`` (None if there is none)."""
    y = np.asarray(y, float)
    finite = np.isfinite(y)
    return int(np.argmax(np.where(finite, np.abs(y), -np.inf))) if finite.any() else None


def block_curve(curves, index: int) -> tuple[np.ndarray, np.ndarray] | None:
    """The run's own curve of block ``index`` of ``curves`` (a result's ``curves``: per block None or
    ``{"control": [mm], "values": [unit of the block]}``) as two float arrays of its finite steps, or None
    when there is none (or fewer than two finite steps)."""
    curves = list(curves or [])
    curve = curves[index] if 0 <= index < len(curves) else None
    if not isinstance(curve, dict) or curve.get("control") is None or curve.get("values") is None:
        return None
    x = np.array([np.nan if v is None else v for v in curve["control"]], float)
    y = np.array([np.nan if v is None else v for v in curve["values"]], float)
    keep = np.isfinite(x) & np.isfinite(y) if x.shape == y.shape else np.zeros(0, bool)
    return (x[keep], y[keep]) if np.count_nonzero(keep) >= 2 else None


def elastic_points(x, y, fraction: float = ELASTIC_FRACTION, std=None) -> tuple[np.ndarray, bool]:
    """Indices of the elastic part of a curve (control ``x`` [mm], values ``y``), and whether they lie in it.

    The points of the curve's own rising branch (up to its own peak, control > 0) whose ``|y|`` is at most
    ``fraction`` of ``|peak|`` (True), within SIGNIFICANCE ``std`` when given (a noisy point just above the line is
    not left out); when there is none, the first point of the rising branch (False: the secant to it is only a
    lower bound of the initial slope); none when nothing rises at control > 0.
    """
    x, y = np.asarray(x, float), np.asarray(y, float)
    peak = block_peak(y)
    if peak is None:
        return np.array([], int), False
    rising = np.flatnonzero((np.arange(y.size) <= peak) & (x > 0) & np.isfinite(y))
    scatter = 0.0 if std is None else SIGNIFICANCE * np.nan_to_num(np.asarray(std, float)[rising])
    low = rising[np.abs(y[rising]) - scatter <= fraction * abs(y[peak])]
    return (low, True) if low.size else (rising[:1], False)


def origin_slope(x, y, std=None) -> tuple[float, float]:
    """Least-squares slope k of the line through the origin y = k x (weights 1 / std^2) and its standard
    deviation from ``std`` (NaN without it). Units: those of y per those of x (N/mm for forces). NaN when
    there is no point at x != 0 or a value is not finite."""
    x, y = np.asarray(x, float), np.asarray(y, float)
    w = np.ones_like(x) if std is None else 1.0 / np.asarray(std, float) ** 2
    if x.size == 0 or not np.all(np.isfinite(np.concatenate([x, y, w]))):
        return math.nan, math.nan
    spread = float(np.sum(w * x**2))
    if spread <= 0:
        return math.nan, math.nan
    return float(np.sum(w * x * y) / spread), (math.sqrt(1.0 / spread) if std is not None else math.nan)


def initial_slope(x, y, std=None, fraction: float = ELASTIC_FRACTION) -> tuple[float, float, int, bool]:
    """The initial slope of a curve (:func:`origin_slope` over its :func:`elastic_points`): slope [unit of y
    per unit of x], its std (NaN without ``std``), the number of points and whether they lie in the elastic
    part (False: the slope is a lower bound)."""
    points, within = elastic_points(x, y, fraction, std)
    slope, slope_std = origin_slope(np.asarray(x, float)[points], np.asarray(y, float)[points],
                                    None if std is None else np.asarray(std, float)[points])
    return slope, slope_std, int(points.size), within


def computed_curve(x, y_fit, curve=None) -> tuple[np.ndarray, np.ndarray, bool]:
    """The computed curve a block is judged on: the run's own steps (``curve``, from :func:`block_curve`) up to
    the data's last control value when given, else the computed values at the data's points; and whether it is
    the run's."""
    if curve is not None and np.size(x) and np.any(np.isfinite(x)):
        cx, cy = curve
        keep = cx <= np.nanmax(x) * (1 + 1e-9)
        if np.count_nonzero(keep) >= 2:
            return cx[keep], cy[keep], True
    return np.asarray(x, float), np.asarray(y_fit, float), False


def block_diagnostics(x, y, std, y_fit, curve=None) -> dict:
    """Elastic slope and peak of one force block, measured and computed, each curve judged on its own points.

    Parameters
    ----------
    x : ndarray
        Control values [mm] (or point indices) of the block.
    y, std, y_fit : ndarray
        Measured values, their std and the computed values at the data's points (N).
    curve : (ndarray, ndarray), optional
        The run's own curve (control [mm], values [N]): the computed slope and peak are then its own.

    Returns
    -------
    dict
        ``elastic_points`` and ``elastic_points_model`` (how many points each slope rests on), ``slope_data``,
        ``slope_model`` [N/mm] (through the origin), ``slope_std`` (of the data's slope), ``slope_ratio`` (model /
        data), ``slope_data_elastic`` and ``slope_model_elastic`` (False: a secant above the elastic part, a lower
        bound), ``run_curve`` (whether the run's own curve was used), ``peak_data``, ``peak_model`` [N],
        ``peak_std`` (the data's std at its peak), ``peak_ratio``, ``control_peak_data``, ``control_peak_model``
        [mm] (NaN where not computed).
    """
    cx, cy, own = computed_curve(x, y_fit, curve)
    slope_data, slope_std, n_data, data_in = initial_slope(x, y, std)
    slope_model, _, n_model, model_in = initial_slope(cx, cy)
    i, j = block_peak(y), block_peak(cy)
    peak_data = float(y[i]) if i is not None else math.nan
    peak_model = float(cy[j]) if j is not None else math.nan
    return {"elastic_points": n_data, "elastic_points_model": n_model, "slope_data": slope_data,
            "slope_model": slope_model, "slope_std": slope_std, "slope_ratio": _ratio(slope_model, slope_data),
            "slope_data_elastic": data_in, "slope_model_elastic": model_in, "run_curve": own,
            "peak_data": peak_data, "peak_model": peak_model, "peak_std": float(std[i]) if i is not None else math.nan,
            "peak_ratio": _ratio(peak_model, peak_data),
            "control_peak_data": float(x[i]) if i is not None else math.nan,
            "control_peak_model": float(cx[j]) if j is not None else math.nan}


def _ratio(a: float, b: float) -> float:
    return a / b if math.isfinite(a) and math.isfinite(b) and b != 0 else math.nan


def worst_residual(control, y, std, y_fit, blocks) -> dict | None:
    """The point of largest ``|computed - measured|`` / std: ``index`` in y, ``block``, ``control``,
    ``measured``, ``computed`` and ``residual_std`` (signed, in units of the data's std); None when no
    point has a finite residual and a std > 0."""
    scaled = (np.asarray(y_fit, float) - y) / np.where(std > 0, std, np.nan)
    if not np.any(np.isfinite(scaled)):
        return None
    k = int(np.nanargmax(np.abs(scaled)))
    block = next((name for name, start, stop in blocks if start <= k < stop), "")
    return {"index": k, "block": block, "control": float(control[k]), "measured": float(y[k]),
            "computed": float(y_fit[k]), "residual_std": float(scaled[k])}


def fit_diagnostics(control, y, std, y_fit, blocks=(), quantities=(), curves=()) -> dict:
    """Diagnostics of a fit: per force block :func:`block_diagnostics`, and the worst residual.

    Parameters
    ----------
    control : array_like or None
        Control value of every entry of y [mm]; None: the point index in its block stands for it
        (slopes are then per point, and their ratio holds for evenly spaced points from control 0 only).
    y, std, y_fit : array_like, shape (n,)
        Measured values, their standard deviations and the values computed at the estimate (unit of
        y: N for forces, mm for widths).
    blocks : sequence of (name, start, stop)
        Data blocks of y (one block ``"data"`` when empty).
    quantities : sequence of str
        Observed quantity of each block (``"force"``, ``"fpz_width"``, ...: the observations' ``quantity``);
        a block of unknown quantity is taken for a force (:func:`measures_force`).
    curves : sequence, optional
        The run's own curve per block (a result's ``curves``, see :func:`block_curve`); used with a ``control``.

    Returns
    -------
    dict
        ``blocks``: per force block ``{"block", ...}`` of :func:`block_diagnostics`; ``worst``:
        :func:`worst_residual`; ``control``: ``"mm"`` or ``"index"``; ``note``: :data:`RUN_CURVE_NOTE` when a
        block was judged on the run's curve, else :data:`SAMPLING_NOTE`.
    """
    y, std, y_fit = (np.asarray(a, float) for a in (y, std, y_fit))
    blocks = [(str(b[0]), int(b[1]), int(b[2])) for b in (blocks or [])] or [("data", 0, y.size)]
    x = np.concatenate([np.arange(b - a, dtype=float) for _, a, b in blocks]) if control is None \
        else np.asarray(control, float)
    quantities = list(quantities or []) + [None] * len(blocks)
    out = []
    for k, ((name, start, stop), quantity) in enumerate(zip(blocks, quantities)):
        if measures_force(quantity) and stop > start:
            part = slice(start, stop)
            curve = None if control is None else block_curve(curves, k)
            out.append({"block": name, **block_diagnostics(x[part], y[part], std[part], y_fit[part], curve)})
    own = any(b["run_curve"] for b in out)
    return {"blocks": out, "worst": worst_residual(x, y, std, y_fit, blocks),
            "control": "index" if control is None else "mm", "note": RUN_CURVE_NOTE if own else SAMPLING_NOTE}


def _departs(ratio: float, tolerance: float, difference: float, std: float) -> bool:
    """A departure above ``tolerance`` and, when the data's std is known, above SIGNIFICANCE std."""
    if not math.isfinite(ratio) or abs(ratio - 1.0) <= tolerance:
        return False
    return not (math.isfinite(std) and abs(difference) <= SIGNIFICANCE * std)


def slope_direction(d: dict) -> tuple[str | None, bool]:
    """What a block's slopes (:func:`block_diagnostics`) can tell: ``("stiffer" | "softer", bound)``, or
    ``(None, True)`` when they cannot tell. A secant above the elastic part is a lower bound of its curve's
    slope: a lower bound on the model's shows it stiffer only, one on the data's shows it softer only;
    ``bound`` is True when the magnitude is then a lower bound too ("at least")."""
    model_in, data_in = d.get("slope_model_elastic", True), d.get("slope_data_elastic", True)
    if d["slope_ratio"] > 1:
        return ("stiffer", not model_in) if data_in else (None, True)
    return ("softer", not data_in) if model_in else (None, True)


def slope_warning(d: dict, tolerance: float = SLOPE_TOLERANCE) -> str | None:
    """The warning of a block whose computed elastic slope departs from the measured one, or None; one that
    says it cannot tell the direction when a secant above the elastic part leaves it open."""
    ratio = d["slope_ratio"]
    if not _departs(ratio, tolerance, d["slope_model"] - d["slope_data"], d["slope_std"]):
        return None
    way, bound = slope_direction(d)
    spread = f" +- {d['slope_std']:.2g}" if math.isfinite(d["slope_std"]) else ""  # the data's scatter
    slopes = (f"elastic slope {d['slope_model']:.4g} against {d['slope_data']:.4g}{spread} measured, through the "
              f"origin over {d.get('elastic_points_model', '?')} computed and {d['elastic_points']} measured point(s) of each "
              f"curve's rising branch below {100 * ELASTIC_FRACTION:.0f} % of its peak")
    causes = ("check the specimen's geometry (e.g. the notch depth, the ligament, the thickness, the span or length), "
              "E, and the units (force_unit, control_unit); a soft start of the test (seating, the machine's "
              "compliance in the measured control) lowers the measured slope")
    if way is None:
        short = " and ".join(w for w, inside in (("the model's", d.get("slope_model_elastic", True)),
                                                 ("the data's", d.get("slope_data_elastic", True))) if not inside)
        return (f"the elastic slopes differ in block {d['block']!r} (model/data {100 * ratio:.0f} %) but the first "
                f"point of {short} rising branch is above {100 * ELASTIC_FRACTION:.0f} % of its peak: too few points "
                f"on the rising branch to tell whether the model is stiffer or softer (a secant that high is only a "
                f"lower bound of the slope; {slopes}): give the data more points at the start of the test, and "
                f"{causes}")
    return (f"the model is {'at least ' if bound else ''}{100 * abs(ratio - 1):.0f} % {way} than the data in block "
            f"{d['block']!r} ({slopes}; above {100 * tolerance:g} %): {causes}")


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
        bound = "" if d.get("slope_model_elastic", True) and d.get("slope_data_elastic", True) else \
            " (a secant above the elastic part: a bound only)"
        lines.append(f"{d['block']}: elastic slope model/data {_percent(d['slope_ratio'])}{bound}, peak "
                     f"{d['peak_model']:.4g} at {d['control_peak_model']:.4g} against {d['peak_data']:.4g} at {d['control_peak_data']:.4g} "
                     f"{unit} measured (model/data {_percent(d['peak_ratio'])})")
    worst = diagnostics.get("worst")
    if worst:
        lines.append(f"worst residual: {worst['residual_std']:+.3g} std at point {worst['index']} (block "
                     f"{worst['block']!r}, control {worst['control']:.4g} {unit}: computed {worst['computed']:.4g}, "
                     f"measured {worst['measured']:.4g})")
    return lines


def _percent(ratio: float) -> str:
    return f"{100 * ratio:.0f} %" if math.isfinite(ratio) else "n/a"


__all__ = ["ELASTIC_FRACTION", "PEAK_TOLERANCE", "RUN_CURVE_NOTE", "SAMPLING_NOTE", "SIGNIFICANCE", "SLOPE_TOLERANCE",
           "block_curve", "block_diagnostics", "block_peak", "computed_curve", "diagnostic_warnings",
           "diagnostics_lines", "elastic_points", "fit_diagnostics", "initial_slope", "measures_force", "origin_slope",
           "slope_direction", "worst_residual"]
