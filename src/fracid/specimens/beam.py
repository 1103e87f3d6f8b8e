"""Notched three-point bending beam (SPEC section 2), modelled as a symmetric half."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from fracid.model.discretization import plane_stress_discretization
from fracid.model.problem import DamageProblem
from fracid.specimens.checks import require_positive
from fracid.specimens.fpz import fpz_width_observer
from fracid.specimens.meshing import QuadMesh, graded_count, graded_lines, quad8_grid_size, structured_quad8


@dataclass(frozen=True)
class NotchedBeam:
    """Notched beam in three-point bending; the default geometry is the Gregoire et al. (2013) beam.

    The half x >= 0 is meshed (symmetry: u_x = 0 on the ligament above the notch). The load acts on
    a rigid loading plate at mid-span, the support is a roller at x = S/2. Curves are for the full
    specimen: force [N], CMOD and mid-span deflection [mm]. S = L (a beam supported at its ends) is
    allowed: the support then holds the nodes of the bottom edge within ``plate_width / 2`` of the end.

    Parameters
    ----------
    depth, thickness, length, span : float
        D, b, L, S [mm], S <= L.
    notch_depth, notch_width : float
        a0 and the notch width [mm].
    plate_width : float
        Width of the loading plate and of each support [mm]: the plate's nodes move together
        vertically, the support's nodes are held vertically (a point load or support would make
        the deflection mesh-dependent).
    h_fine : float
        Element size in the process zone, a band of ``fine_width`` around the ligament [mm].
    h_coarse : float
        Largest element size away from it [mm].
    fine_width : float
        Half-width of the refined band around the crack path [mm].

    Controls: ``cmod`` (default; passes snap-back) and ``deflection`` (plain displacement control
    of the loading plate). Observer: ``fpz_width`` [mm].
    """

    depth: float = 50.0
    thickness: float = 50.0
    length: float = 175.0
    span: float = 125.0
    notch_depth: float = 25.0
    notch_width: float = 2.0
    plate_width: float = 5.0
    h_fine: float = 1.0
    h_coarse: float = 4.0
    fine_width: float = 10.0

    default_control = "cmod"

    def __post_init__(self):
        require_positive(self, ("depth", "thickness", "length", "span", "notch_depth", "notch_width", "plate_width",
                                "h_fine", "h_coarse", "fine_width"), " [mm]")
        if not self.span <= self.length:
            raise ValueError(f"span = {self.span} must not exceed length = {self.length} (S = L: supports at the ends)")
        if not self.notch_depth < self.depth:
            raise ValueError(f"notch_depth = {self.notch_depth} must be smaller than depth = {self.depth}")
        if not self.notch_width / 2 < self.fine_width < self.span / 2 - self.plate_width / 2:
            raise ValueError(f"fine_width = {self.fine_width} must lie between notch_width/2 and span/2")

    def refined(self, factor: float = 2.0, everywhere: bool = False) -> "NotchedBeam":
        """The same beam with the process-zone elements (or all elements) divided by ``factor``."""
        from dataclasses import replace

        return replace(self, h_fine=self.h_fine / factor, h_coarse=self.h_coarse / factor if everywhere else self.h_coarse)

    def _grid(self):
        """Keypoints and element-size functions of the grid lines in x and in y."""
        h_f, h_c, w = self.h_fine, self.h_coarse, self.fine_width
        h_plate = self.plate_width / 4  # the rigid support's edges concentrate the reaction
        x_size = lambda x: np.minimum.reduce(  # noqa: E731
            [np.full_like(x, h_c), h_f + 0.3 * np.maximum(x - w, 0.0), h_plate + 0.3 * np.abs(x - self.span / 2)]
        )
        p, end = self.plate_width / 2, self.length / 2
        keys = {0.0, self.notch_width / 2, p, w, self.span / 2 - p, self.span / 2 + p}
        x_keys = sorted({k for k in keys if k < end - 1e-9 * end} | {end})  # a support at the end: no line beyond it
        y_size = lambda y: np.minimum(h_c, h_f + 0.15 * np.maximum(self.notch_depth - h_f * 4 - y, 0.0))  # noqa: E731
        return x_keys, x_size, [0.0, self.notch_depth, self.depth], y_size

    def mesh(self) -> QuadMesh:
        x_keys, x_size, y_keys, y_size = self._grid()
        xs = graded_lines(x_keys, x_size)
        ys = graded_lines(y_keys, y_size)
        in_notch = lambda s, t: (s < self.notch_width / 2) & (t < self.notch_depth)  # noqa: E731
        return structured_quad8(xs, ys, keep=lambda s, t: ~in_notch(s, t))

    def mesh_size(self) -> tuple[int, int, int]:
        """(elements, nodes, vertices) of :meth:`mesh`, counted from the geometry without building it
        (a configuration checks the size of the problem before any run)."""
        x_keys, x_size, y_keys, y_size = self._grid()
        in_notch = [k for k in x_keys if k <= self.notch_width / 2]  # the keypoints up to the notch's side
        notch = (graded_count(in_notch, x_size), graded_count([0.0, self.notch_depth], y_size))
        return quad8_grid_size(graded_count(x_keys, x_size), graded_count(y_keys, y_size), notch)

    def build_problem(self, params, regularization: str = "gradient", mesh: QuadMesh | None = None) -> DamageProblem:
        mesh = mesh or self.mesh()
        disc = plane_stress_discretization(mesh.nodes, mesh.cells, mesh.n_vertices, self.thickness)
        return DamageProblem(disc, params, regularization=regularization, symmetry_planes=[(0, 0.0)],
                             **self._conditions(mesh))

    def _conditions(self, mesh: QuadMesh, crack_free: bool = False, rigid_plates: bool = True) -> dict:
        """Supports, load pattern and functionals of the half beam (keyword arguments of the problems).

        ``crack_free``: no symmetry condition on the ligament (a discrete crack lies there);
        ``rigid_plates``: the loading plate moves as one and the support holds its nodes, else an
        even pressure loads the beam and the support is a point.
        """
        x, y = mesh.nodes[:, 0], mesh.nodes[:, 1]
        ligament = np.flatnonzero((np.abs(x) < 1e-9) & (y >= self.notch_depth - 1e-9))
        support = np.flatnonzero((np.abs(y) < 1e-9) & (np.abs(x - self.span / 2) <= self.plate_width / 2 + 1e-9))
        plate = np.flatnonzero((np.abs(y - self.depth) < 1e-9) & (x <= self.plate_width / 2 + 1e-9))
        mouth = mesh.closest_node((self.notch_width / 2, 0.0))
        master = int(plate[np.argmin(x[plate])])
        symmetry = [] if crack_free else [2 * ligament]
        if rigid_plates:
            tied = [2 * plate + 1]
            load = {2 * master + 1: -0.5}  # the half model carries half the force: lambda = total force [N]
            deflection = {2 * master + 1: -1.0}
        else:
            # an even pressure under the plate and a point support: once a crack has opened, rigid
            # plates would clamp the halves' rotation and carry load by frame action
            tied = []
            support = np.array([mesh.closest_node((self.span / 2, 0.0))])
            load = {2 * n + 1: -0.5 / plate.size for n in plate}
            deflection = {2 * n + 1: -1.0 / plate.size for n in plate}
        return dict(
            fixed_dofs=np.concatenate(symmetry + [2 * support + 1]),
            tied=tied,
            load=load,
            functionals={"cmod": {2 * mouth: 2.0}, "deflection": deflection},
            symmetry_factor=2.0,
        )

    def build_cohesive_problem(self, params, penalty_factor: float = 1000.0):
        """Elastic half beam with a Hordijk cohesive crack along the ligament (SPEC 5, discrete crack).

        ``params`` is a :class:`~fracid.model.cohesive.CohesiveParameters`; the faces are tied by a
        penalty ``penalty_factor * E / h_fine`` [MPa/mm] until the traction reaches ft.
        """
        from fracid.model.cohesive_problem import CohesiveCrackProblem, ligament_edges

        mesh = self.mesh()
        disc = plane_stress_discretization(mesh.nodes, mesh.cells, mesh.n_vertices, self.thickness)
        edges = ligament_edges(mesh.nodes, mesh.cells, disc.u_dofs, self.notch_depth)
        return CohesiveCrackProblem(disc, params, edges, self.thickness, penalty_factor * params.E / self.h_fine,
                                    **self._conditions(mesh, crack_free=True, rigid_plates=False))

    def build_crack_band_problem(self, params):
        """Half beam with a rotating crack band (Hordijk, :class:`~fracid.model.cohesive.CohesiveParameters`)
        in the element column on the symmetry line above the notch (SPEC 5, smeared crack).

        The crack is confined to that column, as the cohesive crack is to the ligament: in a half model
        a band anywhere else would be mirrored into two cracks. The column is half of a band centred on
        the symmetry line, so its band width is twice its width.
        """
        from fracid.model.crack_band_problem import CrackBandProblem, element_extent

        mesh = self.mesh()
        disc = plane_stress_discretization(mesh.nodes, mesh.cells, mesh.n_vertices, self.thickness)
        corners = mesh.nodes[mesh.cells[:, :4]]
        on_ligament = (corners[..., 0].min(axis=1) < 1e-9) & (corners[..., 1].min(axis=1) >= self.notch_depth - 1e-9)
        return CrackBandProblem(disc, params, 2.0 * element_extent(mesh.nodes, mesh.cells, (1.0, 0.0)),
                                crackable=np.repeat(on_ligament[:, None], disc.weights.shape[1], axis=1).astype(float),
                                **self._conditions(mesh, rigid_plates=False))

    def output_mesh(self):
        """Nodes, cells and VTK cell type of the (half) mesh, for :func:`fracid.report.write_result_vtk`."""
        mesh = self.mesh()
        return mesh.nodes, mesh.cells, "quad8"

    def observers(self, params, damage_threshold: float = 0.0) -> dict:
        """``fpz_width``: width across the crack path (horizontal) of the zone where omega > threshold,
        over the ligament [mm]."""
        ligament = (self.notch_depth, self.depth)
        return {"fpz_width": fpz_width_observer(params, damage_threshold, axis=0, mirror=True, along_range=ligament)}

    def default_steps(self, target: float):
        """Adaptive steps capped at 1/60 of the target, so the softening branch takes tens of steps."""
        from fracid.model.path_following import StepOptions

        return StepOptions(maximum=target / 60)

    def default_target(self, params) -> float:
        return 0.3  # CMOD [mm]
