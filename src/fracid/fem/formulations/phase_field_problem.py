"""The phase-field regularised cohesive zone model (PF-CZM) as a problem for the nonlinear solver: the
displacements u and the crack phase field d (a nodal field on the element corners) solved together
(monolithic Newton, so the bordered indirect control passes snap-back).

Weak form (docs/theory.md, section 7), with the law's functions of :mod:`fracid.fem.material.phase_field`:

    r_u = int B^T g(d) E D eps dV
    r_d = int [ Gf / (pi l) (alpha'(d) N + 2 l^2 grad N . grad d) + g'(d) Y N ] dV

Y = E max(ft / E, h)^2 / 2 (its corner rounded, :func:`~fracid.fem.material.phase_field.driving_force`) is
the crack driving force of the history h, the largest effective major
principal stress per unit E (lambda_1 of D eps, a strain) any step reached: irreversibility as kappa's in
the damage models, and the threshold keeps d = 0 until the effective major principal stress reaches ft
(at d = 0, g'(0) = -a1 and -g'(0) ft^2 / (2 E) = 2 Gf / (pi l) = Gf alpha'(0) / (pi l): the local balance).

Bounds on d: nothing clips d. Where the driving force is at its threshold the equation holds d = 0; in a
band d rises towards 1, where g(1) = g'(1) = 0 (p >= 2) stop the driving force, and (1 - d) is kept >= 0
inside g. The tests measure how far the converged d leaves [0, 1] (docs/pfczm/README.md).

Points that cannot damage (loading platens, ``damageable`` 0) keep their stress undegraded and their
history at zero (their phase-field equation holds d at 0 there).
"""

from __future__ import annotations

import numpy as np

from fracid.fem.formulations import damage_sensitivity as ds
from fracid.fem.formulations.forms import ElementArrays, bt, btdb, gradient_matrix, strain_of
from fracid.fem.formulations.problem import ContinuumProblem
from fracid.fem.formulations.protocol import HistoryVariable
from fracid.fem.material import phase_field as pf
from fracid.fem.material.crack_band import major_principal
from fracid.fem.mesh.dofs import FieldSpec


