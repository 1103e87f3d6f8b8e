"""The phase-field regularised cohesive zone model, PF-CZM (:class:`PhaseFieldModel`)."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from fracid.fem.formulations.phase_field_problem import PhaseFieldProblem
from fracid.fem.material.phase_field import PHASE_FIELD_SHAPES, PhaseFieldSoftening
from fracid.fem.material.phase_field_cohesive import localized_cohesive_law
from fracid.models.cohesive_law import CohesiveLawTable
from fracid.models.path_model import PathFollowingModel
from fracid.models.protocol import BandWidth, MeshLength
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
    #: the band's full width pi l: the 1D profile of alpha(d) = 2 d - d^2 is d = 1 - sin(|x| / l), zero at
    #: |x| = pi l / 2 (Wu 2017). Measured on bars of length L at l = 10 mm (Cornelissen shape, h <= l / 5, the same
    #: 10 mm weak zone, fracid.simulate under end_displacement): the force against the band's opening
    #: after the peak departs from that of a bar 12.5 times longer by 0.55, 0.66, 0.59 and 1.4 % of the peak at
    #: pi l = L / 4, L / 2, 3 L / 4 and L, then 7.8 % with 22 % less energy at 1.3 L (l = 1000 mm on a 100 mm bar:
    #: a peak 4.8 times). Refused above the room (the profile is cut by the specimen's ends); warned above half of
    #: it, a margin for 2D specimens, whose room (a beam's depth) only bounds the band about the crack's tip
    band_width: ClassVar[BandWidth] = BandWidth("l", "mm", math.pi, 1.0, "the band's width pi l",
                                                "the cohesive law of its softening shape", 0.5,
                                                "measured on bars, the law departs by 1.4 % of the peak at the whole "
                                                "length and by 8 %, with 22 % less energy, at 1.3 times it")

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

    def cohesive_law(self, params):
        """Its localized band's traction-opening law in closed form (Wu 2017; independent of l), an
        equivalence: the band is a continuum of width pi l, not a crack."""
        w, sigma = localized_cohesive_law(params.E, params.ft, params.Gf, params.l, params.p, params.a2, params.a3)
        order = np.argsort(w)
        w, sigma = np.concatenate([[0.0], w[order][1:]]), sigma[order].copy()
        sigma[-1] = 0.0  # the closed form ends at 1e-3 ft: the table ends the law there
        return CohesiveLawTable(w, sigma, "equivalent", f"PF-CZM ({self.law.name})",
                                f"the PF-CZM's localized band in 1D, in closed form (Wu 2017), {w.size} points down "
                                f"to 0.1 % of ft")
