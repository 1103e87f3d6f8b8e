"""A rectangular strip in uniaxial tension: the check of a smeared crack's energy per crack area."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from fracid.model.discretization import plane_stress_discretization
from fracid.specimens.checks import require_positive
from fracid.specimens.meshing import structured_quad8


@dataclass(frozen=True)
class TensionStrip:
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

    def __post_init__(self):
        require_positive(self, ("length", "height", "thickness"), " [mm]")
        if not (isinstance(self.n_elements, int) and self.n_elements >= 3 and self.n_elements % 2 == 1):
            raise ValueError(f"TensionStrip.n_elements = {self.n_elements!r}; it must be an odd integer >= 3 "
                             "(the weak column sits in the middle)")
        if not 0.0 < self.weak_factor <= 1.0:
            raise ValueError(f"TensionStrip.weak_factor = {self.weak_factor!r}; it must be in (0, 1]")

    @property
    def element_size(self) -> float:
        return self.length / self.n_elements

    def mesh(self):
        rows = max(1, round(self.height / self.element_size))
        return structured_quad8(np.linspace(0.0, self.length, self.n_elements + 1), np.linspace(0.0, self.height, rows + 1))

    def build_crack_band_problem(self, params, band_width: float | None = None):
        """The strip with the rotating crack band of ``params`` (:class:`~fracid.model.cohesive.CohesiveParameters`).

        ``band_width`` [mm] overrides the element widths the law is scaled by (to see what an
        unscaled softening law does to the energy)."""
        from fracid.model.crack_band_problem import CrackBandProblem, element_extent

        mesh = self.mesh()
        disc = plane_stress_discretization(mesh.nodes, mesh.cells, mesh.n_vertices, self.thickness)
        left, right = mesh.nodes_near(x=0.0), mesh.nodes_near(x=self.length)
        h = self.element_size
        band_left = mesh.nodes_near(x=(self.n_elements // 2) * h)
        band_right = mesh.nodes_near(x=(self.n_elements // 2 + 1) * h)
        centre = np.abs(disc.points[..., 0] - 0.5 * self.length) < 0.5 * h
        opening = {2 * n: 1.0 / band_right.size for n in band_right}
        opening.update({2 * n: -1.0 / band_left.size for n in band_left})
        return CrackBandProblem(
            disc,
            params,
            element_extent(mesh.nodes, mesh.cells, (1.0, 0.0)) if band_width is None else np.full(len(mesh.cells), band_width),
            strength_factor=np.where(centre, self.weak_factor, 1.0),
            fixed_dofs=np.concatenate([2 * left, [2 * mesh.closest_node((0.0, 0.0)) + 1]]),
            tied=[2 * right],
            load={2 * int(right[0]): 1.0},
            functionals={"elongation": {2 * int(right[0]): 1.0}, "band_opening": opening},
        )

    def default_steps(self, target: float):
        """Adaptive steps capped at 1/50 of the target."""
        from fracid.model.path_following import StepOptions

        return StepOptions(maximum=target / 50)

    def default_target(self, params) -> float:
        """Band opening 0.99 wc [mm] (wc of the weak column, which keeps Gf at a lower strength): the crack
        is then all but free of stress (the area of Hordijk's law beyond 0.99 wc is 1e-5 Gf). At wc the
        strip is cut in two and has no stiffness left."""
        return 0.99 * params.wc / self.weak_factor
