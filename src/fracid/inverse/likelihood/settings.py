"""The settings of the two error terms of the likelihood and their keys in ``[identify]``.

``[identify] discretisation_error`` and ``[identify] model_error`` take a word (``"richardson"``, ``"variance"``,
``"off"``) or a table of settings with that word as ``kind``::

    [identify]
    discretisation_error = "richardson"       # or "off" (default)
    [identify.model_error]                    # or model_error = "variance" | "bias" | "off" (default)
    kind = "variance"
    prior = "half-cauchy"

:func:`discretisation_from_config` and :func:`model_error_from_config` check them (a
:class:`~fracid.settings.checks.SettingError` names the key relative to ``[identify]``).
"""

from __future__ import annotations

from dataclasses import dataclass

from fracid.settings import checks as settings
from fracid.settings.keys import FROM_CLASS, Key, described

DISCRETISATION_KEY, MODEL_ERROR_KEY = "discretisation_error", "model_error"
DISCRETISATION_KINDS = ("off", "richardson")
MODEL_ERROR_KINDS = ("off", "variance", "bias")
PRIORS = ("half-cauchy", "log-uniform")
GROUPINGS = ("block", "quantity")
#: the loops of an identification with the terms stop when no parameter moves by more than this share of its std
FIXED_POINT_TOL = 0.1


@dataclass(frozen=True)
class DiscretisationError:
    """The mesh's discretisation error of the computed values, by Richardson extrapolation at the estimate
    (:mod:`fracid.inverse.likelihood.discretisation`).

    Attributes
    ----------
    refinement : float
        The second mesh's element size is h / refinement (the bar: ``n_elements`` times it) [-], > 1.
    observed_order : bool
        Also run a mesh of h x refinement and take each block's order from the three (guarded); False: the
        nominal ``order``.
    order : float
        The order of convergence assumed where it is not observed or not observable [-]; the default 1 is
        conservative (the error is then twice the change from h to h / 2; an order of 2 gives 4/3 of it).
    correlation_length : float
        Correlation length of the error along the control, as a fraction of each block's control range [-]
        (Gaussian kernel times the error; large: one mode per block, the error's shape with an unknown amplitude).
    iterations : int
        Identifications with the term at most: 1 computes it once at the converged estimate; more recompute it
        at each new estimate until that moves less than a tenth of its std.
    """

    refinement: float = 2.0
    observed_order: bool = False
    order: float = 1.0
    correlation_length: float = 0.25
    iterations: int = 1
    kind = "richardson"


@dataclass(frozen=True)
class ModelError:
    """The model's own (form) error, identified with the parameters (:mod:`fracid.inverse.likelihood.model_error`).

    Attributes
    ----------
    kind : {"variance", "bias"}
        ``"variance"``: independent errors of std sigma_m added to every value of a group; ``"bias"``: an additive
        bias smooth along the control, a Gaussian process of std sigma_m (Kennedy and O'Hagan 2001).
    prior : {"half-cauchy", "log-uniform"}
        Prior of sigma_m: half-Cauchy of scale ``scale`` or log-uniform between the ``bounds``.
    scale : float
        The half-Cauchy's scale, as a fraction of the group's largest ``|measured value|`` [-].
    bounds : (float, float)
        The range of sigma_m, fractions of the group's largest ``|measured value|`` [-].
    groups : {"block", "quantity"}
        One sigma_m per data block, or one per observed quantity (blocks of forces share one).
    correlation_length : float
        ``"bias"``: the correlation length along the control, a fraction of each block's control range [-].
    iterations : int
        Fixed-point loops at most (sigma_m at the estimate, then the identification with it).
    """

    kind: str = "variance"
    prior: str = "half-cauchy"
    scale: float = 0.05
    bounds: tuple = (1e-4, 1.0)
    groups: str = "block"
    correlation_length: float = 0.25
    iterations: int = 3

    def __post_init__(self):
        for name, value, allowed in (("kind", self.kind, MODEL_ERROR_KINDS[1:]), ("prior", self.prior, PRIORS),
                                     ("groups", self.groups, GROUPINGS)):
            if value not in allowed:
                raise ValueError(f"ModelError.{name} = {value!r}; choose one of {', '.join(map(repr, allowed))}")
        lower, upper = self.bounds
        if not 0 < lower < upper:
            raise ValueError(f"ModelError.bounds = {self.bounds!r}; give 0 < lower < upper (fractions of the peak)")


def _words(values) -> str:
    return " | ".join(f'"{value}"' for value in values)


#: the keys of the table ``[identify.discretisation_error]``, described (meanings and defaults:
#: :class:`DiscretisationError`'s)
DISCRETISATION_KEY_DOCS = described({
    "kind": Key(DISCRETISATION_KINDS[1], "", _words(DISCRETISATION_KINDS),
                "The term: the mesh's error at the estimate from a mesh refined (Richardson), added to the data "
                'covariance; "off": none.'),
    "refinement": Key(FROM_CLASS, "-", "1 < r <= 4"),
    "observed_order": Key(FROM_CLASS, "", "true | false"),
    "order": Key(FROM_CLASS, "-", "0.5 <= p <= 4"),
    "correlation_length": Key(FROM_CLASS, "-", "> 0"),
    "iterations": Key(FROM_CLASS, "", "1 <= n <= 10"),
}, DiscretisationError)
#: the keys of the table ``[identify.model_error]``, described (meanings and defaults: :class:`ModelError`'s)
MODEL_ERROR_KEY_DOCS = described({
    "kind": Key(FROM_CLASS, "", _words(MODEL_ERROR_KINDS)),
    "prior": Key(FROM_CLASS, "", _words(PRIORS)),
    "scale": Key(FROM_CLASS, "-", "> 0"),
    "bounds": Key(list(ModelError.bounds), "-", "[lower, upper], 0 < lower < upper"),
    "groups": Key(FROM_CLASS, "", _words(GROUPINGS)),
    "correlation_length": Key(FROM_CLASS, "-", "> 0"),
    "iterations": Key(FROM_CLASS, "", "1 <= n <= 10"),
}, ModelError)
DISCRETISATION_KEYS = tuple(DISCRETISATION_KEY_DOCS)
MODEL_ERROR_KEYS = tuple(MODEL_ERROR_KEY_DOCS)