class PhaseFieldProblem(ContinuumProblem):
    """PF-CZM on a bar or a plane-stress discretisation.

    Parameters
    ----------
    disc : MixedDiscretization
    params
        A PF-CZM parameter set (:mod:`fracid.fem.material.phase_field`): E, nu, ft, Gf, l, p, a2, a3.
    conditions : Conditions
    stiffness_factor : float or ndarray, shape (n_el, n_q)
        Young's modulus at the points relative to ``params.E`` (the stress's; the driving force and a1
        use the material's E) [-].
    damageable : float or ndarray, shape (n_el, n_q)
        1 where a crack may form, 0 where the material stays elastic [-].
    strength_factor : float or ndarray, shape (n_el, n_q)
        The tensile strength at the points relative to ``params.ft`` at equal Gf (an imperfection) [-].
    irreversible : bool
        True (the model): the driving force follows the history maximum. False: the driving force of the
        current state, as Wu's 1D analysis assumes (a verification of the formulation against that analysis,
        :mod:`fracid.fem.material.phase_field_cohesive`; where the driving force falls near the band's edges the
        history makes the response depart from it, docs/pfczm/README.md).
    """

    field_specs = (FieldSpec("d", "linear"),)
    #: the parameters :meth:`differentiate` differentiates with respect to
    differentiable = ("E", "nu", "ft", "Gf", "l", "p", "a2", "a3")

    def __init__(self, disc, params, conditions, *, stiffness_factor=1.0, damageable=1.0, strength_factor=1.0,
                 irreversible=True):
        super().__init__(disc, params, conditions, stiffness_factor=stiffness_factor, damageable=damageable)
        self.irreversible = bool(irreversible)
        self.space = disc.space(self.field_specs[0].space)
        self.strength = np.broadcast_to(np.asarray(strength_factor, dtype=float), disc.weights.shape)
        self.ft = params.ft * self.strength
        self.a1 = pf.a1(params.E, self.ft, params.Gf, params.l)
        self.k1 = params.Gf / (pf.C_ALPHA * params.l)  # Gf / (c_alpha l) [MPa]
        self.k2 = 2.0 * params.Gf * params.l / pf.C_ALPHA  # 2 l^2 Gf / (c_alpha l) [N]
        self.laplacian = gradient_matrix(self.space, disc.weights)  # int grad N^T grad N, (n_el, n_e, n_e)
        self.n_u = self.dofs.n_u

    @property
    def history_spec(self) -> dict:
        """``{"h": ...}``: the largest effective major principal stress per unit E reached, per point [-]."""
        return {"h": HistoryVariable()}

    def onset_ratio(self, history) -> float:
        """Largest effective major principal stress reached relative to where the rounded threshold starts to
        drive d, (1 - ONSET_ROUNDING) ft (< 1: no crack yet)."""
        return float(np.max(history * self.params.E / self.ft)) / (1.0 - pf.ONSET_ROUNDING)

    def _state(self, qe, h_old):
        """What the residual, the tangent and the derivatives share at element dof values ``qe``."""
        const, N = self.const, self.space.shape
        ue, de = qe[:, : self.n_u], qe[:, self.n_u:]
        s = strain_of(const.DB, ue)  # D eps, stress per unit E
        lam, dlam = major_principal(s)
        mask = const.damageable > 0.0
        loading = mask & ((lam > h_old) | (not self.irreversible))
        h = np.where(loading, lam, h_old)
        Y, dY_dh = pf.driving_force(h, self.params.E, self.ft)
        d = de @ N.T
        p = self.params
        g, g1, g2 = pf.degradation(d, self.a1, p.p, p.a2, p.a3)
        return dict(ue=ue, de=de, s=s, lam=lam, dlam=dlam, mask=mask, loading=loading, h=h, Y=Y, dY_dh=dY_dh, d=d,
                    g=np.where(mask, g, 1.0), g1=g1, g2=g2, g1_stress=np.where(mask, g1, 0.0))

    def _element_arrays(self, qe, h_old):
        st = self._state(qe, h_old)
        disc, const, N, w = self.disc, self.const, self.space.shape, self.disc.weights
        B, nu = disc.strain_operator, self.n_u
        bt_s = bt(st["s"], B)  # B^T D eps per unit E, (n_el, n_q, n_u)
        w_E = w * const.E
        f_u = np.einsum("eqi,eq->ei", bt_s, w_E * st["g"])
        _, alpha1, alpha2 = pf.geometric(st["d"])
        local = self.k1 * alpha1 + st["g1"] * st["Y"]
        f_d = (w * local) @ N + self.k2 * np.einsum("eij,ej->ei", self.laplacian, st["de"])
        reference = (w * np.abs(st["g1"]) * st["Y"]) @ N

        def tangent():
            out = self._tangent
            out[:, :nu, :nu] = btdb(B * (w_E * st["g"])[..., None, None], const.DB)
            out[:, :nu, nu:] = np.matmul((bt_s * (w_E * st["g1_stress"])[..., None]).transpose(0, 2, 1), N)
            # at loading points dY / du = dY / dh d lambda_1 / d s . D B
            dY = bt(st["dlam"], const.DB) * (st["dY_dh"] * st["loading"])[..., None]
            out[:, nu:, :nu] = np.matmul(N.T, dY * (w * st["g1"])[..., None])
            local_slope = w * (self.k1 * alpha2 + st["g2"] * st["Y"])
            out[:, nu:, nu:] = np.einsum("qi,eq,qj->eij", N, local_slope, N) + self.k2 * self.laplacian
            return out

        return ElementArrays(np.concatenate([f_u, f_d], axis=1), tangent, {"u": f_u, "d": reference}, st["h"],
                             outputs={"omega": 1.0 - st["g"]})

    # direct differentiation (fracid.fem.path.ddm; docs/theory.md, section 7)

    def differentiate(self, q, h_old, h_old_rate, names) -> "ds.StepDerivative":
        """The pseudo-load of a converged step and how to complete its derivatives (see
        :class:`~fracid.fem.formulations.damage_sensitivity.StepDerivative`).

        At fixed (u, d): D eps moves with nu only; Y with E and ft (the threshold), and with h's explicit
        part (at loading points d lambda_1 / d nu at fixed strain, elsewhere h' of the last step); g and g'
        with a1 (E, ft, Gf, l) and the shape (p, a2, a3); the coefficients Gf / (pi l) and 2 Gf l / pi with
        Gf and l. Non-differentiable points take the branch the state took: the threshold (h = ft / E),
        loading versus unloading (lambda_1 = h_old), equal principal values.
        """
        names = ds.check_names(names, self.differentiable)
        params, disc, const = self.params, self.disc, self.const
        N, w, B = self.space.shape, disc.weights, disc.strain_operator
        st = self._state(self.gather(q), h_old)
        column = {name: k for k, name in enumerate(names)}
        n_p = len(names)

        eps = strain_of(B, st["ue"])
        s_nu = np.einsum("st,eqt->eqs", disc.strain_state.unit_elastic_matrix_derivative(params.nu), eps)
        explicit = np.zeros(w.shape + (n_p,))  # d lambda_1 / d x at fixed strain
        if "nu" in column:
            explicit[..., column["nu"]] = np.einsum("eqs,eqs->eq", st["dlam"], s_nu)
        h_rate = np.where(st["loading"][..., None], explicit, h_old_rate)

        Y_rate = self._driving_force_rate(st, h_rate, names)
        g_rate, g1_rate = self._degradation_rates(st["d"], names)
        mask = st["mask"][..., None]
        omega = 1.0 - st["g"]
        stress = ds.unit_stress_forces(disc, const, st["ue"])
        force = ds.equilibrium_pseudo_load(disc, params, const, st["ue"], omega, -np.where(mask, g_rate, 0.0), names,
                                           stress)
        local_rate = g1_rate * st["Y"][..., None] + st["g1"][..., None] * Y_rate
        _, alpha1, _ = pf.geometric(st["d"])
        laplace_d = np.einsum("eij,ej->ei", self.laplacian, st["de"])
        for name, k1_rate, k2_rate in (("Gf", self.k1 / params.Gf, self.k2 / params.Gf),
                                       ("l", -self.k1 / params.l, self.k2 / params.l)):
            if name in column:
                local_rate[..., column[name]] += k1_rate * alpha1
        rows = np.matmul(N.T, w[..., None] * local_rate)  # (n_el, n_e, p)
        for name, k2_rate in (("Gf", self.k2 / params.Gf), ("l", self.k2 / params.l)):
            if name in column:
                rows[..., column[name]] += k2_rate * laplace_d
        pseudo_load = self.assemble_columns(np.concatenate([force, rows], axis=1))

        def complete(dq):
            dqe = self.gather_columns(dq)
            due, dde = dqe[:, : self.n_u], dqe[:, self.n_u:]
            lam_rate = np.einsum("eqs,eqsj,ejp->eqp", st["dlam"], const.DB, due) + explicit
            rate = ds.history_derivative(st["loading"], lam_rate, h_old_rate)
            d_rate = np.einsum("qi,eip->eqp", N, dde)
            total_g = np.where(mask, g_rate + st["g1"][..., None] * d_rate, 0.0)
            energy = ds.elastic_energy_derivative(disc, params, const, st["ue"], due, omega, -total_g, names, stress)
            return rate, self.symmetry_factor * energy

        return ds.StepDerivative(pseudo_load, complete)

    def _driving_force_rate(self, st, h_rate, names) -> np.ndarray:
        """d Y / d x at fixed (u, d), (n_el, n_q, p): E's and ft's own, and h's explicit part."""
        params = self.params
        own = pf.driving_force_parameter_derivatives(st["h"], params.E, params.ft, self.strength)
        rate = ds.stacked(own, names, st["h"].shape)
        return rate + st["dY_dh"][..., None] * h_rate

    def _degradation_rates(self, d, names):
        """d g / d x and d g' / d x at fixed d, (n_el, n_q, p) each: through a1 and the shape constants."""
        params = self.params
        by_constant = pf.degradation_parameter_derivatives(d, self.a1, params.p, params.a2, params.a3)
        a1_rates = {"E": 1.0 / params.E, "ft": -2.0 / params.ft, "Gf": 1.0 / params.Gf, "l": -1.0 / params.l}
        g_rate, g1_rate = np.zeros(d.shape + (len(names),)), np.zeros(d.shape + (len(names),))
        for k, name in enumerate(names):
            if name in a1_rates:  # d a1 / d x = a1 * a1_rates[name]
                dg, dg1 = by_constant["a1"]
                g_rate[..., k], g1_rate[..., k] = dg * self.a1 * a1_rates[name], dg1 * self.a1 * a1_rates[name]
            elif name in by_constant:
                g_rate[..., k], g1_rate[..., k] = by_constant[name]
        return g_rate, g1_rate

