"""Material laws as small objects: values and derivatives at all integration points at once.

A formulation (gradient, local or integral damage; the crack band; the cohesive interface) takes a
law and asks it for values and derivatives; it never names the law's parameters. Damage laws:
:class:`DamageLaw`, by name in :data:`DAMAGE_LAWS`; traction-separation laws (the contract: :class:`fracid.fem.material.tsl.TractionSeparationLaw`):
:class:`HordijkLaw`, :class:`LinearSoftening`, :class:`BilinearSoftening`, by name in
:data:`TRACTION_SEPARATION_LAWS`. A new law is a new
object with the same methods (see :class:`DamageLaw`), nothing else changes. The parameter
derivatives of the laws (for sensitivities computed inside the analysis) belong here too.

Units: strains [-], stresses [MPa], openings [mm], fracture energies [N/mm].
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import ClassVar, Protocol

import numpy as np

from fracid.fem.material.cohesive import CohesiveParameters, hordijk_shape, hordijk_shape_derivatives
from fracid.fem.material.damage import exponential_damage, exponential_damage_parameter_derivatives, kappa_at_damage
from fracid.fem.material.equivalent_strain import (modified_von_mises_plane_stress,
                                          modified_von_mises_plane_stress_parameter_derivatives,
                                          modified_von_mises_uniaxial, modified_von_mises_uniaxial_parameter_derivatives)
from fracid.fem.material.parameters import DamageParameters
from fracid.fem.material.ranges import ELASTIC, Field, ParameterRange, compose
from fracid.fem.material.tsl import STRENGTH_AND_ENERGY, ShapeLaw


class SofteningLaw(Protocol):
    """Damage omega(kappa) of the history variable kappa.

    ``damage(kappa, params) -> (omega, d omega / d kappa)`` at every point; ``kappa_at_damage(omega,
    params)`` its inverse (the FPZ width's level); ``onset(params)`` the kappa at which damage starts
    (omega and its derivative are zero below it: the integral model averages only where the average can
    reach it, :func:`fracid.fem.formulations.nonlocal_average.bounded_average`);
    ``parameter_derivatives(kappa, params) -> {name: d omega / d name}`` at fixed kappa, for the
    parameters it depends on (the direct differentiation of :mod:`fracid.fem.path.ddm`).
    """

    def damage(self, kappa, params): ...

    def parameter_derivatives(self, kappa, params) -> dict: ...

    def kappa_at_damage(self, omega: float, params) -> float: ...

    def onset(self, params) -> float: ...


class EquivalentStrain(Protocol):
    """Scalar strain measure driving damage: ``(strain_state, strain, params) -> (eps_eq, d eps_eq / d strain)``;
    ``parameter_derivatives(strain_state, strain, params) -> {name: d eps_eq / d name}`` at fixed strain."""

    def __call__(self, strain_state, strain, params): ...

    def parameter_derivatives(self, strain_state, strain, params) -> dict: ...


@dataclass(frozen=True)
class ExponentialSoftening:
    """omega = 1 - kappa_i / kappa (1 - alpha + alpha exp(-beta (kappa - kappa_i))) beyond kappa_i
    (parameters ``kappa_i``, ``alpha``, ``beta``; see :func:`~fracid.fem.material.damage.exponential_damage`)."""

    def damage(self, kappa, params):
        return exponential_damage(kappa, params.kappa_i, params.alpha, params.beta)

    def parameter_derivatives(self, kappa, params) -> dict:
        return exponential_damage_parameter_derivatives(kappa, params.kappa_i, params.alpha, params.beta)

    def kappa_at_damage(self, omega: float, params) -> float:
        return kappa_at_damage(omega, params.kappa_i, params.alpha, params.beta)

    def onset(self, params) -> float:
        return params.kappa_i


_MODIFIED_VON_MISES = {"uniaxial": (modified_von_mises_uniaxial, modified_von_mises_uniaxial_parameter_derivatives),
                       "plane stress": (modified_von_mises_plane_stress,
                                        modified_von_mises_plane_stress_parameter_derivatives)}


@dataclass(frozen=True)
class ModifiedVonMises:
    """De Vree's modified von Mises equivalent strain (parameters ``nu`` and ``eta``, the ratio of
    compressive to tensile strength), for the uniaxial and plane-stress strain states."""

    def __call__(self, strain_state, strain, params):
        return self._functions(strain_state)[0](strain, params.nu, params.eta)

    def parameter_derivatives(self, strain_state, strain, params) -> dict:
        return self._functions(strain_state)[1](strain, params.nu, params.eta)

    @staticmethod
    def _functions(strain_state):
        try:
            return _MODIFIED_VON_MISES[strain_state.name]
        except KeyError:
            raise ValueError(f"no modified von Mises strain for the {strain_state.name!r} strain state") from None


@dataclass(frozen=True)
class DamageLaw:
    """A continuum damage law: a softening law of kappa, the equivalent strain that drives it, and
    the parameter class holding their parameters and the elastic ones (``E``, ``nu``; ``c`` for
    the regularised formulations).

    Examples
    --------
    >>> law = DamageLaw()
    >>> float(law.softening.damage(2e-4, DamageParameters())[0]) > 0
    True
    """

    softening: SofteningLaw = ExponentialSoftening()
    equivalent_strain: EquivalentStrain = ModifiedVonMises()
    parameters: type = field(default=DamageParameters, compare=False)  # named by the parameters' own fields
    name: str = "exponential"

    def damage(self, kappa, params):
        return self.softening.damage(kappa, params)

    @property
    def differentiable(self) -> bool:
        """Whether both parts give their parameter derivatives (a law without them is identified with
        central differences of runs)."""
        return all(callable(getattr(part, "parameter_derivatives", None))
                   for part in (self.softening, self.equivalent_strain))

    def scales(self, params) -> dict:
        """Characteristic values a specimen sizes its default control with: ``strain`` [-]."""
        return {"strain": self.softening.onset(params)}

    def kappa_at_damage_derivatives(self, omega: float, params, names) -> np.ndarray:
        """d kappa / d x of the kappa at which the damage reaches ``omega`` (the FPZ width's level), by
        the implicit function theorem on omega(kappa; x) = omega: -(d omega / d x) / (d omega / d kappa),
        from the damaged branch (at omega = 0, the onset's derivative)."""
        kappa = np.atleast_1d(self.softening.kappa_at_damage(omega, params))
        _, d_kappa = self.softening.damage(kappa, params)
        partial = self.softening.parameter_derivatives(kappa, params)
        return np.array([-float(partial[name][0]) / float(d_kappa[0]) if name in partial else 0.0 for name in names])


#: The damage laws by name (a configuration's ``[model] law`` of the damage models); a law of other parts is
#: given in Python (``DamageLaw(softening=..., name=...)``) or registered here under its name
DAMAGE_LAWS = {law.name: law for law in (DamageLaw,)}


# ------------------------------------------------------------------------------------------------
# traction-separation laws (the contract: fracid.fem.material.tsl.TractionSeparationLaw)


@dataclass(frozen=True)
class HordijkLaw(ShapeLaw):
    """Hordijk's traction-opening law, for the cohesive crack and the crack band (parameters of
    :class:`~fracid.fem.material.cohesive.CohesiveParameters`: ft, Gf, c1, c2 and the elastic E, nu); the
    shape is :func:`~fracid.fem.material.cohesive.hordijk_shape`, wc = Gf / (ft I(c1, c2))."""

    name: ClassVar[str] = "hordijk"
    parameters: ClassVar[type] = CohesiveParameters

    def shape(self, x, params):
        return hordijk_shape(x, params.c1, params.c2)

    def shape_derivatives(self, x, params) -> dict:
        return hordijk_shape_derivatives(x, params.c1, params.c2)

    def area(self, params) -> float:
        return params.area_factor

    def area_derivatives(self, params) -> dict:
        return dict(zip(("c1", "c2"), params.area_factor_derivatives()))

    def steepest_shape_slope(self, params, samples: int = 2001) -> float:
        """max ``|f'|`` over 2001 points of [0, 1] (the law is smooth there)."""
        return float(np.max(np.abs(hordijk_shape(np.linspace(0.0, 1.0, samples), params.c1, params.c2)[1])))


LinearSofteningParameters = compose(
    "LinearSofteningParameters", ELASTIC, STRENGTH_AND_ENERGY,
    summary="Parameters x = (E, nu, ft, Gf) of a bulk with linear-softening cohesive cracks, sigma = ft (1 - w / wc), "
            "wc = 2 Gf / ft.")


@dataclass(frozen=True)
class LinearSoftening(ShapeLaw):
    """Linear softening, sigma = ft (1 - w / wc) for 0 <= w < wc, wc = 2 Gf / ft [mm] (area Gf);
    parameters :data:`LinearSofteningParameters` (E, nu, ft, Gf)."""

    name: ClassVar[str] = "linear"
    parameters: ClassVar[type] = LinearSofteningParameters

    def shape(self, x, params):
        x = np.asarray(x, dtype=float)
        return 1.0 - x, np.full(x.shape, -1.0)

    def shape_derivatives(self, x, params) -> dict:
        return {}

    def area(self, params) -> float:
        return 0.5

    def area_derivatives(self, params) -> dict:
        return {}

    def steepest_shape_slope(self, params) -> float:
        return 1.0


BILINEAR_SHAPE = (
    Field("psi", 1.0 / 3.0, ParameterRange(0.0, False, 1.0, False, "-"), "Traction at the kink relative to ft"),
    Field("chi", 2.0 / 9.0, ParameterRange(0.0, False, 1.0, False, "-"), "Opening at the kink relative to wc"),
)

BilinearSofteningParameters = compose(
    "BilinearSofteningParameters", ELASTIC, STRENGTH_AND_ENERGY, BILINEAR_SHAPE,
    summary="Parameters x = (E, nu, ft, Gf, psi, chi) of a bulk with bilinear-softening cohesive cracks: a kink at "
            "(w1, sigma1) = (chi wc, psi ft), wc = 2 Gf / (ft (psi + chi)) (defaults: Petersson's "
            "law, sigma1 = ft / 3 at w1 = 0.8 Gf / ft, wc = 3.6 Gf / ft).")


@dataclass(frozen=True)
class BilinearSoftening(ShapeLaw):
    """Bilinear softening: from (0, ft) to the kink (w1, sigma1) = (chi wc, psi ft), then to (wc, 0).

    The area is ft (w1 + psi wc) / 2 = ft wc (chi + psi) / 2 = Gf, so wc = 2 Gf / (ft (psi + chi))
    [mm]. Parameters :data:`BilinearSofteningParameters` (E, nu, ft [MPa], Gf [N/mm], psi [-],
    chi [-]); the defaults are Petersson's law (psi = 1/3, chi = 2/9: w1 = 0.8 Gf / ft, wc = 3.6 Gf /
    ft). The law has kinks at w1 and wc. Every psi, chi in (0, 1) gives a decreasing law (the
    ranges are a box); concrete's usual laws have psi + chi < 1, a first branch steeper than the second.
    """

    name: ClassVar[str] = "bilinear"
    parameters: ClassVar[type] = BilinearSofteningParameters

    def shape(self, x, params):
        x = np.asarray(x, dtype=float)
        psi, chi = params.psi, params.chi
        first = x < chi
        f = np.where(first, 1.0 - (1.0 - psi) * x / chi, psi * (1.0 - x) / (1.0 - chi))
        return f, np.where(first, -(1.0 - psi) / chi, -psi / (1.0 - chi))

    def shape_derivatives(self, x, params) -> dict:
        x = np.asarray(x, dtype=float)
        psi, chi = params.psi, params.chi
        first = x < chi
        return {"psi": np.where(first, x / chi, (1.0 - x) / (1.0 - chi)),
                "chi": np.where(first, (1.0 - psi) * x / chi**2, psi * (1.0 - x) / (1.0 - chi) ** 2)}

    def area(self, params) -> float:
        return 0.5 * (params.psi + params.chi)

    def area_derivatives(self, params) -> dict:
        return {"psi": 0.5, "chi": 0.5}

    def steepest_shape_slope(self, params) -> float:
        return max((1.0 - params.psi) / params.chi, params.psi / (1.0 - params.chi))

    def kinks(self, params) -> tuple:
        """The opening of the kink, w1 = chi wc [mm] (a table of the law keeps it)."""
        return (params.chi * self.critical_opening(params),)


#: The traction-separation laws by name (a configuration's or a user's choice of law for the crack models)
TRACTION_SEPARATION_LAWS = {law.name: law for law in (HordijkLaw, LinearSoftening, BilinearSoftening)}


def as_array(value, shape) -> np.ndarray:
    """``value`` (a number or an array) broadcast to ``shape``, as floats."""
    return np.broadcast_to(np.asarray(value, dtype=float), shape)
