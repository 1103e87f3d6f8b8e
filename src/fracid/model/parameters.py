"""Immutable, validated parameter set of the gradient-enhanced damage model."""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

# name -> (lower, lower inclusive, upper, upper inclusive, unit); None = unbounded
_RANGES = {
    "E": (0.0, False, None, False, "MPa"),
    "nu": (-1.0, False, 0.5, False, "-"),
    "kappa_i": (0.0, False, None, False, "-"),
    "alpha": (0.0, True, 1.0, True, "-"),
    "beta": (0.0, True, None, False, "-"),
    "c": (0.0, False, None, False, "mm^2"),
    "eta": (1.0, True, None, False, "-"),
}


def _range_text(name: str) -> str:
    lo, lo_incl, hi, hi_incl, _ = _RANGES[name]
    parts = []
    if lo is not None:
        parts.append(f"{lo:g} {'<=' if lo_incl else '<'} {name}")
    text = parts[0] if parts else name
    if hi is not None:
        text += f" {'<=' if hi_incl else '<'} {hi:g}"
    return text


def _check(name: str, value) -> float:
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"parameter {name!r} = {value!r} is not a number; valid range: {_range_text(name)}") from None
    lo, lo_incl, hi, hi_incl, _ = _RANGES[name]
    bad = not math.isfinite(v)
    if lo is not None:
        bad |= v < lo if lo_incl else v <= lo
    if hi is not None:
        bad |= v > hi if hi_incl else v >= hi
    if bad:
        raise ValueError(f"parameter {name!r} = {value!r} is out of range; valid range: {_range_text(name)}")
    return v


@dataclass(frozen=True)
class DamageParameters:
    """Parameters x = (E, nu, kappa_i, alpha, beta, c, eta) of the gradient-enhanced damage model.

    Parameters
    ----------
    E : float
        Young's modulus [MPa], E > 0.
    nu : float
        Poisson's ratio [-], -1 < nu < 0.5.
    kappa_i : float
        Damage threshold, equivalent strain at damage onset [-], kappa_i > 0.
    alpha : float
        Residual-stress parameter of the exponential softening [-], 0 <= alpha <= 1
        (alpha = 1: the stress tends to zero).
    beta : float
        Softening rate [-], beta >= 0 (alpha = 1, beta = 0: "perfect" damage).
    c : float
        Gradient parameter [mm^2], c = l^2 / 2 with l the internal length, c > 0.
    eta : float
        Ratio of compressive to tensile strength in the modified von Mises equivalent strain [-], eta >= 1.

    Examples
    --------
    >>> p = DamageParameters()
    >>> p.replace(c=2.0).c
    2.0
    """

    E: float = 20000.0
    nu: float = 0.2
    kappa_i: float = 1.0e-4
    alpha: float = 0.99
    beta: float = 300.0
    c: float = 1.0
    eta: float = 10.0

    def __post_init__(self):
        for name in _RANGES:
            object.__setattr__(self, name, _check(name, getattr(self, name)))

    @classmethod
    def names(cls) -> tuple[str, ...]:
        """Names of the parameters in the order of the vector x."""
        return tuple(_RANGES)

    @classmethod
    def units(cls) -> dict[str, str]:
        """Unit of each parameter."""
        return {name: r[4] for name, r in _RANGES.items()}

    @classmethod
    def valid_bounds(cls, names) -> tuple[np.ndarray, np.ndarray]:
        """Lower and upper limits of the valid ranges of ``names``, open ends moved inside by 1e-9
        (relative) so that clipped values stay valid; +-inf where unbounded."""
        lower, upper = [], []
        for name in names:
            lo, lo_incl, hi, hi_incl, _ = _RANGES[name]
            lower.append(-np.inf if lo is None else lo if lo_incl else lo + 1e-9 * max(abs(lo), 1e-9))
            upper.append(np.inf if hi is None else hi if hi_incl else hi - 1e-9 * max(abs(hi), 1.0))
        return np.array(lower), np.array(upper)

    def replace(self, **changes) -> "DamageParameters":
        """A copy with some parameters changed (validated)."""
        unknown = set(changes) - set(_RANGES)
        if unknown:
            raise ValueError(f"unknown parameter(s) {sorted(unknown)}; known: {list(_RANGES)}")
        return dataclasses.replace(self, **changes)

    def as_array(self) -> np.ndarray:
        """The vector x in the order of :meth:`names`."""
        return np.array([getattr(self, n) for n in _RANGES])

    @classmethod
    def from_array(cls, x) -> "DamageParameters":
        """Build from a vector x in the order of :meth:`names`."""
        x = np.asarray(x, dtype=float)
        if x.shape != (len(_RANGES),):
            raise ValueError(f"expected a vector of {len(_RANGES)} parameters {list(_RANGES)}, got shape {x.shape}")
        return cls(**dict(zip(_RANGES, x)))
