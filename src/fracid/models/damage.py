"""The continuum damage models: gradient, local or integral damage with a damage law (:class:`DamageModel`)."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import ClassVar

from fracid.fem.formulations.fpz import zone_width_observer
from fracid.fem.formulations.problem import FORMULATIONS
from fracid.fem.material.laws import DAMAGE_LAWS, DamageLaw
from fracid.models.cohesive_law import equivalent_law_on_bar
from fracid.models.path_model import PathFollowingModel
from fracid.models.protocol import BandWidth, MeshLength
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
    def band_width(self) -> BandWidth | None:
        """The width 2 pi sqrt(c) = pi sqrt(2) l of the damage band at the onset of localisation (Peerlings et al.
        1996: the localisation zone of the gradient model spans a full wave of cos(x / sqrt(c))); the integral
        model's Gaussian of standard deviation l = sqrt(2 c) has the same second moment as the gradient model's
        Green function exp(-``|x|`` / sqrt(c)) / (2 sqrt(c)), and measured on the 100 mm bar its damaged zone is as wide
        (11.6 and 21 mm at the peak for c = 1 and 4 mm^2, against 11.2 and 19.9 mm of the gradient model).

        The band then widens as the damage grows (implicit gradient): measured on the 100 mm bar (exponential law,
        defaults), the zone where omega > 0 is 1.8 (at the peak) and 2.7 (at half the peak force after it) times
        2 pi sqrt(c) at c = 16 mm^2. Its effect on the response, measured on bars of length L at c = 16 mm^2 (the same
        10 mm weak zone): the force against the inelastic opening after the peak departs from that of a bar 12.5
        times longer by 0.14, 1.2, 4.1 and 9.5 % of the peak at 2 pi sqrt(c) = L / 4, L / 2, 3 L / 4 and L (7 % less
        energy at L), 15 % at 1.3 L. Hence warned above half the specimen's room and refused above it (the whole
        specimen softens, no band localises). None for local damage.
        """
        if self.mesh_length is None:
            return None
        return BandWidth("c", "mm^2", 2.0 * math.pi, 0.5, "the damage band's width 2 pi sqrt(c)",
                         "a damage band that localises inside the specimen", 0.5,
                         "measured on bars, the response departs by 4 % of the peak at three quarters of the length "
                         "and by 9.5 % at the whole length")

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

    def cohesive_law(self, params):
        """The cohesive law it dissipates like, from a bar 4 band widths long (2 pi sqrt(c) each) with elements of
        an eighth of the internal length l = sqrt(2 c) (its energy within 0.1 % of a mesh twice finer, measured at the
        defaults: tests/test_export.py) (:func:`~fracid.models.cohesive_law.equivalent_law_on_bar`). Local damage
        has none: the energy it dissipates depends on the element size.

        Raises
        ------
        ValueError
            For local damage.
        """
        if self.band_width is None:
            raise ValueError("local damage has no cohesive law: the energy it dissipates depends on the element "
                             "size (identify the crack band or a regularised damage model instead)")
        c = params.c
        width = self.band_width.factor * c ** self.band_width.exponent
        return equivalent_law_on_bar(self, params, width, 0.125 * self.mesh_length.length(c),
                                     f"{self.regularization} damage")
