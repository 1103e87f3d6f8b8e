"""The continuum damage models: gradient, local or integral damage with a damage law (:class:`DamageModel`)."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import ClassVar

from fracid.fem.formulations.fpz import zone_width_observer
from fracid.fem.formulations.problem import FORMULATIONS
from fracid.fem.material.laws import DAMAGE_LAWS, DamageLaw
from fracid.models.path_model import PathFollowingModel
from fracid.models.protocol import MeshLength
from fracid.specimens.description import at_points, conditions, described, discretize, uniform


@dataclass(frozen=True)
class DamageModel(PathFollowingModel):
    """Continuum damage: ``"gradient"`` (implicit gradient enhancement), ``"local"`` (no
    regularisation; mesh-dependent, for comparison) or ``"integral"`` (Gaussian average of the
    equivalent strain, internal length l = sqrt(2 c)), with a damage law (exponential softening and
    the modified von Mises equivalent strain by default; see docs/theory.md, section 1).

    Observable: the width of the damaged zone where the specimen measures it (``fpz_width`` or
    ``damaged_zone_width`` [mm], the zone where omega exceeds ``damage_threshold``).
    """

    regularization: str = "gradient"
    law: DamageLaw = field(default_factory=DamageLaw)
    #: its observers (the zone widths) have derivatives in the runs with ``sensitivities``
    differentiates_observers: ClassVar[bool] = True
    #: ``[model] law``: the damage laws by name
    laws: ClassVar[dict] = DAMAGE_LAWS

    def __post_init__(self):
        if self.regularization not in FORMULATIONS:
            raise ValueError(f"regularization = {self.regularization!r}; choose 'gradient', 'local' or 'integral'")

    @property
    def parameters(self) -> type:
        return self.law.parameters

    @property
    def key(self) -> str:
        suffix = "" if self.law.name == "exponential" else f"-{self.law.name}"
        return f"{self.regularization}-damage{suffix}"

    @property
    def mesh_length(self) -> MeshLength | None:
        """The internal length l = sqrt(2 c) of the regularised formulations (none for local damage)."""
        if self.regularization == "local":
            return None
        return MeshLength("c", "mm^2", lambda c: math.sqrt(2.0 * c), "the internal length l = sqrt(2 c)",
                          "the damage band")

    @property
    def first_identified(self) -> tuple:
        """The damage onset and softening (kappa_i, beta) and, when regularised, the internal length's c."""
        return ("kappa_i", "beta") if self.mesh_length is None else ("kappa_i", "beta", "c")

    def why_not(self, specimen):
        d = described(specimen)
        if d.strength_factor is not uniform:
            return "its imperfection is a reduced tensile strength, which a damage law does not read"
        return None

    @property
    def differentiable(self) -> tuple:
        """Every parameter of the law if the law gives its parameter derivatives, else none."""
        return tuple(self.parameters.names()) if self.law.differentiable else ()

    def build(self, specimen, params):
        """The problem of this formulation on ``specimen`` (a specimen or its description)."""
        d = described(specimen)
        disc = discretize(d)
        return FORMULATIONS[self.regularization](
            disc, self.law, params, conditions(d), stiffness_factor=at_points(d.stiffness_factor, disc),
            damageable=at_points(d.damageable, disc), symmetry_planes=d.symmetry_planes)

    def observers(self, description, params, damage_threshold: float = 0.0) -> dict:
        zone = description.zone
        if zone is None:
            return {}
        law = self.law
        return {zone.name: zone_width_observer(zone, law.softening.kappa_at_damage(damage_threshold, params),
                                               lambda names: law.kappa_at_damage_derivatives(damage_threshold, params,
                                                                                             names))}