def _kind_and_table(key: str, raw, kinds, keys) -> tuple[str, dict]:
    """(kind, table) of a key given as a word or as a table with ``kind``."""
    if isinstance(raw, str):
        return settings.choice(key, raw, kinds), {}
    if not isinstance(raw, dict):
        raise settings.SettingError(key, raw, f"must be one of {', '.join(map(repr, kinds))}, or a table with kind and "
                                              f"settings ({', '.join(keys[1:])})")
    table = settings.table(key, raw, keys)
    return settings.choice(f"{key}.kind", table.get("kind", kinds[1]), kinds), table


def _fraction(key: str, value, what: str) -> float:
    return settings.number(key, value, f"must be a number > 0 ({what})", lambda v: v > 0)


def _loops(key: str, value) -> int:
    return settings.integer(key, value, "must be an integer with 1 <= iterations <= 10", lambda v: 1 <= v <= 10)


def discretisation_from_config(raw) -> DiscretisationError | None:
    """The :class:`DiscretisationError` of ``[identify] discretisation_error`` (None: ``"off"`` or absent)."""
    if raw is None:
        return None
    key = DISCRETISATION_KEY
    kind, table = _kind_and_table(key, raw, DISCRETISATION_KINDS, DISCRETISATION_KEYS)
    if kind == "off":
        return None
    default = DiscretisationError()
    observed = table.get("observed_order", default.observed_order)
    if not isinstance(observed, bool):
        raise settings.SettingError(f"{key}.observed_order", observed, "must be true or false")
    return DiscretisationError(
        refinement=settings.number(f"{key}.refinement", table.get("refinement", default.refinement),
                                   "must be a number with 1 < refinement <= 4 (h / refinement)", lambda v: 1 < v <= 4),
        observed_order=observed,
        order=settings.number(f"{key}.order", table.get("order", default.order),
                              "must be a number with 0.5 <= order <= 4 (the nominal order of convergence)",
                              lambda v: 0.5 <= v <= 4),
        correlation_length=_fraction(f"{key}.correlation_length", table.get("correlation_length",
                                     default.correlation_length), "a fraction of each block's control range"),
        iterations=_loops(f"{key}.iterations", table.get("iterations", default.iterations)))


def model_error_from_config(raw) -> ModelError | None:
    """The :class:`ModelError` of ``[identify] model_error`` (None: ``"off"`` or absent)."""
    if raw is None:
        return None
    key = MODEL_ERROR_KEY
    kind, table = _kind_and_table(key, raw, MODEL_ERROR_KINDS, MODEL_ERROR_KEYS)
    if kind == "off":
        return None
    default = ModelError()
    bounds = table.get("bounds", list(default.bounds))
    if not (isinstance(bounds, list) and len(bounds) == 2 and all(settings.is_number(v) for v in bounds)
            and 0 < bounds[0] < bounds[1]):
        raise settings.SettingError(f"{key}.bounds", bounds, "must be [lower, upper] with 0 < lower < upper "
                                                             "(fractions of the group's largest measured value)")
    return ModelError(
        kind=kind, prior=settings.choice(f"{key}.prior", table.get("prior", default.prior), PRIORS),
        scale=_fraction(f"{key}.scale", table.get("scale", default.scale), "a fraction of the group's peak"),
        bounds=(float(bounds[0]), float(bounds[1])),
        groups=settings.choice(f"{key}.groups", table.get("groups", default.groups), GROUPINGS),
        correlation_length=_fraction(f"{key}.correlation_length", table.get("correlation_length",
                                     default.correlation_length), "a fraction of each block's control range"),
        iterations=_loops(f"{key}.iterations", table.get("iterations", default.iterations)))


def as_discretisation(value) -> DiscretisationError | None:
    """The API's ``discretisation_error=``: None, ``"off"``, ``"richardson"`` or a :class:`DiscretisationError`."""
    return value if isinstance(value, DiscretisationError) else discretisation_from_config(value)


def as_model_error(value) -> ModelError | None:
    """The API's ``model_error=``: None, ``"off"``, ``"variance"``, ``"bias"`` or a :class:`ModelError`."""
    return value if isinstance(value, ModelError) else model_error_from_config(value)


__all__ = ["DISCRETISATION_KEY", "DISCRETISATION_KEY_DOCS", "MODEL_ERROR_KEY_DOCS", "DISCRETISATION_KINDS", "DiscretisationError", "FIXED_POINT_TOL", "GROUPINGS", "MODEL_ERROR_KEY",
           "MODEL_ERROR_KINDS", "ModelError", "PRIORS", "as_discretisation", "as_model_error",
           "discretisation_from_config", "model_error_from_config"]
