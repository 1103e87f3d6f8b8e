"""The phase-field regularised cohesive zone model (PF-CZM; J.-Y. Wu 2017, J. Mech. Phys. Solids 103:72-99;
Wu & Nguyen 2018, J. Mech. Phys. Solids 119:20-42): its functions and parameters, values and derivatives
at all integration points at once (docs/theory.md, section 7).

A crack phase field d in [0, 1] of length scale l degrades the elastic stress by the rational function

    g(d) = (1 - d)^p / ((1 - d)^p + Q(d)),   Q(d) = a1 d (1 + a2 d + a2 a3 d^2),   a1 = 4 E Gf / (pi l ft^2),

and is spread over the band by the geometric function alpha(d) = 2 d - d^2 (c_alpha = 4 int_0^1
sqrt(alpha) = pi). The softening shape (p, a2, a3) sets which cohesive law the regularised crack follows
(:data:`SHAPES`); since a1 carries 1 / l, the law does not depend on l (Wu 2017, section 4): l is a numerical
parameter. The crack driving force is the history maximum of the effective major principal stress
(Rankine), never below the threshold ft^2 / (2 E).

Units: stresses [MPa], lengths [mm], Gf [N/mm].
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from fracid.fem.material.ranges import ELASTIC, Field, ParameterRange, compose
from fracid.fem.material.tsl import STRENGTH_AND_ENERGY

#: c_alpha = 4 int_0^1 sqrt(2 s - s^2) ds of the geometric function alpha(d) = 2 d - d^2
C_ALPHA = math.pi

#: softening shape -> (p, a2, a3) of Wu & Nguyen (2018), table 1: the cohesive law each reproduces
SHAPES = {"linear": (2.0, -0.5, 0.0), "exponential": (2.5, 2.0 ** (5.0 / 3.0) - 3.0, 0.0),
          "cornelissen": (2.0, 1.3868, 0.6567)}

LENGTH = (Field("l", 2.5, ParameterRange(0.0, False, None, False, "mm"),
                "Length scale of the phase field (Wu's b): a numerical parameter, the band's half-width is "
                "pi l / 2 (pi l is refused beyond the specimen's room, warned above half of it); the mesh needs "
                "h <= l / 5 where the crack runs", (0.1, 50.0)),)


def _shape_fields(p, a2, a3):
    # usual: near Wu's shapes (p = 2..2.5, a2 = -0.5..1.4, a3 = 0..0.7)
    return (Field("p", p, ParameterRange(2.0, True, None, False, "-"), "Exponent of (1 - d) in the degradation",
                  (1.5, 5.0)),
            Field("a2", a2, ParameterRange(-0.5, True, None, False, "-"),
                  "Softening shape: 2nd coefficient of Q(d) = a1 d (1 + a2 d + a2 a3 d^2)", (-0.5, 5.0)),
            Field("a3", a3, ParameterRange(None, False, None, False, "-"), "Softening shape: 3rd coefficient of Q(d)",
                  (0.0, 5.0)))


def shape_polynomial(d, a2, a3):
    """P(d) = 1 + a2 d + a2 a3 d^2 of the softening shape: Q(d) = a1 d P(d)."""
    return 1.0 + a2 * d + a2 * a3 * d * d


def _check_shape(params):
    """Q(d) / d = a1 (1 + a2 d + a2 a3 d^2) must stay positive on (0, 1] (a degradation in (0, 1))."""
    d = np.linspace(0.0, 1.0, 201)
    if np.min(shape_polynomial(d, params.a2, params.a3)) <= 0.0:
        raise ValueError(f"a2 = {params.a2:g}, a3 = {params.a3:g}: 1 + a2 d + a2 a3 d^2 must stay positive for "
                         "0 <= d <= 1 (else the degradation leaves (0, 1]); the shapes of Wu & Nguyen (2018): "
                         + ", ".join(f"{name} {shape}" for name, shape in SHAPES.items()))


def _parameter_class(shape: str):
    p, a2, a3 = SHAPES[shape]
    return compose(
        f"PhaseField{shape.capitalize()}Parameters", ELASTIC, STRENGTH_AND_ENERGY, LENGTH, _shape_fields(p, a2, a3),
        defaults={"E": 20000.0, "ft": 2.4, "Gf": 0.113}, check=_check_shape,
        summary=f"Parameters x = (E, nu, ft, Gf, l, p, a2, a3) of the phase-field regularised cohesive zone model "
                f"(Wu 2017), defaults: the {shape} softening shape (p, a2, a3) = {SHAPES[shape]} and Wu's concrete "
                "beam (E 20 GPa, ft 2.4 MPa, Gf 0.113 N/mm).")


PhaseFieldLinearParameters = _parameter_class("linear")
PhaseFieldExponentialParameters = _parameter_class("exponential")
PhaseFieldCornelissenParameters = _parameter_class("cornelissen")
_PARAMETERS = {"linear": PhaseFieldLinearParameters, "exponential": PhaseFieldExponentialParameters,
               "cornelissen": PhaseFieldCornelissenParameters}


def a1(E, ft, Gf, l):
    """a1 = 4 E Gf / (pi l ft^2) = 4 l_ch / (pi l) [-], l_ch = E Gf / ft^2 Irwin's length."""
    return 4.0 * E * Gf / (math.pi * l * ft**2)


