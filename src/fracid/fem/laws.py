"""Material laws as small objects: values and derivatives at all integration points at once.

A formulation (gradient, local or integral damage; the crack band; the cohesive interface) takes a
law and asks it for values and derivatives; it never names the law's parameters. A new law is a new
object with the same methods (see :class:`DamageLaw`), nothing else changes. The parameter
derivatives of the laws (for sensitivities computed inside the analysis) belong here too.

Units: strains [-], stresses [MPa], openings [mm].
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import ClassVar, Protocol

import numpy as np

from fracid.fem.damage import exponential_damage, exponential_damage_parameter_derivatives, kappa_at_damage
from fracid.fem.equivalent_strain import (modified_von_mises_plane_stress,
                                          modified_von_mises_plane_stress_parameter_derivatives,
                                          modified_von_mises_uniaxial, modified_von_mises_uniaxial_parameter_derivatives)
from fracid.fem.parameters import DamageParameters


class SofteningLaw(Protocol):
    """Damage omega(kappa) of the history variable kappa.

    ``damage(kappa, params) -> (omega, d omega / d kappa)`` at every point; ``kappa_at_damage(omega,
    params)`` its inverse (the FPZ width's level); ``onset(params)`` the kappa at which damage starts;
    ``parameter_derivatives(kappa, params) -> {name: d omega / d name}`` at fixed kappa, for the
    parameters it depends on (the direct differentiation of :mod:`fracid.fem.ddm`).
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
    (parameters ``kappa_i``, ``alpha``, ``beta``; see :func:`~fracid.fem.damage.exponential_damage`)."""

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


@dataclass(frozen=True)
class HordijkLaw:
    """Hordijk's traction-opening law, for the cohesive crack and the crack band (parameters of
    :class:`~fracid.fem.cohesive.CohesiveParameters`: ft, Gf, c1, c2 and the elastic E, nu)."""

    name: ClassVar[str] = "hordijk"

    @property
    def parameters(self) -> type:
        from fracid.fem.cohesive import CohesiveParameters

        return CohesiveParameters

    def scales(self, params) -> dict:
        """``strain`` = ft / E [-] and ``opening`` = wc, the opening of zero traction [mm]."""
        return {"strain": params.ft / params.E, "opening": params.wc}


def as_array(value, shape) -> np.ndarray:
    """``value`` (a number or an array) broadcast to ``shape``, as floats."""
    return np.broadcast_to(np.asarray(value, dtype=float), shape)
