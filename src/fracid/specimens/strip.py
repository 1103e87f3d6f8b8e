"""A rectangular strip in uniaxial tension: the check of a smeared crack's energy per crack area."""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from fracid.settings.field_error import FieldError
from fracid.specimens.checks import require_positive
from fracid.specimens.protocol import (BandRoom, Resolution, SizeEstimate, SpecimenDefaults, bar_resolution,
                                       plane_estimate)
from fracid.specimens.description import CrackPath, Description, Load, Measure, Support
from fracid.specimens.meshing import quad8_grid_size, structured_quad8


@dataclass(frozen=True)
class TensionStrip(SpecimenDefaults):
    """Plane-stress strip L x H (thickness t) pulled by a rigid platen at x = L, held at x = 0.

    The element column at mid-length is weaker (tensile strength times ``weak_factor``) so the crack
    forms there, across the whole height: the dissipated energy at separation is Gf H t whatever the
    element size, the test of a crack band's regularisation.

    Parameters
    ----------
    length, height, thickness : float
        L, H, t [mm].
    n_elements : int
        Elements along the length (square elements: H / (L / n) rows, at least one).
    weak_factor : float
        Strength of the middle column relative to ft, in (0, 1] [-].

    Controls: ``band_opening`` (default: the elongation of the weak column, which passes the
    snap-back of a long strip) and ``elongation`` (the platen's displacement) [mm].
    """

    length: float = 100.0
    height: float = 10.0
    thickness: float = 10.0
    n_elements: int = 21
    weak_factor: float = 0.98

    default_control = "band_opening"
    controls: ClassVar[tuple] = ("band_opening", "elongation")
    #: the control that grows through a snap-back (an opening across the crack)
    snap_back_control: ClassVar[str] = "band_opening"
    observables: ClassVar[tuple] = ()
    steps_per_target: ClassVar[float] = 50.0

    def __post_init__(self):
        require_positive(self, ("length", "height", "thickness"), " [mm]")
        if not (isinstance(self.n_elements, int) and self.n_elements >= 3 and self.n_elements % 2 == 1):
            raise FieldError("n_elements", self.n_elements,
                             f"TensionStrip.n_elements = {self.n_elements!r}; it must be an odd integer >= 3 "
                             "(the weak column sits in the middle)")
        if not 0.0 < self.weak_factor <= 1.0:
            raise FieldError("weak_factor", self.weak_factor,
                             f"TensionStrip.weak_factor = {self.weak_factor!r}; it must be in (0, 1]")

    @property
    def element_size(self) -> float:
        return self.length / self.n_elements

    @property
    def _rows(self) -> int:
        return max(1, round(self.height / self.element_size))

    def mesh(self):
        return structured_quad8(np.linspace(0.0, self.length, self.n_elements + 1),
                                np.linspace(0.0, self.height, self._rows + 1))

    def resolution(self, internal_length: float | None = None) -> Resolution:
        """The element size length / n_elements [mm] (square elements)."""
        return bar_resolution(self.length, self.n_elements, internal_length)

    def size_estimate(self) -> SizeEstimate:
        """The unknowns of the n_elements x rows grid, counted without building it."""
        return plane_estimate("n_elements", self.n_elements, *quad8_grid_size(self.n_elements, self._rows),
                              "use fewer n_elements")

    def describe(self) -> Description:
        """The strip held at x = 0 (one node also vertically), pulled by a rigid platen at x = L, the
        middle column weaker; a crack may form anywhere across x."""
        mesh = self.mesh()
        h = self.element_size
        sets = {"left": mesh.nodes_near(x=0.0), "right": mesh.nodes_near(x=self.length),
                "corner": np.array([mesh.closest_node((0.0, 0.0))]),
                "band_left": mesh.nodes_near(x=(self.n_elements // 2) * h),
                "band_right": mesh.nodes_near(x=(self.n_elements // 2 + 1) * h)}
        centre = lambda points: np.abs(points[..., 0] - 0.5 * self.length) < 0.5 * h  # noqa: E731
        return Description(
            nodes=mesh.nodes, cells=mesh.cells, n_vertices=mesh.n_vertices, section=self.thickness, node_sets=sets,
            supports=(Support("left", 0), Support("corner", 1)), loads=(Load("right", 0, 1.0),),
            functionals={"elongation": (Measure("right", 0),),
                         "band_opening": (Measure("band_right", 0), Measure("band_left", 0, -1.0))},
            strength_factor=lambda points: np.where(centre(points), self.weak_factor, 1.0),
            crack=CrackPath(None, normal=0, mirrored=False),
        )

    def band_room(self) -> BandRoom:
        """L: the crack forms across the whole height at once, and its band lies along the length between the
        platens."""
        return BandRoom(self.length, f"its length = {self.length:g} mm")

    def default_target(self, scales) -> float:
        """Band opening 0.99 wc [mm] (wc = ``scales["opening"]`` of the weak column, which keeps Gf at a
        lower strength): the crack is then all but free of stress (the area of Hordijk's law beyond 0.99 wc is 1e-5 Gf). At wc the
        strip is cut in two and has no stiffness left."""
        if "opening" not in scales:
            raise ValueError("the tension strip's default target is a crack opening: give target= for this model")
        return 0.99 * scales["opening"] / self.weak_factor
