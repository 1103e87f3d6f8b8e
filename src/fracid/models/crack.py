"""The models of one crack with a traction-separation law: the discrete cohesive crack
(:class:`CohesiveCrackModel`) and the smeared crack band (:class:`CrackBandModel`)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from fracid.fem.formulations.cohesive_problem import CohesiveCrackProblem, crack_edges
from fracid.fem.formulations.crack_band_problem import CrackBandProblem, element_extent
from fracid.fem.material.laws import TRACTION_SEPARATION_LAWS, HordijkLaw
from fracid.fem.material.tsl import differentiable as gives_derivatives
from fracid.models.cohesive_law import law_table
from fracid.models.path_model import PathFollowingModel
from fracid.models.protocol import SpecimenStart
from fracid.specimens.description import at_points, conditions, described, discretize
from fracid.specimens.wedge import WedgeSplitting


class CrackModel(PathFollowingModel):
    """The models of one crack with a traction-separation law (:class:`~fracid.fem.material.tsl.TractionSeparationLaw`,
    Hordijk's by default): plane stress, where the specimen says the crack runs."""

    #: observers whose values the runs do not differentiate (a count of cracked points: a staircase)
    observer_names: ClassVar[tuple] = ("crack_length",)
    #: ``[model] law``: the traction-separation laws by name
    laws: ClassVar[dict] = TRACTION_SEPARATION_LAWS
    #: a first identification looks for the strength and the fracture energy
    first_identified: ClassVar[tuple] = ("ft", "Gf")

    @property
    def parameters(self) -> type:
        return self.law.parameters

    @property
    def differentiable(self) -> tuple:
        """Every parameter of the law if the law gives its parameter derivatives, else none."""
        return tuple(self.parameters.names()) if gives_derivatives(self.law) else ()

    def why_not(self, specimen):
        d = described(specimen)
        if d.dim != 2:
            return "it is a plane-stress model"
        if d.crack is None:
            return "the specimen says nothing of where the crack runs"
        return self.path_problem(d.crack)

    def path_problem(self, crack) -> str | None:
        """Why the specimen's crack path does not suit this model, or None."""
        return None

    def cohesive_law(self, params):
        """Its own law at ``params`` as a table (:func:`~fracid.models.cohesive_law.law_table`)."""
        return law_table(self.law, params)


@dataclass(frozen=True)
class CohesiveCrackModel(CrackModel):
    """Discrete cohesive crack with a traction-separation law (Hordijk's by default) along the specimen's crack path (a symmetry line of
    the model), elastic bulk (docs/theory.md, section 5). The faces are tied by a penalty
    ``penalty_factor * E / h`` [MPa/mm] (h the finest element size along the path) until the traction
    reaches ft. Observable: ``crack_length`` [mm], the length of the path whose faces have separated.
    """

    penalty_factor: float = 1000.0
    law: HordijkLaw = HordijkLaw()

    #: another code represents it by interface elements
    crack_representation: ClassVar[str] = "discrete"

    @property
    def key(self) -> str:
        """``cohesive-crack-<law>``: runs of different traction-separation laws never share a key."""
        return f"cohesive-crack-{self.law.name}"

    def path_problem(self, crack):
        if crack.nodes is None or not crack.mirrored:
            return "the specimen has no crack path on a symmetry line"
        return None

    def build(self, specimen, params):
        d = described(specimen)
        disc = discretize(d)
        path = d.nodes_of(d.crack.nodes)
        edges = crack_edges(d.nodes, d.cells, disc.u_dofs, path, d.crack.normal)
        h = d.crack.element_size or float((edges[2][:, 2] - edges[2][:, 0]).min())
        return CohesiveCrackProblem(disc, self.law, params, conditions(d, open_crack=True, discrete_crack=True), edges,
                                    float(d.section), self.penalty_factor * params.E / h,
                                    stiffness_factor=at_points(d.stiffness_factor, disc))

    def observers(self, description, params, damage_threshold: float = 0.0) -> dict:
        return {"crack_length": lambda problem, q, arrays: problem.cracked_length(arrays.history)}


@dataclass(frozen=True)
class CrackBandModel(CrackModel):
    """Smeared crack band: a rotating crack with a traction-separation law (Hordijk's by default) scaled by the band width
    (docs/theory.md, section 5). Same parameters as the cohesive crack, so the two are directly
    comparable. The band is confined to the elements along the specimen's crack path (in a half
    model a band elsewhere would be mirrored into two cracks), or free where the specimen has no path.

    ``band_width`` [mm] overrides the element widths the law is scaled by (to see what an unscaled
    softening law does to the energy).
    """

    band_width: float | None = None
    law: HordijkLaw = HordijkLaw()

    #: on the wedge-splitting test the default mesh stops converging after the peak
    specimen_starts: ClassVar[dict] = {
        WedgeSplitting: SpecimenStart({"h_fine": 4.0}, "at h_fine = 5 the crack band stops converging after the peak "
                                                       "(cmod 0.046 mm); 4 runs through")}

    @property
    def key(self) -> str:
        """``crack-band-<law>[-band-<width>]``: runs of different laws or band widths never share a key."""
        return f"crack-band-{self.law.name}" + ("" if self.band_width is None else f"-band-{self.band_width:g}")

    def build(self, specimen, params):
        d = described(specimen)
        disc = discretize(d)
        direction = [0.0, 0.0]
        direction[d.crack.normal] = 1.0
        width = element_extent(d.nodes, d.cells, direction)
        if self.band_width is not None:
            width = np.full(len(d.cells), float(self.band_width))
        crackable = 1.0
        if d.crack.nodes is not None:
            on_path = (d.nodes_of(d.crack.nodes)[None, None, :] == d.corners[:, :, None]).any(axis=2).sum(axis=1) >= 2
            crackable = np.repeat(on_path[:, None], disc.weights.shape[1], axis=1).astype(float)
        if d.crack.mirrored and self.band_width is None:
            width = 2.0 * width
        return CrackBandProblem(disc, self.law, params, conditions(d, open_crack=True), width,
                                strength_factor=at_points(d.strength_factor, disc), crackable=crackable,
                                stiffness_factor=at_points(d.stiffness_factor, disc))

    def observers(self, description, params, damage_threshold: float = 0.0) -> dict:
        return {}