def geometric(d):
    """alpha(d) = 2 d - d^2 and its first two derivatives (arrays like d)."""
    d = np.asarray(d, dtype=float)
    return 2.0 * d - d * d, 2.0 - 2.0 * d, np.full_like(d, -2.0)


def _parts(d, a_1, p, a2, a3):
    """(1 - d)^p, Q and their first two derivatives in d; (1 - d) is kept >= 0 (d = 1 is a full crack)."""
    r = np.maximum(1.0 - np.asarray(d, dtype=float), 0.0)
    P = r**p
    P1 = -p * r ** (p - 1.0)
    P2 = p * (p - 1.0) * np.maximum(r, 1e-12) ** (p - 2.0)
    Q = a_1 * d * shape_polynomial(d, a2, a3)
    Q1 = a_1 * (1.0 + 2.0 * a2 * d + 3.0 * a2 * a3 * d**2)
    Q2 = a_1 * (2.0 * a2 + 6.0 * a2 * a3 * d)
    return r, (P, P1, P2), (Q, Q1, Q2)


def degradation(d, a_1, p, a2, a3):
    """g(d) = P / (P + Q) with P = (1 - d)^p, and its first two derivatives in d.

    Parameters
    ----------
    d : ndarray
        Phase field [-].
    a_1, p, a2, a3 : float or ndarray broadcastable to d
        The degradation's constants (:func:`a1`, the softening shape).

    Returns
    -------
    g, dg, d2g : ndarray
    """
    _, (P, P1, P2), (Q, Q1, Q2) = _parts(d, a_1, p, a2, a3)
    S = P + Q
    N = P1 * Q - P * Q1  # g' = N / S^2
    N1 = P2 * Q - P * Q2
    S1 = P1 + Q1
    return P / S, N / S**2, N1 / S**2 - 2.0 * N * S1 / S**3


def degradation_parameter_derivatives(d, a_1, p, a2, a3) -> dict:
    """d g / d c and d g' / d c at fixed d for c in (a1, p, a2, a3): ``{c: (dg, dg')}``.

    With P = (1 - d)^p, S = P + Q and g' = (P' Q - P Q') / S^2, each constant c moves P (p only)
    or Q (a1, a2, a3, all linearly): dg = (P_c Q - P Q_c) / S^2 and dg' = ((P'_c Q + P' Q_c - P_c Q' -
    P Q'_c) S - 2 (P' Q - P Q') (P_c + Q_c)) / S^3.
    """
    d = np.asarray(d, dtype=float)
    r, (P, P1, _), (Q, Q1, _) = _parts(d, a_1, p, a2, a3)
    S = P + Q
    N = P1 * Q - P * Q1
    log_r = np.log(np.where(r > 0.0, r, 1.0))
    zero = np.zeros_like(d)
    moves = {  # c -> (P_c, P'_c, Q_c, Q'_c)
        "a1": (zero, zero, Q / a_1, Q1 / a_1),
        "p": (P * log_r, -r ** (p - 1.0) * (1.0 + p * log_r), zero, zero),
        "a2": (zero, zero, a_1 * d**2 * (1.0 + a3 * d), a_1 * (2.0 * d + 3.0 * a3 * d**2)),
        "a3": (zero, zero, a_1 * a2 * d**3, 3.0 * a_1 * a2 * d**2),
    }
    out = {}
    for name, (Pc, P1c, Qc, Q1c) in moves.items():
        dg = (Pc * Q - P * Qc) / S**2
        dg1 = ((P1c * Q + P1 * Qc - Pc * Q1 - P * Q1c) * S - 2.0 * N * (Pc + Qc)) / S**3
        out[name] = (dg, dg1)
    return out


