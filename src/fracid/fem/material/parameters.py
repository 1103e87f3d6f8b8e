"""Immutable, validated parameter set of the gradient-enhanced damage model."""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

from fracid.fem.material.ranges import ELASTIC_USUAL, ParameterRange, ParameterSet

_R = ParameterRange
_RANGES = {
    "E": _R(0.0, False, None, False, "MPa"),
    "nu": _R(-1.0, False, 0.5, False, "-"),
    "kappa_i": _R(0.0, False, None, False, "-"),
    "alpha": _R(0.0, True, 1.0, True, "-"),
    "beta": _R(0.0, True, None, False, "-"),
    "c": _R(0.0, False, None, False, "mm^2"),
    "eta": _R(1.0, True, None, False, "-"),
}
#: concrete: kappa_i ~ 1e-4 (ft / E), c of a few mm^2, beta of a few hundred
_USUAL = {**ELASTIC_USUAL, "kappa_i": (2.0e-5, 1.0e-3), "alpha": (0.0, 1.0), "beta": (10.0, 1.0e4), "c": (0.01, 1000.0),
          "eta": (1.0, 30.0)}


@dataclass(frozen=True)
class DamageParameters(ParameterSet):
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
        Gradient parameter [mm^2], c = l^2 / 2 with l the internal length, c > 0; the damage band, 2 pi sqrt(c)
        wide, is refused beyond the specimen's room and warned above half of it.
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

    ranges: ClassVar[dict] = _RANGES
    usual_ranges: ClassVar[dict] = _USUAL
