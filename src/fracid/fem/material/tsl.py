"""Traction-separation laws: the contract both crack formulations use, and what they build on any law.

A traction-separation law (TSL) gives the normal traction sigma [MPa] across a crack as a function
of its opening w [mm] on the monotonic envelope, with its derivatives, at all points at once
(:class:`TractionSeparationLaw`). The discrete cohesive crack
(:mod:`fracid.fem.formulations.cohesive_problem`) and the crack band (:mod:`fracid.fem.material.crack_band`) call
only their law object; what is the formulation's business is built here once for every law:

- secant unloading and reloading with the history w_max (:func:`secant_unloading`, and its
  parameter derivatives :func:`secant_unloading_parameter_derivatives`);
- a law with its strength and its openings scaled, s sigma(r w) (:class:`ScaledLaw`: the crack
  band's strength imperfection at equal fracture energy, s = r).

:class:`ShapeLaw` is the common implementation of the laws written as sigma = ft f(w / wc) with a
normalised shape f on [0, 1) and wc = Gf / (ft I), I the area under f: the area under the law is
exactly Gf. Hordijk's, the linear and the bilinear laws (:mod:`fracid.fem.material.laws`) are shape laws.
"""

from __future__ import annotations

from typing import Protocol

import numpy as np

from fracid.fem.material.damage import update_history
from fracid.fem.material.ranges import Field, ParameterRange


class TractionSeparationLaw(Protocol):
    """What the crack formulations ask of a traction-separation law.

    ``name`` (str) names the law (run-store keys, messages); ``parameters`` (type) is its parameter
    class (a :class:`~fracid.fem.material.ranges.ParameterSet` with ``E`` and ``nu`` of the bulk and the law's
    own parameters).

    ``traction(w, params) -> (sigma [MPa], d sigma / d w [MPa/mm])`` on the envelope, at every opening
    w [mm]: the tension-only law, sigma = 0 for w < 0 (contact is the formulation's business) and
    where the crack is fully open. ``parameter_derivatives(w, params) -> {name: d sigma / d name}`` at
    fixed w, for the law's parameters it depends on (optional: without it the runs are
    differentiated by central differences). ``strength(params)`` is ft = sigma(0) [MPa]; its
    parameter derivatives are those of the traction at w = 0. ``critical_opening(params)`` is wc
    [mm], where the traction vanishes (``np.inf`` if it never does). ``scales(params)``: the
    characteristic ``strain`` (ft / E) [-] and ``opening`` [mm] a specimen sizes its default control
    with and the crack band's solver its tolerance. ``steepest_slope(params)``: max over w of
    ``|d sigma / d w|`` [MPa/mm], the crack band's snap-back limit (needed by the crack band only).
    """

    name: str
    parameters: type

    def traction(self, w, params): ...

    def parameter_derivatives(self, w, params) -> dict: ...

    def strength(self, params) -> float: ...

    def critical_opening(self, params) -> float: ...

    def scales(self, params) -> dict: ...

    def steepest_slope(self, params) -> float: ...


def differentiable(law) -> bool:
    """Whether ``law`` gives its parameter derivatives (the runs' exact sensitivities)."""
    return callable(getattr(law, "parameter_derivatives", None))


# ------------------------------------------------------------------------------------------------
# secant unloading on any envelope


