"""A plane-stress problem whose material is the rotating crack band of :mod:`fracid.fem.material.crack_band`, with
any traction-separation law (:class:`~fracid.fem.material.tsl.TractionSeparationLaw`)."""

from __future__ import annotations

import numpy as np

from fracid.fem.formulations import damage_sensitivity as ds
from fracid.fem.mesh.assembly import assemble_vector, norm2
from fracid.fem.material.crack_band import (band_damage, band_damage_parameter_derivatives, crack_band_stress,
                                   crack_direction_stress, crack_direction_stress_nu_derivative, element_mean,
                                   snap_back_limit)
from fracid.fem.material.damage import update_history
from fracid.fem.formulations.forms import ElementArrays, btdb, point_outputs, strain_of
from fracid.fem.formulations.problem import ContinuumProblem
from fracid.fem.material.tsl import ScaledLaw, differentiable


def element_extent(nodes, cells, direction) -> np.ndarray:
    """Extent of each element along a unit ``direction`` [mm]: the width of a crack band that
    crosses the element normal to ``direction`` (Rots' projection)."""
    projected = nodes[cells] @ np.asarray(direction, dtype=float)
    return projected.max(axis=1) - projected.min(axis=1)


class CrackBandProblem(ContinuumProblem):
    """Smeared crack band (rotating crack, a traction-separation law) on a plane-stress discretisation.

    Displacement unknowns only (:class:`~fracid.fem.formulations.problem.ContinuumProblem`); the material is the
    crack band's.

    Parameters
    ----------
    disc : MixedDiscretization
        Plane stress.
    law : TractionSeparationLaw
        E.g. :class:`~fracid.fem.material.laws.HordijkLaw`; with ``steepest_slope`` (the snap-back limit).
    params : ParameterSet
        E, nu of the bulk and the law's parameters (``law.parameters``).
    band_width : array_like, shape (n_el,)
        Crack band width h of each element [mm] (the element's extent across the expected crack;
        twice that for an element on a symmetry line the crack runs along, whose band is mirrored).
    strength_factor : float or ndarray, shape (n_el, n_q)
        Tensile strength relative to the law's at equal fracture energy (openings divided by the same
        factor: a sigma(a w)): an imperfection that fixes where the band forms without changing Gf [-].
        Each element takes the mean factor of its points for the strength and the mean of its
        inverse for the openings.
    crackable : float or ndarray, shape (n_el, n_q)
        1 where a crack may form, 0 where the material stays elastic [-].
    conditions : Conditions
    stiffness_factor : float or ndarray
        Young's modulus relative to ``params.E`` at the integration points [-].
    """

    #: parameters :meth:`differentiate` differentiates with respect to with Hordijk's law (all of
    #: CohesiveParameters); an instance's are all of its ``params`` if its law gives parameter derivatives
    differentiable = ("E", "nu", "ft", "Gf", "c1", "c2")

    def __init__(self, disc, law, params, conditions, band_width, *, strength_factor=1.0, crackable=1.0,
                 stiffness_factor=1.0):
        if disc.strain_state.n_components != 3:
            raise ValueError("the crack band model is written for plane stress (3 strain components)")
        super().__init__(disc, params, conditions, stiffness_factor=stiffness_factor)
        self.law = law
        self.differentiable = tuple(params.names()) if differentiable(law) else ()
        h = np.asarray(band_width, dtype=float)
        if h.shape != (disc.n_elements,) or not np.all(h > 0):
            raise ValueError(f"band_width must be {disc.n_elements} positive element widths [mm]")
        self.band_width = h[:, None]
        self.strength = np.broadcast_to(np.asarray(strength_factor, dtype=float), disc.weights.shape)
        self.ft = law.strength(params) * self.strength
        self.crackable = np.broadcast_to(np.asarray(crackable, dtype=float), disc.weights.shape)
        # the law at the points: strength mean(a) ft, openings divided by 1 / mean(1 / a) (equal Gf for uniform a)
        stress = element_mean(self.strength, disc.weights)
        opening = 1.0 / element_mean(1.0 / self.strength, disc.weights)
        self.local_law = ScaledLaw(law, params, stress, opening)
        crackable_elements = np.any(self.crackable > 0, axis=1)
        steepest = float(np.max(stress * opening, axis=1)[crackable_elements].max(initial=1.0))
        limit = snap_back_limit(self.const.E.min(), law, params) / steepest
        widest = float(h[crackable_elements].max(initial=0.0))
        if widest >= limit:
            raise ValueError(
                f"crack band width {widest:g} mm exceeds the snap-back limit {limit:g} mm of E = {params.E:g} MPa "
                f"with the {law.name} law at {params}: refine the mesh where the crack runs"
            )

    def onset_ratio(self, kappa: np.ndarray) -> float:
        """Largest major principal stress relative to the strength (< 1: no crack yet)."""
        return float(np.max(kappa * self.const.E / self.ft))

    def _stress(self, ue, kappa_old):
        s = strain_of(self.const.DB, ue)  # D eps per unit E
        return crack_band_stress(s, kappa_old, self.disc.weights, self.band_width, self.const.E, self.params.nu,
                                 self.local_law, self.crackable)

    def evaluate(self, q, kappa_old):
        ue = self.gather(q)
        B, w = self.disc.strain_operator, self.disc.weights
        sigma, dsigma, (a, b), kappa, omega = self._stress(ue, kappa_old)
        forces = np.einsum("eqsi,eqs->ei", B, sigma * w[..., None])
        self._tangent[:] = btdb(B * w[..., None, None], np.matmul(dsigma, self.const.DB))
        # the element's common damage couples its points: a rank-one term per element
        self._tangent -= np.einsum("ei,ej->eij", np.einsum("eqsi,eqs->ei", B, a * w[..., None]),
                                   np.einsum("eqs,eqsj->ej", b, self.const.DB))
        residual = assemble_vector(self.element_dofs, forces, self.n_free)
        arrays = ElementArrays(forces, self._tangent, {"u": forces}, kappa, outputs={"omega": omega})
        return residual, arrays, {"u": norm2(residual)}

    def elastic_energy(self, q, kappa, arrays):
        """Energy recovered on unloading to zero stress, 1/2 int eps . sigma dV (secant unloading) [N mm]."""
        omega = point_outputs(arrays)["omega"]
        ue = self.gather(q)
        eps = strain_of(self.disc.strain_operator, ue)
        s = strain_of(self.const.DB, ue)
        sigma = self.const.E[..., None] * (s - omega[..., None] * crack_direction_stress(s, self.params.nu)[1])
        return self.symmetry_factor * 0.5 * float(np.sum(self.disc.weights * np.sum(eps * sigma, axis=-1)))

    # direct differentiation (fracid.fem.path.ddm)

    def differentiate(self, q, kappa_old, kappa_old_rate, names) -> "ds.StepDerivative":
        """The pseudo-load of a converged step and how to complete its derivatives (see
        :class:`~fracid.fem.formulations.damage_sensitivity.StepDerivative`).

        sigma = E (s - omega F(s, nu)) with s = D(nu) eps, omega = omega(kappa; E, h = (1 - nu^2) h_el,
        the law's parameters) of the element's history kappa = max(kappa_old, mean lambda_1(s)). At fixed
        displacements, s moves with nu only; omega with the parameters at fixed kappa
        (:func:`~fracid.fem.material.crack_band.band_damage_parameter_derivatives`) and with kappa's explicit
        part: at loading elements the parameter derivative of mean lambda_1 at fixed eps (through
        D(nu)), elsewhere the kappa' carried from the last step.

        Non-differentiable points, where the one-sided derivative of the branch the element is on
        is used: the onset of cracking of an element, kappa = ft / E (omega leaves 0 with a kink; its
        parameter derivatives jump from 0), the opening at which the law's traction reaches zero
        (w = wc) and the law's own kinks (the bilinear law's w1), loading versus unloading at kappa = mean lambda_1, and the closure of a crack
        (lambda_1 = 0, where F switches off) or equal principal values (the crack direction is
        undefined). With the element's crack band advancing one element at a time, a recorded step
        exactly on such a point is rare.
        """
        names = ds.check_names(names, self.differentiable)
        p, params, nu = len(names), self.params, self.params.nu
        disc, const = self.disc, self.const
        B, weights = disc.strain_operator, disc.weights
        share = weights / np.sum(weights, axis=1, keepdims=True)

        def element_means(values):  # weighted element means of (n_el, n_q, p) values, at every point
            return np.broadcast_to(np.einsum("eq,eqp->ep", share, values)[:, None, :], values.shape)

        ue = self.gather(q)
        eps = strain_of(B, ue)
        s = strain_of(const.DB, ue)
        lam, F, dF, dlam = crack_direction_stress(s, nu)
        F_nu = crack_direction_stress_nu_derivative(s)
        kappa, loading = update_history(kappa_old, element_mean(lam, weights))

        # omega and its parameter derivatives at fixed kappa, with the arguments crack_band_stress uses
        mean = lambda v: element_mean(v, weights)  # noqa: E731
        width = np.broadcast_to(self.band_width, weights.shape)
        h, crackable = (1.0 - nu * nu) * width, mean(self.crackable)
        arguments = (kappa, h, mean(const.E), self.local_law)
        omega, d_omega = (crackable * v for v in band_damage(*arguments))
        by_argument, rates = band_damage_parameter_derivatives(*arguments)
        rates.update(E=by_argument["E"] * mean(const.E) / params.E, nu=by_argument["band_width"] * (-2.0 * nu * width))
        law_rate = crackable[..., None] * ds.stacked(rates, names, weights.shape)

        # s' at fixed displacements (nu only) and the explicit part of the driving mean lambda_1
        s_rate = np.zeros(s.shape + (p,))
        if "nu" in names:
            d_D = disc.strain_state.unit_elastic_matrix_derivative(nu)
            s_rate[..., names.index("nu")] = np.einsum("st,eqt->eqs", d_D, eps)
        explicit = element_means(np.einsum("eqs,eqsp->eqp", dlam, s_rate))
        nu_column = np.zeros(p)
        if "nu" in names:
            nu_column[names.index("nu")] = 1.0
        E_column = np.array([1.0 / params.E if name == "E" else 0.0 for name in names])
        sigma = const.E[..., None] * (s - omega[..., None] * F)

        def stress_rate(ds_rate, omega_rate):
            """d sigma (n_el, n_q, 3, p) for rates of s and omega (all parameters' columns)."""
            d_F = np.einsum("eqst,eqtp->eqsp", dF, ds_rate) + F_nu[..., None] * nu_column
            return (sigma[..., None] * E_column + const.E[..., None, None]
                    * (ds_rate - omega_rate[..., None, :] * F[..., None] - omega[..., None, None] * d_F))

        omega_rate = law_rate + d_omega[..., None] * np.where(loading[..., None], explicit, kappa_old_rate)
        d_sigma = stress_rate(s_rate, omega_rate)
        pseudo_load = self.assemble_columns(np.einsum("eqsi,eqsp->eip", B, d_sigma * weights[..., None, None]))

        def complete(dq):
            due = self.gather_columns(dq)
            d_eps = np.einsum("eqsi,eip->eqsp", B, due)
            ds_total = np.einsum("eqsj,ejp->eqsp", const.DB, due) + s_rate
            rate = ds.history_derivative(loading, element_means(np.einsum("eqs,eqsp->eqp", dlam, ds_total)),
                                         kappa_old_rate)
            total_sigma = stress_rate(ds_total, law_rate + d_omega[..., None] * rate)
            energy = 0.5 * np.einsum("eq,eqsp->p", weights, d_eps * sigma[..., None] + eps[..., None] * total_sigma)
            return rate, self.symmetry_factor * energy

        return ds.StepDerivative(pseudo_load, complete)
