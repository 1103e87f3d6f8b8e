"""Validated parameter sets: the ranges, checks and vector conversions every model's parameters share.

A model's parameter class is a frozen dataclass that derives from :class:`ParameterSet` and lists
its fields' valid ranges in the class attribute ``ranges`` (name -> :class:`ParameterRange`, in the
order of the fields) and, beside them, the usual ranges of quasi-brittle materials in ``usual_ranges``
(name -> (lower, upper) in the parameter's unit; a parameter without one is never called implausible); it
then has ``names``, ``units``, ``valid_bounds``, ``replace``, ``as_array``
and ``from_array``, the interface the inverse code relies on (:mod:`fracid.models`).

A parameter class can also be composed from parts (:func:`compose`): the elastic part
:data:`ELASTIC` (E, nu), a law's own part (e.g. ft, Gf and its shape constants), a regularisation
part (e.g. c), so that a new law defines only its own fields.
"""

from __future__ import annotations

import dataclasses
import math
import sys
import textwrap
from typing import Callable, ClassVar, NamedTuple

import numpy as np

from fracid.settings.field_error import FieldError


class ParameterError(FieldError):
    """An invalid parameter value: ``name``, ``value`` and ``range`` (its :class:`ParameterRange`)."""

    def __init__(self, name: str, value, rng, message: str):
        super().__init__(name, value, message)
        self.range = rng


class ParameterRange(NamedTuple):
    """Valid range of one parameter; None = unbounded on that side."""

    lo: float | None
    lo_incl: bool
    hi: float | None
    hi_incl: bool
    unit: str

    def describe(self, name: str) -> str:
        """The range in words, e.g. ``"-1 < nu < 0.5"`` or ``"0 < E"``."""
        text = name if self.lo is None else f"{self.lo:g} {'<=' if self.lo_incl else '<'} {name}"
        return text if self.hi is None else f"{text} {'<=' if self.hi_incl else '<'} {self.hi:g}"

    def admits(self, v: float) -> bool:
        above = self.lo is None or (v >= self.lo if self.lo_incl else v > self.lo)
        below = self.hi is None or (v <= self.hi if self.hi_incl else v < self.hi)
        return math.isfinite(v) and above and below

    def inner_limits(self) -> tuple[float, float]:
        """The limits with open ends moved inside by 1e-9 (relative), so that clipped values are valid."""
        lower = -np.inf if self.lo is None else self.lo if self.lo_incl else self.lo + 1e-9 * max(abs(self.lo), 1e-9)
        upper = np.inf if self.hi is None else self.hi if self.hi_incl else self.hi - 1e-9 * max(abs(self.hi), 1.0)
        return lower, upper

    def validated(self, name: str, value) -> float:
        """``value`` as a float, or a ValueError naming the parameter, the value and the range."""
        try:
            v = float(value)
        except (TypeError, ValueError):
            raise ParameterError(name, value, self, f"parameter {name!r} = {value!r} is not a number; valid range: "
                                 f"{self.describe(name)}") from None
        if not self.admits(v):
            raise ParameterError(name, value, self, f"parameter {name!r} = {value!r} is out of range; valid range: "
                                 f"{self.describe(name)}")
        return v


class ParameterSet:
    """Mixin of the parameter dataclasses: validation on construction and the vector interface."""

    ranges: ClassVar[dict[str, ParameterRange]] = {}
    #: name -> (lower, upper): the values usual for quasi-brittle materials (concrete, mortar, rock), wide on
    #: purpose, in the parameter's unit; a value far outside is almost surely another unit or scale
    usual_ranges: ClassVar[dict[str, tuple[float, float]]] = {}

    def __post_init__(self):
        for name, rng in self.ranges.items():
            object.__setattr__(self, name, rng.validated(name, getattr(self, name)))

    @classmethod
    def names(cls) -> tuple[str, ...]:
        """Names of the parameters in the order of the vector x."""
        return tuple(cls.ranges)

    @classmethod
    def units(cls) -> dict[str, str]:
        """Unit of each parameter."""
        return {name: rng.unit for name, rng in cls.ranges.items()}

    @classmethod
    def valid_bounds(cls, names) -> tuple[np.ndarray, np.ndarray]:
        """Lower and upper limits of the valid ranges of ``names``, open ends moved inside by 1e-9
        (relative) so that clipped values stay valid; +-inf where unbounded."""
        unknown = sorted(set(names).difference(cls.ranges))
        if unknown:
            raise ValueError(f"unknown parameter(s) {unknown}; known: {list(cls.ranges)}")
        limits = np.array([cls.ranges[name].inner_limits() for name in names], dtype=float).reshape(-1, 2)
        return limits[:, 0].copy(), limits[:, 1].copy()

    def replace(self, **changes):
        """A copy with some parameters changed (validated)."""
        unknown = sorted(set(changes).difference(self.ranges))
        if unknown:
            raise ValueError(f"unknown parameter(s) {unknown}; known: {list(self.ranges)}")
        return dataclasses.replace(self, **changes)

    def as_array(self) -> np.ndarray:
        """The vector x in the order of :meth:`names`."""
        return np.array([getattr(self, name) for name in self.ranges], dtype=float)

    @classmethod
    def from_array(cls, x):
        """Build from a vector x in the order of :meth:`names`."""
        x = np.asarray(x, dtype=float)
        names = cls.names()
        if x.shape != (len(names),):
            raise ValueError(f"expected a vector of {len(names)} parameters {list(names)}, got shape {x.shape}")
        return cls(**dict(zip(names, x)))


