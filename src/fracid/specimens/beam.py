"""Notched three-point bending beam (docs/theory.md, section 2.2), modelled as a symmetric half."""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from fracid.settings.field_error import FieldError
from fracid.specimens.checks import require_positive, resolve_defaults
from fracid.specimens.protocol import BandRoom, FineSizeDefaults
from fracid.specimens.description import CrackPath, Description, Load, Measure, Support, ZoneWidth
from fracid.specimens.meshing import QuadMesh, graded_count, graded_lines, quad8_grid_size, structured_quad8

COARSE_PER_DEPTH = 0.08  # default h_coarse / D: 4 mm at the default D = 50 mm
FINE_PER_DEPTH = 0.2  # default fine_width / D: 10 mm at D = 50 mm


@dataclass(frozen=True)
class NotchedBeam(FineSizeDefaults):
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
    h_coarse : float or None
        Largest element size away from it [mm]; None: ``COARSE_PER_DEPTH`` D = D / 12.5, at least
        ``h_fine`` (4 mm for the default D = 50 mm).
    fine_width : float or None
        Half-width of the refined band around the crack path [mm]; None: ``FINE_PER_DEPTH`` D = D / 5,
        at least ``notch_width / 2 + 2 h_fine`` and at most ``(span - plate_width) / 4`` (10 mm for
        the default beam).

    The mesh defaults scale with the depth, so a deeper or longer beam does not get the elements of
    a 50 mm one: the element size grows from ``h_fine`` away from the band and the notch tip up to
    ``h_coarse``. They are resolved when the beam is built (the fields then hold the numbers, and a
    beam built with None has the run key of one built with these numbers);
    ``dataclasses.replace(beam, depth=...)`` keeps them, ``NotchedBeam(depth=...)`` derives them anew.

    Controls: ``cmod`` (default; passes snap-back) and ``deflection`` (plain displacement control
    of the loading plate). Observable of the damage models: ``fpz_width`` [mm].
    """

    depth: float = 50.0
    thickness: float = 50.0
    length: float = 175.0
    span: float = 125.0
    notch_depth: float = 25.0
    notch_width: float = 2.0
    plate_width: float = 5.0
    h_fine: float = 1.0
    h_coarse: float | None = None
    fine_width: float | None = None

    default_control = "cmod"
    controls: ClassVar[tuple] = ("cmod", "deflection")
    #: the control that grows through a snap-back (an opening across the crack)
    snap_back_control: ClassVar[str] = "cmod"
    observables: ClassVar[tuple] = ("fpz_width",)
    size_field: ClassVar[str] = "depth"

    def __post_init__(self):
        require_positive(self, ("depth", "thickness", "length", "span", "notch_depth", "notch_width", "plate_width",
                                "h_fine"), " [mm]")
        resolve_defaults(self, {"h_coarse": self._default_coarse, "fine_width": self._default_fine_width})
        require_positive(self, ("h_coarse", "fine_width"), " [mm]")
        if not self.span <= self.length:
            raise FieldError(("span", "length"), self.span,
                             f"span = {self.span} must not exceed length = {self.length} (S = L: supports at the ends)")
        if not self.notch_depth < self.depth:
            raise FieldError(("notch_depth", "depth"), self.notch_depth,
                             f"notch_depth = {self.notch_depth} must be smaller than depth = {self.depth}")
        if not self.notch_width / 2 < self.fine_width < self.span / 2 - self.plate_width / 2:
            raise FieldError(("fine_width", "notch_width", "span"), self.fine_width,
                             f"fine_width = {self.fine_width} must lie between notch_width/2 and span/2")

    def _default_coarse(self) -> float:
        """h_coarse when not given: D / 12.5, at least h_fine [mm]."""
        return max(self.h_fine, COARSE_PER_DEPTH * self.depth)

    def _default_fine_width(self) -> float:
        """fine_width when not given: D / 5, within [notch_width / 2 + 2 h_fine, (span - plate_width) / 4] [mm]."""
        lowest = self.notch_width / 2 + 2.0 * self.h_fine
        return min(max(FINE_PER_DEPTH * self.depth, lowest), (self.span - self.plate_width) / 4)

    @property
    def characteristic_size(self) -> float:
        """D, the depth [mm] (the size of a size-effect series)."""
        return self.depth

    def band_room(self) -> BandRoom:
        """D: the crack runs up the depth, whose faces (the notch's included) cut the band about its tip."""
        return BandRoom(self.depth, f"its depth = {self.depth:g} mm")

    @property
    def nominal_section(self) -> float:
        """A_N with sigma_N = F / A_N = 3 F S / (2 b D^2), the elastic bending stress of the unnotched beam [mm^2]."""
        return 2.0 * self.thickness * self.depth**2 / (3.0 * self.span)

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

    def describe(self, mesh: QuadMesh | None = None) -> Description:
        """The half beam: symmetry u_x = 0 on the ligament, the support plate at x = S/2 (a roller at
        its centre for the models of an open crack), the loading plate at mid-span carrying half the
        force (rigid; an even pressure for the models of an open crack, since rigid plates would clamp
        the rotation of the cracked halves and carry load by frame action), the crack path along the
        ligament and the FPZ width measured across it."""
        mesh = mesh or self.mesh()
        x, y = mesh.nodes[:, 0], mesh.nodes[:, 1]
        plate = np.flatnonzero((np.abs(y - self.depth) < 1e-9) & (x <= self.plate_width / 2 + 1e-9))
        sets = {
            "ligament": np.flatnonzero((np.abs(x) < 1e-9) & (y >= self.notch_depth - 1e-9)),
            "support": np.flatnonzero((np.abs(y) < 1e-9) & (np.abs(x - self.span / 2) <= self.plate_width / 2 + 1e-9)),
            "support_point": np.array([mesh.closest_node((self.span / 2, 0.0))]),
            "loading_plate": plate[np.argsort(x[plate], kind="stable")],
            "mouth": np.array([mesh.closest_node((self.notch_width / 2, 0.0))]),
        }
        return Description(
            nodes=mesh.nodes, cells=mesh.cells, n_vertices=mesh.n_vertices, section=self.thickness, node_sets=sets,
            symmetry=(("ligament", 0),),
            supports=(Support("support", 1, point="support_point"),),
            # the half model carries half the force: lambda = total force [N]
            loads=(Load("loading_plate", 1, -0.5, rigid=True, rigid_under_open_crack=False),),
            functionals={"cmod": (Measure("mouth", 0, 2.0),), "deflection": (Measure("loading_plate", 1, -1.0),)},
            symmetry_factor=2.0, symmetry_planes=((0, 0.0),),
            crack=CrackPath("ligament", normal=0, mirrored=True, element_size=self.h_fine),
            zone=ZoneWidth("fpz_width", axis=0, mirror=True, along_range=(self.notch_depth, self.depth)),
        )

    def default_target(self, scales) -> float:
        """CMOD 0.3 mm, whatever the model (``scales``: its characteristic strain and opening)."""
        return 0.3
