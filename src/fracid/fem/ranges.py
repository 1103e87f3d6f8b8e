"""Validated parameter sets: the ranges, checks and vector conversions every model's parameters share.

A model's parameter class is a frozen dataclass that derives from :class:`ParameterSet` and lists
its fields' valid ranges in the class attribute ``ranges`` (name -> :class:`ParameterRange`, in the
order of the fields); it then has ``names``, ``units``, ``valid_bounds``, ``replace``, ``as_array``
and ``from_array``, the interface the inverse code relies on (:mod:`fracid.models`).
"""

from __future__ import annotations

import dataclasses
import math
from typing import ClassVar, NamedTuple

import numpy as np


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
            raise ValueError(f"parameter {name!r} = {value!r} is not a number; valid range: {self.describe(name)}") from None
        if not self.admits(v):
            raise ValueError(f"parameter {name!r} = {value!r} is out of range; valid range: {self.describe(name)}")
        return v


class ParameterSet:
    """Mixin of the parameter dataclasses: validation on construction and the vector interface."""

    ranges: ClassVar[dict[str, ParameterRange]] = {}

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