class Field(NamedTuple):
    """One parameter of a composed parameter class: its name, default value, valid range (with the
    unit), meaning in a few words (for the docstring, e.g. ``"Young's modulus"``) and usual range
    ((lower, upper) for quasi-brittle materials, in the unit of the range; None: none)."""

    name: str
    default: float
    range: ParameterRange
    meaning: str
    usual: tuple | None = None


#: The elastic part of every model's parameters: Young's modulus E [MPa] and Poisson's ratio nu [-]
ELASTIC = (Field("E", 30000.0, ParameterRange(0.0, False, None, False, "MPa"), "Young's modulus of the bulk",
                 (5.0e3, 1.0e5)),
           Field("nu", 0.2, ParameterRange(-1.0, False, 0.5, False, "-"), "Poisson's ratio of the bulk", (0.0, 0.45)))

#: the usual ranges of the elastic part (a hand-written parameter class takes them from here)
ELASTIC_USUAL = {f.name: f.usual for f in ELASTIC}


def _docstring(summary: str, fields) -> str:
    """A numpydoc docstring listing ``fields`` with their meaning, unit and valid range."""
    lines = [textwrap.fill(summary, 100), "", "Parameters", "----------"]
    for f in fields:
        limits = f.range.describe(f.name)
        lines += [f"{f.name} : float",
                  f"    {f.meaning} [{f.range.unit}]" + ("" if limits == f.name else f", {limits}") + "."]
    return "\n".join(lines) + "\n"


def _checked_fields(parts, defaults) -> list:
    fields = [f for part in parts for f in part]
    if not all(isinstance(f, Field) for f in fields):
        raise TypeError("compose: every part must be a sequence of Field(name, default, range, meaning)")
    names = [f.name for f in fields]
    twice = sorted({n for n in names if names.count(n) > 1})
    if twice:
        raise ValueError(f"compose: parameter(s) {twice} defined by more than one part")
    unknown = sorted(set(defaults).difference(names))
    if unknown:
        raise ValueError(f"compose: defaults for unknown parameter(s) {unknown}; the parameters are {names}")
    return [f._replace(default=float(defaults.get(f.name, f.default))) for f in fields]


def compose(class_name: str, *parts, summary: str = "", defaults: dict | None = None,
            check: Callable | None = None, namespace: dict | None = None, module: str | None = None) -> type:
    """A frozen :class:`ParameterSet` dataclass whose fields are those of ``parts``, in order.

    Parameters
    ----------
    class_name : str
        Name of the class; assign the result to this name at module level (pickling and the run
        store find the class by its module and name).
    *parts : sequence of Field
        E.g. ``ELASTIC``, the law's part, a regularisation part; a name may appear in one part only.
    summary : str
        First line of the docstring (the fields' list is appended, numpydoc, with units and ranges).
    defaults : dict, optional
        Default values replacing those of the parts, e.g. ``{"E": 20000.0}``.
    check : callable, optional
        ``check(params)`` run after the range checks, raising ValueError for values that are valid
        one by one but not together (name the parameters and the values in the message).
    namespace : dict, optional
        Further class members (properties, methods).
    module : str, optional
        The module the class belongs to (default: the caller's).

    Returns
    -------
    type
        The parameter class, with ``ranges`` in the order of the fields.

    Examples
    --------
    >>> from fracid.fem.material.ranges import ELASTIC, Field, ParameterRange, compose
    >>> STRENGTH = (Field("ft", 3.0, ParameterRange(0.0, False, None, False, "MPa"), "Tensile strength"),)
    >>> P = compose("P", ELASTIC, STRENGTH, defaults={"E": 20000.0})
    >>> P().names(), P().E
    (('E', 'nu', 'ft'), 20000.0)
    """
    fields = _checked_fields(parts, defaults or {})
    members = dict(namespace or {})
    members.update(ranges={f.name: f.range for f in fields},
                   usual_ranges={f.name: f.usual for f in fields if f.usual is not None}, __doc__=_docstring(summary or f"Parameters of {class_name}.",
                                                                               fields))
    if check is not None:
        def __post_init__(self):
            ParameterSet.__post_init__(self)
            check(self)

        members["__post_init__"] = __post_init__
    cls = dataclasses.make_dataclass(class_name, [(f.name, float, dataclasses.field(default=f.default)) for f in fields],
                                     bases=(ParameterSet,), namespace=members, frozen=True)
    cls.__module__ = module or sys._getframe(1).f_globals.get("__name__", __name__)
    return cls