#: half-width of the rounding of the threshold, relative to the onset strain ft / E (:func:`driving_force`)
ONSET_ROUNDING = 0.01


def _rounded_history(history, onset):
    """max(h, onset) with its corner rounded over onset (1 -+ :data:`ONSET_ROUNDING`) by a parabola (C1), and
    its slopes in h and in onset."""
    delta = ONSET_ROUNDING * onset
    x = (history - onset + delta) / (2.0 * delta)  # 0 to 1 across the rounding
    below, above = x <= 0.0, x >= 1.0
    rounded = np.where(below, onset, np.where(above, history, onset + delta * x**2))
    slope = np.where(below, 0.0, np.where(above, 1.0, x))
    # d/d onset at fixed h: 1 below; 0 above; in between d/d onset (onset + delta x^2) with delta = r onset
    onset_slope = np.where(below, 1.0, np.where(above, 0.0, 1.0 + ONSET_ROUNDING * x**2 - x * (1.0 + ONSET_ROUNDING * (2.0 * x - 1.0))))
    return rounded, slope, onset_slope


def driving_force(history, E, ft):
    """The crack driving force Y = E m^2 / 2 [MPa] of the history h (the largest effective major principal
    stress per unit E reached, a strain [-]), m = max(h, ft / E) with its corner rounded over ft / E (1 -+
    :data:`ONSET_ROUNDING`) so that Newton's iterations meet no kink at the onset (a sharp corner made them
    cycle between points switching on and off), and d Y / d h.

    Returns
    -------
    Y, dY_dh : ndarray
    """
    m, slope, _ = _rounded_history(history, ft / E)
    return 0.5 * E * m**2, E * m * slope


def driving_force_parameter_derivatives(history, E, ft, strength_factor=1.0) -> dict:
    """d Y / d E and d Y / d ft at fixed h (``strength_factor``: the points' ft relative to the material's)."""
    local_ft = ft * strength_factor
    onset = local_ft / E
    m, _, onset_slope = _rounded_history(history, onset)
    dm_donset = onset_slope
    return {"E": 0.5 * m**2 + E * m * dm_donset * (-onset / E),
            "ft": E * m * dm_donset * strength_factor / E}


@dataclass(frozen=True)
class PhaseFieldSoftening:
    """A softening shape of the PF-CZM by name (:data:`SHAPES`) with its parameter class; its (p, a2, a3)
    are parameters of the model, the shape's values their defaults.

    Parameters
    ----------
    name : str
        ``"linear"``, ``"exponential"`` or ``"cornelissen"`` (Cornelissen / Hordijk's law).
    """

    name: str = "cornelissen"
    differentiable: ClassVar[bool] = True

    def __post_init__(self):
        if self.name not in SHAPES:
            raise ValueError(f"phase-field softening = {self.name!r}; choose one of {sorted(SHAPES)}")

    @property
    def parameters(self) -> type:
        return _PARAMETERS[self.name]

    def scales(self, params) -> dict:
        """The strain at the strength ft / E [-] and the opening [mm] where the nominal law ends (linear
        2 Gf / ft, Cornelissen's wc = 5.136 Gf / ft, exponential 5 Gf / ft: a traction below 1 % of ft), a
        specimen sizes its default control with."""
        return {"strain": params.ft / params.E, "opening": _ULTIMATE_OPENING[self.name] * params.Gf / params.ft}


_ULTIMATE_OPENING = {"linear": 2.0, "exponential": 5.0, "cornelissen": 5.1361}

#: The softening shapes by name: ``[model] law`` of ``type = "pf-czm"``
PHASE_FIELD_SHAPES = {name: (lambda name=name: PhaseFieldSoftening(name)) for name in SHAPES}
