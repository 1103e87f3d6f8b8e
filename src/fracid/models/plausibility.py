"""Whether a parameter value is plausible for a quasi-brittle material (concrete, mortar, rock): each parameter
class declares the usual range of its parameters beside their valid range (``usual_ranges``,
:class:`~fracid.fem.material.ranges.ParameterSet`); a value far outside is almost surely another unit or scale
(kappa_i in per mille, E in GPa, c in cm^2). Callers that know the model pass its parameter class; a name
alone is looked up among the registered models (:data:`~fracid.models.registry.MODEL_TYPES`)."""

from __future__ import annotations

import math

from fracid.models.registry import known_units, parameter_classes

#: A value further outside its usual range than this factor (above upper * factor, below lower / factor) is
#: implausible: almost surely another unit or scale (kappa_i in per mille, E in GPa, c in cm^2)
IMPLAUSIBLE_FACTOR = 10.0


def usual_ranges(parameters: type | None = None) -> dict:
    """name -> (lower, upper) usual range in the parameter's unit: of the parameter class ``parameters``, or
    (None) of every registered model's, the first model's where two share a name."""
    if parameters is not None:
        return dict(parameters.usual_ranges)
    ranges = {}
    for cls in parameter_classes():
        for name, usual in cls.usual_ranges.items():
            ranges.setdefault(name, usual)
    return ranges


def usual_range_text(name: str, units: dict | None = None, parameters: type | None = None) -> str:
    """The usual range of parameter ``name`` in words, e.g. ``"2e-05 <= kappa_i <= 0.001 [-]"`` ("" if unknown).

    Parameters
    ----------
    name : str
        The parameter.
    units : dict, optional
        name -> unit (default: those of ``parameters``, else of the registered models).
    parameters : type, optional
        The model's parameter class (default: the registered models').
    """
    ranges = usual_ranges(parameters)
    if name not in ranges:
        return ""
    lower, upper = ranges[name]
    unit = (units or (parameters.units() if parameters is not None else known_units())).get(name, "-")
    return f"{lower:g} <= {name} <= {upper:g} [{unit}]"


def implausible(name: str, value: float, units: dict | None = None, parameters: type | None = None) -> str | None:
    """Why ``value`` of parameter ``name`` is implausible for a quasi-brittle material, or None.

    Implausible: more than :data:`IMPLAUSIBLE_FACTOR` times above the upper end of its usual range
    (:func:`usual_ranges` of ``parameters``, the model's parameter class; None: of the registered models), or
    positive and below its lower end divided by the factor. Parameters without a usual range are never
    implausible.

    Examples
    --------
    >>> implausible("kappa_i", 0.2)
    'kappa_i = 0.2 is 200 times the upper end of its usual range 2e-05 <= kappa_i <= 0.001 [-]'
    >>> implausible("kappa_i", 1e-4) is None
    True
    """
    ranges = usual_ranges(parameters)
    if name not in ranges or not math.isfinite(value):
        return None
    lower, upper = ranges[name]
    if value > upper * IMPLAUSIBLE_FACTOR:
        return (f"{name} = {value:g} is {value / upper:.3g} times the upper end of its usual range "
                f"{usual_range_text(name, units, parameters)}")
    if 0 < value < lower / IMPLAUSIBLE_FACTOR:  # 0 itself is a bound, not a scale (e.g. beta >= 0)
        return (f"{name} = {value:g} is 1/{lower / value:.3g} of the lower end of its usual range "
                f"{usual_range_text(name, units, parameters)}")
    return None


#: what to check when a value is implausible (:func:`implausible_text`)
SCALE_ADVICE = "check its unit and scale (e.g. kappa_i ~ 1e-4 for concrete, about ft / E; E in MPa, c in mm^2)"


def implausible_text(reason: str) -> str:
    """The words of a refusal or warning about an implausible value, ``reason`` being :func:`implausible`'s."""
    return (f"implausible for a quasi-brittle material: {reason} (more than {IMPLAUSIBLE_FACTOR:g} times outside "
            f"it); {SCALE_ADVICE}")


def first_bounds(parameters: type, name: str, value: float) -> list:
    """Bounds [lower, upper] a first identification searches around ``value`` of parameter ``name``: a factor 3
    each way, inside the usual range and the valid one of the parameter class ``parameters``, to 3 digits."""
    low, high = parameters.valid_bounds([name])
    usual = usual_ranges(parameters).get(name, (-math.inf, math.inf))
    lower = max(value / 3.0, usual[0], float(low[0]))
    upper = min(value * 3.0, usual[1], float(high[0]))
    return [float(f"{lower:.3g}"), float(f"{upper:.3g}")]