def secant_unloading(w, w_max, envelope):
    """Traction, consistent tangent and history update of an envelope with secant unloading.

    Loading (w >= w_max, neutral loading included, as in :func:`fracid.fem.material.damage.update_history`):
    the point follows the envelope. Unloading (0 <= w < w_max): it goes back linearly to the origin,
    sigma = sigma_env(w_max) w / w_max, and reloading retraces the same secant until the envelope is
    met again. Closure (w < 0): sigma = 0 with zero tangent; contact is the caller's business.

    Parameters
    ----------
    w : array_like
        Current opening [mm].
    w_max : array_like
        Largest opening reached before this step [mm], w_max >= 0 (0 for an intact point).
    envelope : callable
        ``envelope(w) -> (sigma [MPa], d sigma / d w [MPa/mm])``, e.g. a law's ``traction`` at fixed
        parameters.

    Returns
    -------
    sigma : ndarray
        Traction [MPa].
    dsigma_dw : ndarray
        Consistent tangent [MPa/mm]: the envelope's slope when loading, the secant slope when unloading.
    w_max_new : ndarray
        Updated history max(w_max, w) [mm].
    """
    w = np.asarray(w, dtype=float)
    w_max = np.asarray(w_max, dtype=float)
    w_max_new, loading = update_history(w_max, w)
    sigma_env, slope_env = envelope(w)
    # w < w_max implies w_max > 0 for admissible histories; the guard keeps the division finite
    # at points that are not unloading
    reached = np.where(loading, 1.0, np.maximum(w_max, np.finfo(float).tiny))
    secant = envelope(reached)[0] / reached
    opened = w >= 0.0
    sigma = np.where(loading, sigma_env, np.where(opened, secant * w, 0.0))
    dsigma = np.where(loading, slope_env, np.where(opened, secant, 0.0))
    return sigma, dsigma, w_max_new


def secant_unloading_parameter_derivatives(w, w_max, envelope, envelope_rates):
    """Derivatives of the traction of :func:`secant_unloading` at fixed opening w and fixed history
    w_max: with respect to the parameters, and with respect to w_max.

    Loading (w >= w_max): the envelope's, and no dependence on w_max. Unloading (0 <= w < w_max):
    sigma = sigma_env(w_max) w / w_max, so d sigma / d x = d sigma_env(w_max) / d x  w / w_max and
    d sigma / d w_max = w (w_max sigma_env'(w_max) - sigma_env(w_max)) / w_max^2. Closed (w < 0): zeros.

    Parameters
    ----------
    w, w_max, envelope
        As in :func:`secant_unloading`.
    envelope_rates : callable
        ``envelope_rates(w) -> {name: d sigma_env / d name}`` at fixed w (a law's
        ``parameter_derivatives`` at fixed parameters).

    Returns
    -------
    rates : dict {name: ndarray}
        d sigma / d name at fixed w and w_max [MPa per unit parameter].
    d_sigma_d_w_max : ndarray
        [MPa/mm], nonzero at unloading points only.
    """
    w = np.asarray(w, dtype=float)
    w_max = np.asarray(w_max, dtype=float)
    loading = w >= w_max
    unloading = ~loading & (w >= 0.0)
    reached = np.where(unloading, w_max, 1.0)  # w < w_max implies w_max > 0
    at_w, at_max = envelope_rates(w), envelope_rates(reached)
    ratio = np.where(unloading, w / reached, 0.0)
    rates = {name: np.where(loading, at_w[name], at_max[name] * ratio) for name in at_w}
    stress, slope = envelope(reached)
    d_w_max = np.where(unloading, w * (reached * slope - stress) / reached**2, 0.0)
    return rates, d_w_max


# ------------------------------------------------------------------------------------------------
# a law with its strength and openings scaled


class ScaledLaw:
    """``law`` at fixed ``params`` with its traction scaled by ``stress`` and its openings by
    1 / ``opening``: sigma(w) = s sigma_law(r w), point by point.

    With s = r = a the fracture energy is unchanged and the strength is a ft (Hordijk's law with ft a
    and wc / a): the crack band's strength imperfection. s and r may be arrays (one value per point).

    Parameters
    ----------
    law : TractionSeparationLaw
    params : ParameterSet
        The law's parameters.
    stress, opening : float or ndarray
        s [-] and r [-], positive.
    """

    def __init__(self, law, params, stress=1.0, opening=1.0):
        self.law, self.params = law, params
        self.stress = np.asarray(stress, dtype=float)
        self.opening = np.asarray(opening, dtype=float)
        if not (np.all(self.stress > 0) and np.all(self.opening > 0)):
            raise ValueError("ScaledLaw: the stress and opening factors must be positive")

    def traction(self, w):
        """sigma [MPa] and d sigma / d w [MPa/mm] at openings w [mm]."""
        sigma, slope = self.law.traction(self.opening * np.asarray(w, dtype=float), self.params)
        return self.stress * sigma, self.stress * self.opening * slope

    def parameter_derivatives(self, w) -> dict:
        """{name: d sigma / d name} at fixed w, for the law's parameters."""
        rates = self.law.parameter_derivatives(self.opening * np.asarray(w, dtype=float), self.params)
        return {name: self.stress * value for name, value in rates.items()}

    def strength(self) -> np.ndarray:
        """s ft [MPa]."""
        return self.stress * self.law.strength(self.params)

    def opening_scale(self) -> np.ndarray:
        """The law's characteristic opening divided by r [mm]."""
        return self.law.scales(self.params)["opening"] / self.opening


