"""A discretised damage model with its boundary conditions, load pattern and named functionals."""

from __future__ import annotations

from typing import Mapping

import numpy as np

from fracid.model.assembly import assemble_vector, norm2
from fracid.model.discretization import MixedDiscretization
from fracid.model.forms import elastic_energy, gradient_damage, integral_damage, local_damage, model_constants
from fracid.model.nonlocal_average import internal_length, nonlocal_averaging
from fracid.model.parameters import DamageParameters

REGULARIZATIONS = ("gradient", "local", "integral")


class DamageProblem:
    """Damage model on a mixed discretisation, ready for the nonlinear solver.

    Dirichlet conditions are homogeneous (eliminated dofs); the structure is loaded by a force pattern
    scaled by the load factor lambda (so lambda is the applied force in N for a unit pattern). Which
    quantity is prescribed (an end displacement, an elongation, a CMOD) is a named linear functional of
    the displacements chosen at solve time, so snap-back can be traced by indirect displacement control.

    Parameters
    ----------
    disc : MixedDiscretization
    params : DamageParameters
    regularization : {"gradient", "local", "integral"}
        Implicit gradient-enhanced damage; the local damage model (no ebar dofs) for comparison; or
        integral-type nonlocal damage (no ebar dofs, Gaussian average of internal length
        l = sqrt(2 c) over the integration points, built once here).
    stiffness_factor : float or ndarray, shape (n_el, n_q)
        Young's modulus at each integration point relative to ``params.E`` (weak zones) [-].
    fixed_dofs : sequence of int
        Global displacement dofs held at zero.
    load : mapping {dof: weight}
        The force pattern f_hat; the applied force is lambda * f_hat [N].
    functionals : mapping {name: {dof: coefficient}}
        Linear functionals of the displacement (control quantities, observables) [mm].
    tied : sequence of sequences of int, optional
        Groups of displacement dofs that share one unknown (a rigid loading platen, a loading plate).
    symmetry_factor : float
        Copies of the model in the whole specimen (2 for a half model, 4 for a quarter model); the
        energies are reported for the whole specimen.
    damageable : float or ndarray, shape (n_el, n_q)
        1 where the material damages, 0 where it stays elastic (loading platens) [-].
    symmetry_planes : sequence of (axis, coordinate)
        Symmetry planes x[axis] = coordinate [mm] of a half or quarter model. Only the integral model
        needs them (the nonlocal average reaches across the plane, see
        :func:`~fracid.model.nonlocal_average.averaging_matrix`); the gradient model's natural
        boundary condition already is the symmetry condition.
    """

    def __init__(
        self,
        disc: MixedDiscretization,
        params: DamageParameters,
        *,
        regularization: str = "gradient",
        stiffness_factor=1.0,
        fixed_dofs=(),
        load: Mapping[int, float],
        functionals: Mapping[str, Mapping[int, float]],
        tied=(),
        symmetry_factor: float = 1.0,
        damageable=1.0,
        symmetry_planes=(),
    ):
        if regularization not in REGULARIZATIONS:
            raise ValueError(f"regularization = {regularization!r}; choose one of {REGULARIZATIONS}")
        if not isinstance(params, DamageParameters):
            raise TypeError(f"params must be DamageParameters, got {type(params).__name__}")
        self.disc, self.params, self.regularization = disc, params, regularization
        gradient = regularization == "gradient"
        n_active = disc.n_dofs if gradient else disc.n_u_dofs
        fixed = np.unique(np.asarray(fixed_dofs, dtype=int))
        if fixed.size and (fixed.min() < 0 or fixed.max() >= disc.n_u_dofs):
            raise ValueError(f"fixed dofs must be displacement dofs in [0, {disc.n_u_dofs}); got {fixed.tolist()}")
        self.free_index = self._number_unknowns(n_active, fixed, tied)
        self.n_free = int(self.free_index.max()) + 1
        self.symmetry_factor = float(symmetry_factor)
        dofs = np.concatenate([disc.u_dofs, disc.ebar_dofs], axis=1) if gradient else disc.u_dofs
        self.element_dofs = self.free_index[dofs]
        u_index = self.free_index[: disc.n_u_dofs]
        self.blocks = {"u": np.unique(u_index[u_index >= 0])}
        if gradient:
            self.blocks["ebar"] = self.free_index[disc.n_u_dofs :]
        self.load_vector = self._dense(load, "load")
        if not np.any(self.load_vector):
            raise ValueError("the load pattern is empty or acts only on fixed dofs")
        self.functionals = {name: self._dense(f, f"functional {name!r}") for name, f in functionals.items()}
        self.const = model_constants(disc, params, stiffness_factor, damageable)
        n_u = disc.u_dofs.shape[1]
        self._tangent = np.zeros((disc.n_elements,) + (self.element_dofs.shape[1],) * 2)
        if gradient:
            self._tangent[:, n_u:, n_u:] = self.const.ebar_matrix
        self.averaging = None
        if regularization == "integral":
            length = internal_length(params.c)
            self.averaging = nonlocal_averaging(disc, length, self.element_dofs, self.n_free, mirror=symmetry_planes)

    def _number_unknowns(self, n_active, fixed, tied) -> np.ndarray:
        """Unknown index of every dof: -1 if fixed or absent, shared within a tied group."""
        representative = np.arange(self.disc.n_dofs)
        for group in tied:
            group = np.asarray(group, dtype=int)
            if group.size == 0 or group.min() < 0 or group.max() >= self.disc.n_u_dofs:
                raise ValueError(f"a tied group must hold displacement dofs in [0, {self.disc.n_u_dofs})")
            if np.intersect1d(group, fixed).size:
                raise ValueError("a tied group contains a fixed dof; fix the whole group instead")
            representative[group] = group[0]
        active = np.zeros(self.disc.n_dofs, dtype=bool)
        active[:n_active] = True
        active[fixed] = False
        leaders = np.unique(representative[active])
        number = np.full(self.disc.n_dofs, -1)
        number[leaders] = np.arange(leaders.size)
        return np.where(active, number[representative], -1)

    def _dense(self, entries: Mapping[int, float], what: str) -> np.ndarray:
        vec = np.zeros(self.n_free)
        for dof, value in entries.items():
            if not 0 <= dof < self.disc.n_u_dofs:
                raise ValueError(f"{what}: dof {dof} is not a displacement dof")
            if self.free_index[dof] >= 0:
                vec[self.free_index[dof]] += value
            elif what == "load":
                raise ValueError(f"load: dof {dof} is fixed; a load on a support does no work")
        return vec

    def initial_history(self) -> np.ndarray:
        """History variable kappa of the virgin material, at every integration point."""
        return np.zeros(self.disc.weights.shape)

    def onset_ratio(self, kappa: np.ndarray) -> float:
        """Largest history variable relative to the damage threshold (< 1: still undamaged)."""
        return float(kappa.max()) / self.params.kappa_i

    def gather(self, q: np.ndarray) -> np.ndarray:
        """Element dof values from the free-dof vector (eliminated dofs are zero)."""
        return np.append(q, 0.0)[self.element_dofs]

    def evaluate(self, q: np.ndarray, kappa_old: np.ndarray):
        """Internal-force residual, element tangents and per-field reference norms at state q.

        Returns
        -------
        residual : ndarray, shape (n_free,)
            Internal forces minus the equivalent-strain source (no external load).
        arrays : ElementArrays
            Element tangents, trial history and damage (and the nonlocal coupling of the integral model).
        references : dict {field: float}
            Norms that make the residual of each field relative.
        """
        qe = self.gather(q)
        n_u = self.disc.u_dofs.shape[1]
        if self.regularization == "gradient":
            arrays = gradient_damage(self.disc, self.params, self.const, qe[:, :n_u], qe[:, n_u:], kappa_old, self._tangent)
        elif self.regularization == "integral":
            arrays = integral_damage(self.disc, self.params, self.const, qe, kappa_old, self._tangent, self.averaging)
        else:
            arrays = local_damage(self.disc, self.params, self.const, qe, kappa_old, self._tangent)
        residual = assemble_vector(self.element_dofs, arrays.residual, self.n_free)
        references = {}
        for field, element_ref in arrays.reference.items():
            dofs = self.element_dofs[:, :n_u] if field == "u" else self.element_dofs[:, n_u:]
            references[field] = float(norm2(assemble_vector(dofs, element_ref, self.n_free)))
        return residual, arrays, references

    def full_vector(self, q: np.ndarray) -> np.ndarray:
        """All dofs (displacements then ebar), eliminated ones zero."""
        return np.where(self.free_index >= 0, np.append(q, 0.0)[self.free_index], 0.0)

    def restrict(self, full: np.ndarray) -> np.ndarray:
        """Free-dof vector from all dofs (displacements, then ebar if any): inverse of :meth:`full_vector`."""
        padded = np.zeros(self.disc.n_dofs)
        padded[: len(full)] = full
        active = self.free_index >= 0
        q = np.zeros(self.n_free)
        q[self.free_index[active]] = padded[active]
        return q

    def fields(self, q: np.ndarray, kappa: np.ndarray, omega: np.ndarray) -> dict:
        """Nodal u [mm] and ebar [-], and kappa, omega [-] at the integration points."""
        full = self.full_vector(q)
        out = {"u": full[: self.disc.n_u_dofs], "kappa": kappa.copy(), "omega": omega.copy()}
        if self.regularization == "gradient":
            out["ebar"] = full[self.disc.n_u_dofs :]
        return out

    def elastic_energy(self, q: np.ndarray, omega: np.ndarray) -> float:
        """Recoverable elastic energy of the state [N mm]."""
        ue = self.gather(q)[:, : self.disc.u_dofs.shape[1]]
        return self.symmetry_factor * elastic_energy(self.disc, self.const, ue, omega)
