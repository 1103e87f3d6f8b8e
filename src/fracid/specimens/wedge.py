"""The wedge-splitting test (Linsbauer & Tschegg 1986; Brühwiler & Wittmann 1990), the usual test for the
fracture energy: a cube or prism with a groove and a starter notch, split by a wedge pressed into the groove.

Built through the mesh mechanism of :mod:`fracid.specimens.mesh`: the geometry gives a linear mesh whose
groups name the ligament, the support and the loading piece, and :class:`MeshSpecimen` describes it.
"""

from __future__ import annotations

from typing import ClassVar

import math
from dataclasses import dataclass

import numpy as np

from fracid.settings.field_error import FieldError
from fracid.specimens.checks import require_positive, resolve_defaults
from fracid.specimens.protocol import BandRoom, FineSizeDefaults
from fracid.specimens.description import Description
from fracid.specimens.mesh import MeshSpecimen
from fracid.specimens.mesh_reading import plane_mesh
from fracid.specimens.meshing import graded_lines, structured_quad8

COARSE_PER_SIZE = 0.125  # default h_coarse / min(width, height): 25 mm for the default 200 mm cube


@dataclass(frozen=True)
class WedgeSplitting(FineSizeDefaults):
    """Half of a wedge-splitting specimen (x >= 0, the notch plane x = 0 a symmetry line), plane stress.

    The wedge of full angle ``wedge_angle`` pushes the loading pieces on the groove walls at height
    ``load_height``: each half receives the horizontal splitting force F_sp (the load factor, [N]) and
    the vertical force F_sp tan(alpha/2) downwards (friction neglected); the specimen rests on a line
    support under the notch. F_sp = F_v / (2 tan(alpha/2)) from the machine's vertical force F_v
    (:meth:`splitting_force`).

    The whole specimen, front view (x = 0 is the notch plane; depths count down from the top face
    y = H, heights up from the bottom face y = 0; the notch depth includes the groove's)::

                  |<- groove_width ->|
        +---------+                  +---------+  y = H: the top face
        |   F_sp <[]    wedge       []> F_sp   |  y = load_height: centre of the loading pieces []
        |         |                  |         |
        |         +------+    +------+         |  y = H - groove_depth: the groove's floor
        |                |    |<- notch_width  |
        |                |    |                |
        |                +----+                |  y = H - notch_depth: the notch tip
        |                  ::                  |
        |                  :: ligament         |  ligament = H - notch_depth
        |                  ::                  |
        +------------------/\\------------------+  y = 0: the bottom face
                     support (x = 0)
        |<------------- width B -------------->|

    ``[]`` are the loading pieces on the groove walls x = +-groove_width / 2, each ``load_piece`` high
    and centred at ``y = load_height``; they must lie on the wall, between ``H - groove_depth`` and H.

    Parameters
    ----------
    width, height, thickness : float
        Whole specimen's width B (across the notch, x), height H (y) and thickness t (out of plane) [mm].
    groove_width, groove_depth : float
        The groove at the top that holds the wedge and the loading pieces: its full width (centred on
        the notch) and its depth below the top face [mm].
    notch_depth : float
        Depth of the notch tip below the top face, the groove included (groove_depth + the starter
        notch below the groove's floor) [mm]: the ligament is H - notch_depth.
    notch_width : float
        Full width of the starter notch [mm], less than ``groove_width``.
    load_height : float
        Height of the splitting force's line above the bottom face [mm] (on the groove walls).
    load_piece : float
        Height of the loading piece on the groove wall [mm]: the forces are spread over it (the piece
        turns with the half, as on its roller; a rigid tie would keep it upright).
    wedge_angle : float
        Full angle of the wedge [degrees].
    h_fine : float
        Element size along the ligament [mm]; the size grows away from it (slope 0.3) up to ``h_coarse``.
    h_coarse : float or None
        Largest element size [mm]; None: min(B, H) / 8, at least ``h_fine`` (25 mm for the default
        200 mm cube). Resolved when the specimen is built (the field then holds the number, and the
        run key is that of a specimen given it); ``dataclasses.replace`` keeps it.

    Controls: ``cmod`` (the opening at the load line, twice the mean u_x of the loading piece; the default) [mm].
    Observable: ``fpz_width`` across the ligament (damage models).
    """

    width: float = 200.0
    height: float = 200.0
    thickness: float = 100.0
    groove_width: float = 30.0
    groove_depth: float = 30.0
    notch_depth: float = 80.0
    notch_width: float = 4.0
    load_height: float = 185.0
    load_piece: float = 10.0
    wedge_angle: float = 15.0
    h_fine: float = 5.0
    h_coarse: float | None = None

    default_control = "cmod"
    controls = ("cmod",)
    #: the control that grows through a snap-back (an opening across the crack)
    snap_back_control: ClassVar[str] = "cmod"
    observables = ("fpz_width",)

    def __post_init__(self):
        require_positive(self, ("width", "height", "thickness", "groove_width", "groove_depth", "notch_depth",
                                "notch_width", "load_height", "load_piece", "wedge_angle", "h_fine"), " [mm]")
        resolve_defaults(self, {"h_coarse": lambda: max(self.h_fine, COARSE_PER_SIZE * min(self.width, self.height))})
        require_positive(self, ("h_coarse",), " [mm]")
        if not self.notch_width < self.groove_width < self.width:
            raise FieldError(("notch_width", "groove_width", "width"), self.notch_width,
                             f"need notch_width = {self.notch_width} < groove_width = {self.groove_width} < "
                             f"width = {self.width}")
        if not self.groove_depth < self.notch_depth < self.height:
            raise FieldError(("groove_depth", "notch_depth", "height"), self.groove_depth,
                             f"need groove_depth = {self.groove_depth} < notch_depth = {self.notch_depth} < "
                             f"height = {self.height}")
        piece = (self.load_height - self.load_piece / 2, self.load_height + self.load_piece / 2)
        if not (self.height - self.groove_depth <= piece[0] and piece[1] <= self.height):
            raise FieldError(("load_height", "load_piece"), self.load_height,
                             f"load_height = {self.load_height} with load_piece = {self.load_piece}: the loading "
                             f"piece must lie on the groove wall, between y = {self.height - self.groove_depth:g} "
                             f"and {self.height:g}")
        if not 0.0 < self.wedge_angle < 180.0:
            raise FieldError("wedge_angle", self.wedge_angle,
                             f"wedge_angle = {self.wedge_angle} degrees; it must be in (0, 180)")

    @property
    def ligament(self) -> float:
        """Ligament length H - notch_depth [mm] (the crack area is ligament x thickness)."""
        return self.height - self.notch_depth

    def band_room(self) -> BandRoom:
        """H: the crack runs down the height, whose faces (the groove's and the notch's included) cut the band."""
        return BandRoom(self.height, f"its height = {self.height:g} mm")

    @property
    def characteristic_size(self) -> float:
        return self.height

    def splitting_force(self, vertical_force):
        """F_sp = F_v / (2 tan(alpha / 2)) [N] from the machine's vertical force F_v [N]."""
        return np.asarray(vertical_force) / (2.0 * math.tan(math.radians(self.wedge_angle) / 2.0))

    def mesh_specimen(self) -> MeshSpecimen:
        """The test as a :class:`MeshSpecimen` of the groups of :meth:`describe`'s mesh."""
        down = -math.tan(math.radians(self.wedge_angle) / 2.0)
        return MeshSpecimen(
            "wedge-splitting specimen", thickness=self.thickness, supports=(("support", "y"),),
            # spread over the piece, not tied: a tie of the vertical piece's u_x would keep it from turning
            # with the half, a spurious moment that made the force rise again after CMOD 0.7 mm
            loads=(("loading_piece", "x", False, 1.0), ("loading_piece", "y", False, down)),
            controls=(("cmod", (("loading_piece", "x", 2.0),)),), symmetry=(("ligament", "x"),),
            symmetry_factor=2.0, crack=("ligament", "x", self.h_fine))

    def _quads(self):
        """The half specimen's Q8 grid, graded from h_fine on the ligament to h_coarse."""
        half, H = self.width / 2, self.height
        groove, notch = self.groove_width / 2, self.notch_width / 2
        tip = H - self.notch_depth
        piece = (self.load_height - self.load_piece / 2, self.load_height + self.load_piece / 2)
        h_f, h_c = self.h_fine, self.h_coarse
        xs = graded_lines(sorted({0.0, notch, groove, half}), lambda x: np.minimum(h_c, h_f + 0.3 * x))
        y_keys = sorted({0.0, tip, H - self.groove_depth, *piece, H})
        ys = graded_lines(y_keys, lambda y: np.minimum(h_c, h_f + 0.3 * np.maximum(y - tip, 0.0)))
        cut = lambda s, t: ((s < groove) & (t > H - self.groove_depth)) | ((s < notch) & (t > tip))  # noqa: E731
        return structured_quad8(xs, ys, keep=lambda s, t: ~cut(s, t))

    def mesh_size(self) -> tuple[int, int, int]:
        """(elements, nodes, vertices) of the mesh (a configuration checks the size before any run)."""
        quads = self._quads()
        return len(quads.cells), len(quads.nodes), quads.n_vertices

    def describe(self) -> Description:
        H, groove = self.height, self.groove_width / 2
        tip = H - self.notch_depth
        piece = (self.load_height - self.load_piece / 2, self.load_height + self.load_piece / 2)
        quads = self._quads()
        corners, cells = quads.nodes[:quads.n_vertices], quads.cells[:, :4]
        x, y = corners[:, 0], corners[:, 1]
        tol = 1e-9 * H
        on = {"ligament": (np.abs(x) < tol) & (y <= tip + tol),
              "loading_piece": (np.abs(x - groove) < tol) & (y >= piece[0] - tol) & (y <= piece[1] + tol)}
        sides = np.stack([cells, np.roll(cells, -1, axis=1)], axis=-1).reshape(-1, 2)
        blocks, groups = [("quad", cells)], {}
        for name, mask in on.items():
            lines = sides[mask[sides].all(axis=1)]
            blocks.append(("line", lines))
            groups[name] = {"line": np.arange(len(lines)) + sum(len(b) for k, b in blocks[1:-1])}
        support = np.flatnonzero((np.abs(x) < tol) & (np.abs(y) < tol))
        blocks.append(("vertex", support[:, None]))
        groups["support"] = {"vertex": np.array([0])}
        points = np.column_stack([corners, np.zeros(len(corners))])
        return self.mesh_specimen().describe_mesh(plane_mesh(points, blocks, groups, "wedge-splitting specimen"))

    def default_target(self, scales) -> float:
        """An opening of 2 wc at the load line when the model has a crack opening scale (wc), else 1 mm."""
        return 2.0 * scales["opening"] if "opening" in scales else 1.0