# ------------------------------------------------------------------------------------------------
# laws sigma = ft f(w / wc), wc = Gf / (ft I)

#: The part of a shape law's parameters common to all: the strength and the fracture energy
STRENGTH_AND_ENERGY = (
    Field("ft", 3.0, ParameterRange(0.0, False, None, False, "MPa"), "Tensile strength, traction at zero opening",
          (0.5, 20.0)),
    Field("Gf", 0.1, ParameterRange(0.0, False, None, False, "N/mm"),
          "Fracture energy, area under the traction-opening law", (0.005, 1.0)),
)


class ShapeLaw:
    """A traction-separation law sigma(w) = ft f(w / wc) for 0 <= w < wc, 0 elsewhere, with
    wc = Gf / (ft I) so that the area under the law is exactly Gf (parameters ``ft`` [MPa], ``Gf``
    [N/mm] and the shape's own).

    A subclass gives the normalised shape: ``shape(x, params) -> (f, df / dx)`` on 0 <= x < 1 with
    f(0) = 1; ``shape_derivatives(x, params) -> {name: d f / d name}`` at fixed x for the shape's
    parameters; ``area(params)`` I = int_0^1 f dx [-] and ``area_derivatives(params) -> {name:
    d I / d name}``; ``steepest_shape_slope(params)``, max ``|df / dx|`` [-]. This class turns them
    into the law's values and exact parameter derivatives at fixed w (through wc as well).
    """

    def strength(self, params) -> float:
        return params.ft

    def critical_opening(self, params) -> float:
        """wc = Gf / (ft I) [mm]."""
        return params.Gf / (params.ft * self.area(params))

    def scales(self, params) -> dict:
        """``strain`` = ft / E [-] and ``opening`` = wc [mm]."""
        return {"strain": params.ft / params.E, "opening": self.critical_opening(params)}

    def steepest_slope(self, params) -> float:
        """max ``|d sigma / d w|`` = ft max ``|f'|`` / wc [MPa/mm]."""
        return params.ft * self.steepest_shape_slope(params) / self.critical_opening(params)

    def _normalised(self, w, params):
        w = np.asarray(w, dtype=float)
        wc = self.critical_opening(params)
        active = (w >= 0.0) & (w < wc)
        # evaluate at a harmless x where inactive so that no overflow or nan leaks through np.where
        x = np.where(active, w / wc, 0.0)
        return active, x, wc

    def traction(self, w, params):
        """sigma [MPa] and d sigma / d w [MPa/mm] at openings w [mm]; both 0 outside 0 <= w < wc."""
        active, x, wc = self._normalised(w, params)
        f, df = self.shape(x, params)
        return np.where(active, params.ft * f, 0.0), np.where(active, params.ft / wc * df, 0.0)

    def parameter_derivatives(self, w, params) -> dict:
        """{name: d sigma / d name} at fixed w [MPa per unit parameter], for ft, Gf and the shape's
        parameters: d sigma = ft (df/dname at fixed x) + sigma' w (-d ln wc / d name) + f d ft.
        Zero outside 0 <= w < wc (at w = wc, a kink, the cut-off side's value)."""
        active, x, _ = self._normalised(w, params)
        f, df = self.shape(x, params)
        area = self.area(params)
        out = {"ft": f + x * df, "Gf": -params.ft * df * x / params.Gf}
        area_rates = self.area_derivatives(params)
        for name, d_f in self.shape_derivatives(x, params).items():
            out[name] = params.ft * (d_f + df * x * area_rates[name] / area)
        return {name: np.where(active, value, 0.0) for name, value in out.items()}
