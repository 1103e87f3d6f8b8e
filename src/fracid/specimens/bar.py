"""Bar with a weak zone (SPEC section 2), the 1D specimen of the gradient damage model."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from fracid.model.damage import kappa_at_damage
from fracid.model.discretization import bar_discretization
from fracid.model.problem import DamageProblem
from fracid.specimens.checks import require_positive
from fracid.specimens.observables import superlevel_length

_WEAKENINGS = ("modulus", "area")
_PROFILES = ("step", "hat")


@dataclass(frozen=True)
class BarWithWeakZone:
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

    Controls (``problem.functionals``): ``end_displacement`` (plain displacement control) and
    ``weak_zone_elongation`` (elongation over the weak zone, for snap-back).
    Observer: ``damaged_zone_width`` [mm], the length where the damage exceeds a threshold.
    """

    length: float = 100.0
    area: float = 1.0
    weak_zone_width: float = 10.0
    weak_zone_factor: float = 0.9
    weakening: str = "modulus"
    profile: str = "step"
    n_elements: int = 200

    default_control = "end_displacement"

    def __post_init__(self):
        require_positive(self, ("length", "area", "weak_zone_width"), " [mm or mm^2]")
        if self.weak_zone_width >= self.length:
            raise ValueError(f"weak_zone_width = {self.weak_zone_width} must be smaller than length = {self.length}")
        if not 0.0 < self.weak_zone_factor <= 1.0:
            raise ValueError(f"weak_zone_factor = {self.weak_zone_factor!r}; it must be in (0, 1]")
        if self.weakening not in _WEAKENINGS:
            raise ValueError(f"weakening = {self.weakening!r}; choose one of {_WEAKENINGS}")
        if self.profile not in _PROFILES:
            raise ValueError(f"profile = {self.profile!r}; choose one of {_PROFILES}")
        if int(self.n_elements) != self.n_elements or self.n_elements < 3:
            raise ValueError(f"n_elements = {self.n_elements!r}; it must be an integer >= 3")

    def vertices(self) -> np.ndarray:
        """Element end coordinates [mm]: as uniform as possible, with nodes at the weak-zone edges."""
        n, L, W = int(self.n_elements), self.length, self.weak_zone_width
        n_weak = max(1, round(n * W / L))
        n_weak += (n - n_weak) % 2
        n_out = (n - n_weak) // 2
        if n_out < 1:
            raise ValueError(f"n_elements = {n} is too few to mesh the weak zone and both outer parts")
        a, b = 0.5 * (L - W), 0.5 * (L + W)
        return np.concatenate([np.linspace(0, a, n_out + 1), np.linspace(a, b, n_weak + 1)[1:], np.linspace(b, L, n_out + 1)[1:]])

    def weakness(self, x) -> np.ndarray:
        """Factor (modulus or area) at positions x [mm]."""
        distance = np.abs(np.asarray(x, dtype=float) - 0.5 * self.length) / (0.5 * self.weak_zone_width)
        if self.profile == "step":
            return np.where(distance < 1.0, self.weak_zone_factor, 1.0)
        return 1.0 - (1.0 - self.weak_zone_factor) * np.clip(1.0 - distance, 0.0, 1.0)

    def build_problem(self, params, regularization: str = "gradient") -> DamageProblem:
        """The discretised bar: u(0) = 0, unit force pattern at x = L."""
        x = self.vertices()
        n = x.size - 1
        mid = 0.5 * (x[:-1] + x[1:])
        by_area = self.weakening == "area"
        areas = self.area * (self.weakness(mid) if by_area else 1.0)
        disc = bar_discretization(x, areas)
        factor = 1.0 if by_area else self.weakness(disc.points[..., 0])
        node = {xv: 2 * i for i, xv in enumerate(x)}
        a, b = 0.5 * (self.length - self.weak_zone_width), 0.5 * (self.length + self.weak_zone_width)
        left, right = node[min(node, key=lambda v: abs(v - a))], node[min(node, key=lambda v: abs(v - b))]
        functionals = {"end_displacement": {2 * n: 1.0}, "weak_zone_elongation": {right: 1.0, left: -1.0}}
        return DamageProblem(
            disc,
            params,
            regularization=regularization,
            stiffness_factor=factor,
            fixed_dofs=[0],
            load={2 * n: 1.0},
            functionals=functionals,
        )

    def output_mesh(self):
        """Nodes, cells and VTK cell type of the mesh, for :func:`fracid.report.write_result_vtk`."""
        from fracid.report.vtk import bar_mesh

        return bar_mesh(self.vertices())

    def observers(self, params, damage_threshold: float = 0.0) -> dict:
        """``damaged_zone_width``: length [mm] where omega > damage_threshold (kappa-level, interpolated)."""
        kappa_t = kappa_at_damage(damage_threshold, params.kappa_i, params.alpha, params.beta)

        def damaged_zone_width(problem, q, arrays):
            return superlevel_length(problem.disc.points[..., 0].ravel(), arrays.kappa.ravel(), kappa_t, 0.0, self.length)

        return {"damaged_zone_width": damaged_zone_width}

    def default_target(self, params) -> float:
        """A control value well past the peak: 50 times the elastic-limit elongation [mm]."""
        return 50.0 * params.kappa_i * self.length
