"""Bar with a weak zone (docs/theory.md, section 2.1), the 1D specimen of the gradient damage model."""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from fracid.settings.field_error import FieldError
from fracid.specimens.checks import require_positive
from fracid.specimens.description import Description, Load, Measure, Support, ZoneWidth
from fracid.specimens.protocol import (
    BAR_BYTES_PER_ELEMENT,
    BandRoom,
    MAX_BAR_ELEMENTS,
    Resolution,
    SizeEstimate,
    SpecimenDefaults,
    bar_resolution,
)

_WEAKENINGS = ("modulus", "area")
_PROFILES = ("step", "hat")


@dataclass(frozen=True)
class BarWithWeakZone(SpecimenDefaults):
    """A bar of length L fixed at x = 0 and pulled at x = L, weakened in a centre zone of width W.

    Parameters
    ----------
    length : float
        L [mm].
    area : float
        Cross-section outside the weak zone [mm^2].
    weak_zone_width : float
        W [mm], centred at L / 2.
    weak_zone_factor : float
        Young's modulus (or cross-section) in the weak zone relative to the rest, in (0, 1].
    weakening : {"modulus", "area"}
        What the weak zone reduces. The closed-form solution of Peerlings et al. (1996) assumes
        "modulus"; "area" also weights the diffusion equation by the area.
    profile : {"step", "hat"}
        "step": the factor holds over the whole zone. "hat": it varies linearly from 1 at the zone
        edges to ``weak_zone_factor`` at the centre, so a local model localises in the central
        elements, as a mesh-dependence study needs.
    n_elements : int
        Number of elements (uniform mesh; the zone edges fall on element boundaries).

    Controls: ``end_displacement`` (plain displacement control) and ``weak_zone_elongation``
    (elongation over the weak zone, for snap-back). Observable of the damage models:
    ``damaged_zone_width`` [mm], the length where the damage exceeds a threshold.
    """

    length: float = 100.0
    area: float = 1.0
    weak_zone_width: float = 10.0
    weak_zone_factor: float = 0.9
    weakening: str = "modulus"
    profile: str = "step"
    n_elements: int = 200

    default_control = "end_displacement"
    controls: ClassVar[tuple] = ("end_displacement", "weak_zone_elongation")
    #: the control that grows through a snap-back (an opening across the crack)
    snap_back_control: ClassVar[str] = "weak_zone_elongation"
    observables: ClassVar[tuple] = ("damaged_zone_width",)
    size_field: ClassVar[str] = "length"
    steps_per_target: ClassVar[None] = None  # the path follower's default steps

    def __post_init__(self):
        require_positive(self, ("length", "area", "weak_zone_width"), " [mm or mm^2]")
        if self.weak_zone_width >= self.length:
            raise FieldError(("weak_zone_width", "length"), self.weak_zone_width,
                             f"weak_zone_width = {self.weak_zone_width} must be smaller than length = {self.length}")
        if not 0.0 < self.weak_zone_factor <= 1.0:
            raise FieldError("weak_zone_factor", self.weak_zone_factor,
                             f"weak_zone_factor = {self.weak_zone_factor!r}; it must be in (0, 1]")
        if self.weakening not in _WEAKENINGS:
            raise FieldError("weakening", self.weakening,
                             f"weakening = {self.weakening!r}; choose one of {_WEAKENINGS}")
        if self.profile not in _PROFILES:
            raise FieldError("profile", self.profile, f"profile = {self.profile!r}; choose one of {_PROFILES}")
        if int(self.n_elements) != self.n_elements or self.n_elements < 3:
            raise FieldError("n_elements", self.n_elements,
                             f"n_elements = {self.n_elements!r}; it must be an integer >= 3")

    @property
    def characteristic_size(self) -> float:
        """L, the length [mm]."""
        return self.length

    @property
    def nominal_section(self) -> float:
        """The cross-section outside the weak zone [mm^2] (sigma_N = F / area)."""
        return self.area

    def vertices(self) -> np.ndarray:
        """Element end coordinates [mm]: as uniform as possible, with nodes at the weak-zone edges."""
        n, L, W = int(self.n_elements), self.length, self.weak_zone_width
        n_weak = max(1, round(n * W / L))
        n_weak += (n - n_weak) % 2
        n_out = (n - n_weak) // 2
        if n_out < 1:
            raise FieldError("n_elements", n, f"n_elements = {n} is too few to mesh the weak zone and both outer parts")
        a, b = 0.5 * (L - W), 0.5 * (L + W)
        return np.concatenate([np.linspace(0, a, n_out + 1), np.linspace(a, b, n_weak + 1)[1:], np.linspace(b, L, n_out + 1)[1:]])

    def weakness(self, x) -> np.ndarray:
        """Factor (modulus or area) at positions x [mm]."""
        distance = np.abs(np.asarray(x, dtype=float) - 0.5 * self.length) / (0.5 * self.weak_zone_width)
        if self.profile == "step":
            return np.where(distance < 1.0, self.weak_zone_factor, 1.0)
        return 1.0 - (1.0 - self.weak_zone_factor) * np.clip(1.0 - distance, 0.0, 1.0)

    def describe(self) -> Description:
        """The discretised bar: u(0) = 0, a unit force at x = L, the weak zone as a reduced modulus (or
        cross-section), the damaged-zone length measured along the whole bar."""
        x = self.vertices()
        n = x.size - 1
        nodes = np.empty(2 * n + 1)
        nodes[0::2], nodes[1::2] = x, 0.5 * (x[:-1] + x[1:])  # vertex i is node 2 i
        by_area = self.weakening == "area"
        a, b = 0.5 * (self.length - self.weak_zone_width), 0.5 * (self.length + self.weak_zone_width)
        sets = {"start": np.array([0]), "end": np.array([2 * n]),
                "weak_zone_start": np.array([2 * int(np.argmin(np.abs(x - a)))]),
                "weak_zone_end": np.array([2 * int(np.argmin(np.abs(x - b)))])}
        return Description(
            nodes=nodes[:, None], cells=np.stack([np.arange(n), np.arange(1, n + 1)], axis=1), node_sets=sets,
            section=self.area * (self.weakness(0.5 * (x[:-1] + x[1:])) if by_area else 1.0),
            supports=(Support("start", 0),), loads=(Load("end", 0, 1.0),),
            functionals={"end_displacement": (Measure("end", 0),),
                         "weak_zone_elongation": (Measure("weak_zone_end", 0), Measure("weak_zone_start", 0, -1.0))},
            stiffness_factor=(lambda points: np.ones(points.shape[:-1])) if by_area else (lambda points: self.weakness(points[..., 0])),
            zone=ZoneWidth("damaged_zone_width", along_range=(0.0, self.length)), cell_type="line3",
        )

    def band_room(self) -> BandRoom:
        """L: the band forms across the bar and must fit between its ends."""
        return BandRoom(self.length, f"its length = {self.length:g} mm")

    def default_target(self, scales) -> float:
        """A control value well past the peak: 50 times the bar's elongation at the model's
        characteristic strain ``scales["strain"]`` (the strain at damage onset) [mm]."""
        return 50.0 * scales["strain"] * self.length

    def resolution(self, internal_length: float | None = None) -> Resolution:
        """The element size length / n_elements [mm]; the advice: the n_elements that resolves ``internal_length``."""
        return bar_resolution(self.length, int(self.n_elements), internal_length)

    def size_estimate(self) -> SizeEstimate:
        """``n_elements`` bar elements, limited to :data:`~fracid.specimens.protocol.MAX_BAR_ELEMENTS`."""
        n = int(self.n_elements)
        return SizeEstimate("n_elements", n, f"{n:,} bar elements", n, "element", BAR_BYTES_PER_ELEMENT,
                            MAX_BAR_ELEMENTS, "a few elements per internal length l = sqrt(2 c) are enough")
