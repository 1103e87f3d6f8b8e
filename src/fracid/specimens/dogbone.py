"""Dog-bone tension specimen (van Vliet & van Mier size-effect series), modelled as a symmetric quarter."""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import ClassVar

import numpy as np

from fracid.settings.field_error import FieldError
from fracid.specimens.checks import require_positive
from fracid.specimens.protocol import BandRoom, FineSizeDefaults
from fracid.specimens.description import CrackPath, Description, Load, Measure, Support, ZoneWidth
from fracid.specimens.meshing import QuadMesh, graded_count, graded_lines, quad8_grid_size, structured_quad8


@dataclass(frozen=True)
class DogBone(FineSizeDefaults):
    """Dog-bone specimen of size D: width D, height 1.5 D, circular side notches of radius 0.725 D
    reducing the width to 0.6 D at mid-height, thickness 100 mm; ends glued to loading platens.

    Glued platens (default, rotations fixed): the quarter x >= 0, y >= 0 is meshed (symmetry about
    both axes) and the top edge moves as a rigid platen: u_x = 0, one common u_y.
    Hinged platens: the upper half y >= 0 is meshed over the full width with a stiff elastic platen
    block glued on top, loaded at a hinge at its top centre (u_x = 0 there), so the platen can
    rotate if the specimen fails asymmetrically (``platen_tilt`` records its rotation as the
    difference of the vertical displacements of the specimen's top corners).
    Curves are for the full specimen: force [N], elongation over the gauge length [mm].

    Parameters
    ----------
    size : float
        D [mm].
    thickness : float
        [mm].
    gauge_length : float or None
        Length over which the elongation is measured, centred at mid-height [mm]; 0.5 D if None.
    h_fine : float
        Element size at the notched section, in a band of half-height ``fine_height`` [mm].
    fine_height : float or None
        Half-height of the refined band [mm]; 0.05 D + 5 h_fine if None.
    h_coarse : float or None
        Largest element height away from the band [mm]; 0.1 D if None, at least ``h_fine``.
    notch_radius, notch_width : float
        Notch radius and the width at mid-height, relative to D (0.725 and 0.6).
    platens : {"glued", "hinged"}
        Boundary condition of the loading platens.
    platen_height, platen_stiffness : float
        Height of the hinged platen block relative to D (0.1) and its Young's modulus relative to
        the specimen's (100; it does not damage).
    hinge_offset : float
        Eccentricity of the hinge from the specimen's axis [mm] (hinged platens only; the nearest
        node of the platen's top edge is used).

    The mesh defaults (None) scale with D: coarse elements of 10 mm and a band of half-height 15 mm
    for the default D = 100 mm and h_fine = 2 mm. They stay None in the fields (the run key of a
    specimen built with None is not that of one given the numbers) and follow D through
    ``dataclasses.replace``.

    Controls: ``elongation`` (default; passes snap-back) and ``platen_displacement`` (plain
    displacement control). Observer: ``fpz_width`` [mm], across the mid-height section.
    """

    size: float = 100.0
    thickness: float = 100.0
    gauge_length: float | None = None
    h_fine: float = 2.0
    fine_height: float | None = None
    h_coarse: float | None = None
    notch_radius: float = 0.725
    notch_width: float = 0.6
    platens: str = "glued"
    platen_height: float = 0.1
    platen_stiffness: float = 100.0
    hinge_offset: float = 0.0

    default_control = "elongation"
    controls: ClassVar[tuple] = ("elongation", "platen_displacement")
    #: the control that grows through a snap-back (an opening across the crack)
    snap_back_control: ClassVar[str] = "elongation"
    observables: ClassVar[tuple] = ("fpz_width",)
    size_field: ClassVar[str] = "size"

    def __post_init__(self):
        optional = ("gauge_length", "fine_height", "h_coarse")  # None: derived from the size
        require_positive(self, [n for n in ("size", "thickness", "gauge_length", "h_fine", "fine_height", "h_coarse",
                                            "notch_radius", "notch_width")
                                if not (n in optional and getattr(self, n) is None)])
        if not self.notch_width < 1.0 or (1.0 - self.notch_width) / 2 > self.notch_radius:
            raise FieldError(("notch_width", "notch_radius"), self.notch_width,
                             f"notch_width = {self.notch_width} and notch_radius = {self.notch_radius}: "
                             "the notch must narrow the width (notch_width < 1) and fit its radius")
        if self.platens not in ("glued", "hinged"):
            raise FieldError("platens", self.platens, f"DogBone.platens = {self.platens!r}; choose 'glued' or 'hinged'")
        for name in ("platen_height", "platen_stiffness"):
            if not getattr(self, name) > 0:
                raise FieldError(name, getattr(self, name),
                                 f"DogBone.{name} = {getattr(self, name)!r}; it must be positive")
        if not abs(self.hinge_offset) < 0.5 * self.size or (self.hinge_offset and self.platens != "hinged"):
            raise FieldError("hinge_offset", self.hinge_offset,
                             f"DogBone.hinge_offset = {self.hinge_offset!r} mm: it needs hinged platens and |offset| < D/2")
        if self._gauge / 2 >= 0.75 * self.size:
            raise FieldError("gauge_length", self._gauge,
                             f"gauge_length = {self._gauge} mm must be shorter than the height 1.5 D")

    @property
    def _gauge(self) -> float:
        return self.gauge_length if self.gauge_length is not None else 0.5 * self.size

    def refined(self, factor: float = 2.0, everywhere: bool = False) -> "DogBone":
        """The same specimen with the process-zone elements (or all elements) divided by ``factor``."""
        coarse = self._h_coarse
        return replace(self, h_fine=self.h_fine / factor, fine_height=self._fine_height,
                       h_coarse=coarse / factor if everywhere else coarse)

    @property
    def _h_coarse(self) -> float:
        """h_coarse, or 0.1 D (at least h_fine) if None [mm]."""
        return self.h_coarse if self.h_coarse is not None else max(self.h_fine, 0.1 * self.size)

    @property
    def _fine_height(self) -> float:
        return self.fine_height if self.fine_height is not None else 0.05 * self.size + 5 * self.h_fine

    def half_width(self, y) -> np.ndarray:
        """Half-width of the specimen at height y above mid-height [mm]."""
        D, R = self.size, self.notch_radius * self.size
        centre = 0.5 * self.notch_width * D + R
        y = np.abs(np.asarray(y, dtype=float))
        arc = centre - np.sqrt(np.maximum(R * R - y * y, 0.0))
        return np.where(arc < 0.5 * D, np.minimum(arc, 0.5 * D), 0.5 * D)

    def _grid(self):
        """Keypoints and element-size function of the lines in height, the number of elements across
        the half-width, and the number of element rows of a hinged platen (0 if glued)."""
        D, h = self.size, self.h_fine
        fine, coarse = self._fine_height, self._h_coarse
        R = self.notch_radius * D
        end_of_arc = math.sqrt(max(R * R - (0.5 * D - (0.5 * self.notch_width * D + R)) ** 2, 0.0))
        keys = sorted({0.0, self._gauge / 2, min(end_of_arc, 0.75 * D), 0.75 * D})
        size = lambda t: np.minimum(coarse, h + 0.25 * np.maximum(t - fine, 0.0))  # noqa: E731
        n_s = max(2, math.ceil(0.5 * self.notch_width * D / h))
        n_platen = max(2, math.ceil(self.platen_height * D / coarse)) if self.platens == "hinged" else 0
        return keys, size, n_s, n_platen

    def mesh(self) -> QuadMesh:
        D = self.size
        keys, size, n_s, n_platen = self._grid()
        ts = graded_lines(keys, size)
        s_lines = np.linspace(0.0, 1.0, n_s + 1)
        if self.platens == "hinged":
            s_lines = np.concatenate([-s_lines[:0:-1], s_lines])
            top = 0.75 * D + self.platen_height * D
            ts = np.concatenate([ts, np.linspace(0.75 * D, top, n_platen + 1)[1:]])
        return structured_quad8(s_lines, ts, mapping=lambda s, t: (s * self.half_width(t), t))

    def mesh_size(self) -> tuple[int, int, int]:
        """(elements, nodes, vertices) of :meth:`mesh`, counted from the geometry without building it
        (a configuration checks the size of the problem before any run)."""
        keys, size, n_s, n_platen = self._grid()
        across = 2 * n_s if self.platens == "hinged" else n_s
        return quad8_grid_size(across, graded_count(keys, size) + n_platen)

    def describe(self, mesh: QuadMesh | None = None) -> Description:
        """Glued platens: the quarter x, y >= 0 with symmetry on both axes, the top edge held
        horizontally and moving as one, carrying half the force. Hinged platens: the upper half with
        a stiff elastic platen (no damage) loaded at the hinge, symmetry about y = 0. The crack path
        is the mid-height section; the FPZ width is measured across it."""
        mesh = mesh or self.mesh()
        D, x, y = self.size, mesh.nodes[:, 0], mesh.nodes[:, 1]
        g = self._gauge / 2
        half = float(self.half_width(0.0))
        sets = {"section": np.flatnonzero(np.abs(y) < 1e-9)}
        common = dict(nodes=mesh.nodes, cells=mesh.cells, n_vertices=mesh.n_vertices, section=self.thickness,
                      crack=CrackPath("section", normal=1, mirrored=True))
        if self.platens == "hinged":
            hinge = mesh.closest_node((self.hinge_offset, 0.75 * D + self.platen_height * D))
            sets.update(hinge=np.array([hinge]),
                        **{f"gauge_{side}": np.array([mesh.closest_node((sign * float(self.half_width(g)), g))])
                           for side, sign in (("right", 1.0), ("left", -1.0))},
                        **{f"corner_{side}": np.array([mesh.closest_node((sign * 0.5 * D, 0.75 * D))])
                           for side, sign in (("right", 1.0), ("left", -1.0))})
            in_platen = lambda points: points[..., 1] > 0.75 * D  # noqa: E731
            return Description(
                node_sets=sets, symmetry=(("section", 1),), supports=(Support("hinge", 0),),
                loads=(Load("hinge", 1, 1.0),),  # the upper half carries the whole force
                functionals={
                    # mean of the elongations on both sides: (2 u_R + 2 u_L) / 2
                    "elongation": (Measure("gauge_right", 1, 1.0), Measure("gauge_left", 1, 1.0)),
                    "platen_displacement": (Measure("hinge", 1, 2.0),),
                    "platen_tilt": (Measure("corner_right", 1, 1.0), Measure("corner_left", 1, -1.0)),
                },
                symmetry_factor=2.0, symmetry_planes=((1, 0.0),),
                stiffness_factor=lambda points: np.where(in_platen(points), self.platen_stiffness, 1.0),
                damageable=lambda points: np.where(in_platen(points), 0.0, 1.0),
                zone=ZoneWidth("fpz_width", axis=1, mirror=True, along_range=(-half, half)), **common)
        sets.update(axis=np.flatnonzero(np.abs(x) < 1e-9), top=np.flatnonzero(np.abs(y - 0.75 * D) < 1e-9),
                    gauge=np.array([mesh.closest_node((float(self.half_width(g)), g))]))
        return Description(
            node_sets=sets, symmetry=(("axis", 0), ("section", 1)), supports=(Support("top", 0),),
            loads=(Load("top", 1, 0.5),),  # the quarter carries half the force: lambda = total force [N]
            functionals={"elongation": (Measure("gauge", 1, 2.0),), "platen_displacement": (Measure("top", 1, 2.0),)},
            symmetry_factor=4.0, symmetry_planes=((0, 0.0), (1, 0.0)),
            zone=ZoneWidth("fpz_width", axis=1, mirror=True, along_range=(0.0, half)), **common)

    def default_target(self, scales) -> float:
        """Elongation well past the peak: 20 times the gauge length times the model's characteristic
        strain ``scales["strain"]`` (the strain at damage onset) [mm]."""
        return 20.0 * scales["strain"] * self._gauge

    @property
    def ligament_area(self) -> float:
        """Area of the notched section [mm^2], for the nominal strength F / (0.6 D t)."""
        return self.notch_width * self.size * self.thickness

    @property
    def characteristic_size(self) -> float:
        """D, the width [mm] (the size of a size-effect series)."""
        return self.size

    def band_room(self) -> BandRoom:
        """The width at mid-height, notch_width D: the crack runs across it and the notches cut the band."""
        width = self.notch_width * self.size
        return BandRoom(width, f"its width at mid-height notch_width * size = {width:g} mm")

    @property
    def nominal_section(self) -> float:
        """A_N with sigma_N = F / A_N: the notched section [mm^2]."""
        return self.ligament_area
