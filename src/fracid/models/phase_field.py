"""The phase-field regularised cohesive zone model, PF-CZM (:class:`PhaseFieldModel`)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

from fracid.fem.formulations.phase_field_problem import PhaseFieldProblem
from fracid.fem.material.phase_field import PHASE_FIELD_SHAPES, PhaseFieldSoftening
from fracid.models.path_model import PathFollowingModel
from fracid.models.protocol import MeshLength
from fracid.specimens.description import at_points, conditions, described, discretize


@dataclass(frozen=True)
class PhaseFieldModel(PathFollowingModel):
    """The phase-field regularised cohesive zone model (PF-CZM; Wu 2017, docs/theory.md, section 7): the
    displacements and a crack phase field of length scale ``l`` solved together, whose global response follows
    the cohesive law of its softening shape (Cornelissen's by default; linear, exponential) for any l fine enough
    for the mesh (h <= l / 5 where the crack runs). Runs wherever a damage model runs, and reads a specimen's
    strength imperfection.
    """

    law: PhaseFieldSoftening = PhaseFieldSoftening()

    #: ``[model] law``: the softening shapes by name
    laws: ClassVar[dict] = PHASE_FIELD_SHAPES
    #: a first identification looks for the strength and the fracture energy (l is numerical)
    first_identified: ClassVar[tuple] = ("ft", "Gf")
    #: h <= l / 5 where the crack runs (Wu 2017): the band's profile is then resolved
    mesh_length: ClassVar[MeshLength] = MeshLength("l", "mm", lambda l: l / 5.0, "l / 5 (a fifth of the length scale)",
                                                   "the phase field's band",
                                                   "make the elements where the crack runs {size:.3g} mm or smaller")

    @property
    def parameters(self) -> type:
        return self.law.parameters

    @property
    def key(self) -> str:
        """``pf-czm-<shape>``: runs of different softening shapes never share a key."""
        return f"pf-czm-{self.law.name}"

    @property
    def differentiable(self) -> tuple:
        return PhaseFieldProblem.differentiable

    def build(self, specimen, params):
        d = described(specimen)
        disc = discretize(d)
        return PhaseFieldProblem(disc, params, conditions(d), stiffness_factor=at_points(d.stiffness_factor, disc),
                                 damageable=at_points(d.damageable, disc),
                                 strength_factor=at_points(d.strength_factor, disc))

    def observers(self, description, params, damage_threshold: float = 0.0) -> dict:
        return {}
