"""A plane-stress problem whose material is the rotating crack band of :mod:`fracid.fem.crack_band`."""

from __future__ import annotations

import numpy as np

from fracid.fem.assembly import assemble_vector, norm2
from fracid.fem.crack_band import crack_band_stress, crack_direction_stress, snap_back_limit
from fracid.fem.forms import ElementArrays, _btdb
from fracid.fem.problem import ContinuumProblem


def element_extent(nodes, cells, direction) -> np.ndarray:
    """Extent of each element along a unit ``direction`` [mm]: the width of a crack band that
    crosses the element normal to ``direction`` (Rots' projection)."""
    projected = nodes[cells] @ np.asarray(direction, dtype=float)
    return projected.max(axis=1) - projected.min(axis=1)


class CrackBandProblem(ContinuumProblem):
    """Smeared crack band (rotating crack, Hordijk softening) on a plane-stress discretisation.

    Displacement unknowns only (:class:`~fracid.fem.problem.ContinuumProblem`); the material is the
    crack band's.

    Parameters
    ----------
    disc : MixedDiscretization
        Plane stress.
    law : HordijkLaw
    params : CohesiveParameters
        E, nu of the bulk and ft, Gf, c1, c2 of the crack law.
    band_width : array_like, shape (n_el,)
        Crack band width h of each element [mm] (the element's extent across the expected crack;
        twice that for an element on a symmetry line the crack runs along, whose band is mirrored).
    strength_factor : float or ndarray, shape (n_el, n_q)
        Tensile strength relative to ``params.ft`` at equal fracture energy (wc divided by the same
        factor): an imperfection that fixes where the band forms without changing Gf [-].
    crackable : float or ndarray, shape (n_el, n_q)
        1 where a crack may form, 0 where the material stays elastic [-].
    conditions : Conditions
    stiffness_factor : float or ndarray
        Young's modulus relative to ``params.E`` at the integration points [-].
    """

    def __init__(self, disc, law, params, conditions, band_width, *, strength_factor=1.0, crackable=1.0,
                 stiffness_factor=1.0):
        if disc.strain_state.n_components != 3:
            raise ValueError("the crack band model is written for plane stress (3 strain components)")
        super().__init__(disc, params, conditions, stiffness_factor=stiffness_factor)
        self.law = law
        h = np.asarray(band_width, dtype=float)
        if h.shape != (disc.n_elements,) or not np.all(h > 0):
            raise ValueError(f"band_width must be {disc.n_elements} positive element widths [mm]")
        self.band_width = h[:, None]
        self.strength = np.broadcast_to(np.asarray(strength_factor, dtype=float), disc.weights.shape)
        self.ft = params.ft * self.strength
        self.crackable = np.broadcast_to(np.asarray(crackable, dtype=float), disc.weights.shape)
        limit = snap_back_limit(self.const.E.min(), self.ft.max(), *params.law()[1:])
        widest = float(h[np.any(self.crackable > 0, axis=1)].max(initial=0.0))
        if widest >= limit:
            raise ValueError(
                f"crack band width {widest:g} mm exceeds the snap-back limit {limit:g} mm of E = {params.E:g} MPa, "
                f"ft = {params.ft:g} MPa, Gf = {params.Gf:g} N/mm: refine the mesh where the crack runs"
            )

    def onset_ratio(self, kappa: np.ndarray) -> float:
        """Largest major principal stress relative to the strength (< 1: no crack yet)."""
        return float(np.max(kappa * self.const.E / self.ft))

    def _stress(self, ue, kappa_old):
        s = np.einsum("eqsj,ej->eqs", self.const.DB, ue)  # D eps per unit E
        _, wc, c1, c2 = self.params.law()
        law = (wc / self.strength, c1, c2)
        return crack_band_stress(s, kappa_old, self.disc.weights, self.band_width, self.const.E, self.params.nu, self.ft,
                                 law, self.crackable)

    def evaluate(self, q, kappa_old):
        ue = self.gather(q)
        B, w = self.disc.strain_operator, self.disc.weights
        sigma, dsigma, (a, b), kappa, omega = self._stress(ue, kappa_old)
        forces = np.einsum("eqsi,eqs->ei", B, sigma * w[..., None])
        self._tangent[:] = _btdb(B * w[..., None, None], np.matmul(dsigma, self.const.DB))
        # the element's common damage couples its points: a rank-one term per element
        self._tangent -= np.einsum("ei,ej->eij", np.einsum("eqsi,eqs->ei", B, a * w[..., None]),
                                   np.einsum("eqs,eqsj->ej", b, self.const.DB))
        residual = assemble_vector(self.element_dofs, forces, self.n_free)
        arrays = ElementArrays(forces, self._tangent, {"u": forces}, kappa, omega)
        return residual, arrays, {"u": norm2(residual)}

    def elastic_energy(self, q, kappa, omega):
        """Energy recovered on unloading to zero stress, 1/2 int eps . sigma dV (secant unloading) [N mm]."""
        ue = self.gather(q)
        eps = np.einsum("eqsi,ei->eqs", self.disc.strain_operator, ue)
        s = np.einsum("eqsj,ej->eqs", self.const.DB, ue)
        sigma = self.const.E[..., None] * (s - omega[..., None] * crack_direction_stress(s, self.params.nu)[1])
        return self.symmetry_factor * 0.5 * float(np.sum(self.disc.weights * np.sum(eps * sigma, axis=-1)))
