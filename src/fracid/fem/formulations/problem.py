"""Continuum damage formulations as problems for the nonlinear solver: gradient, local and integral.

Each takes a material law (:class:`~fracid.fem.material.laws.DamageLaw`), its parameters, a discretisation and
the boundary :class:`~fracid.fem.mesh.dofs.Conditions`, and implements the
:class:`~fracid.fem.formulations.protocol.Problem` protocol. :data:`FORMULATIONS` names them for the model
registry.
"""

from __future__ import annotations

import numpy as np

from fracid.fem.mesh.assembly import assemble_vector, norm2
from fracid.fem.formulations import damage_sensitivity as ds
from fracid.fem.mesh.discretization import MixedDiscretization
from fracid.fem.mesh.dofs import Conditions, FieldSpec, number_dofs
from fracid.fem.formulations.forms import (elastic_bulk, elastic_energy, gradient_damage, gradient_matrix, integral_damage,
                                           local_damage, masked_damage, model_constants, point_outputs, strain_of)
from fracid.fem.material.laws import DamageLaw
from fracid.fem.formulations.nonlocal_average import averaging_length_derivative, internal_length, nonlocal_averaging
from fracid.fem.formulations.protocol import HistoryVariable, allocate_history


class ContinuumProblem:
    """What every continuum formulation shares: the unknowns under the conditions (a
    :class:`~fracid.fem.mesh.dofs.DofMap`), the constant parts of the tangent, the assembly of the element
    arrays, the fields and the elastic energy. Subclasses give ``_element_arrays(qe, history_old)``, and
    declare their named scalar fields (``field_specs``, none here) and history (``history_spec``: one
    scalar ``kappa`` per integration point here).

    Parameters
    ----------
    disc : MixedDiscretization
    params
        Parameters with the elastic ``E`` [MPa] and ``nu`` [-] of the bulk (and whatever the
        subclass's fields need).
    conditions : Conditions
        Supports, load pattern, tied groups, functionals and symmetry factor.
    stiffness_factor : float or ndarray, shape (n_el, n_q)
        Young's modulus at each integration point relative to ``params.E`` (weak zones, platens) [-].
    damageable : float or ndarray, shape (n_el, n_q)
        1 where the material softens, 0 where it stays elastic (loading platens) [-].
    """

    #: the named scalar fields besides the displacements (:class:`~fracid.fem.mesh.dofs.FieldSpec`)
    field_specs: tuple = ()

    def __init__(self, disc: MixedDiscretization, params, conditions: Conditions, *, stiffness_factor=1.0,
                 damageable=1.0):
        self.disc, self.params = disc, params
        self.dofs = number_dofs(disc, conditions, self.field_specs)
        self.n_free, self.element_dofs, self.blocks = self.dofs.n_free, self.dofs.element_dofs, self.dofs.blocks
        self.load_vector, self.functionals = self.dofs.load_vector, self.dofs.functionals
        self.symmetry_factor = float(conditions.symmetry_factor)
        self.const = model_constants(disc, params, stiffness_factor, damageable, self._gradient_space())
        self._tangent = np.zeros((disc.n_elements,) + (self.element_dofs.shape[1],) * 2)

    def _gradient_space(self):
        """The scalar space of a diffusion equation whose constant matrix the constants hold (none here)."""
        return None

    @property
    def history_spec(self) -> dict:
        """``{"kappa": HistoryVariable()}``: one scalar per integration point."""
        return {"kappa": HistoryVariable()}

    def initial_history(self):
        """History of the virgin material, allocated from :attr:`history_spec`."""
        return allocate_history(self.history_spec, self.disc)

    def gather(self, q: np.ndarray) -> np.ndarray:
        """Element dof values from the free-dof vector (eliminated dofs are zero)."""
        return self.dofs.gather(q)

    def full_vector(self, q: np.ndarray) -> np.ndarray:
        """All dofs (displacements, then the named fields'), eliminated ones zero."""
        return self.dofs.full_vector(q)

    def restrict(self, full: np.ndarray) -> np.ndarray:
        """Free-dof vector from all dofs: inverse of :meth:`full_vector`."""
        return self.dofs.restrict(full)

    def _element_arrays(self, qe, history_old):
        raise NotImplementedError

    def assemble_columns(self, element_values: np.ndarray) -> np.ndarray:
        """Element vectors with a last axis of p columns (n_el, n_dof_el, p) assembled to (n_free, p)."""
        return np.column_stack([assemble_vector(self.element_dofs, element_values[..., k], self.n_free)
                                for k in range(element_values.shape[-1])])

    def gather_columns(self, dq: np.ndarray) -> np.ndarray:
        """Element dof values (n_el, n_dof_el, p) of p free-dof vectors (n_free, p)."""
        return np.stack([self.gather(dq[:, k]) for k in range(dq.shape[1])], axis=-1)

    def evaluate(self, q: np.ndarray, history_old: np.ndarray):
        """Internal-force residual, element arrays and per-field reference norms at state q
        (see :meth:`fracid.fem.formulations.protocol.Problem.evaluate`)."""
        arrays = self._element_arrays(self.gather(q), history_old)
        residual = assemble_vector(self.element_dofs, arrays.residual, self.n_free)
        references = {}
        for field, element_ref in arrays.reference.items():
            dofs = self.element_dofs[:, self.dofs.columns[field]]
            references[field] = float(norm2(assemble_vector(dofs, element_ref, self.n_free)))
        return residual, arrays, references

    def fields(self, q: np.ndarray, history, arrays) -> dict:
        """Nodal u [mm] and the named fields, the history (``kappa`` [-]) and the point outputs
        (``omega`` [-]) of the state; ``arrays`` are its :class:`~fracid.fem.formulations.forms.ElementArrays` (or,
        as before named outputs, the damage omega at the points)."""
        out = self.dofs.split(q)
        out["kappa"] = history.copy()
        out.update({name: value.copy() for name, value in point_outputs(arrays).items()})
        return out

    def elastic_energy(self, q: np.ndarray, history, arrays) -> float:
        """Recoverable elastic energy of the state [N mm]; ``arrays`` as for :meth:`fields`."""
        ue = self.gather(q)[:, self.dofs.columns["u"]]
        return self.symmetry_factor * elastic_energy(self.disc, self.const, ue, point_outputs(arrays)["omega"])


class ElasticProblem(ContinuumProblem):
    """A linear elastic bulk (the bulk of the discrete cohesive crack); ``params`` needs ``E`` and ``nu``."""

    def __init__(self, disc, params, conditions, *, stiffness_factor=1.0):
        super().__init__(disc, params, conditions, stiffness_factor=stiffness_factor, damageable=0.0)

    def onset_ratio(self, history: np.ndarray) -> float:
        return 0.0

    def _element_arrays(self, qe, history_old):
        return elastic_bulk(self.disc, self.const, qe, self._tangent)


class DamageProblem(ContinuumProblem):
    """Local continuum damage (no regularisation; mesh-dependent, for comparison), and the base of the
    regularised formulations.

    Dirichlet conditions are homogeneous (eliminated dofs); the structure is loaded by a force pattern
    scaled by the load factor lambda (so lambda is the applied force in N for a unit pattern). Which
    quantity is prescribed (an end displacement, an elongation, a CMOD) is a named linear functional of
    the displacements chosen at solve time, so snap-back can be traced by indirect displacement control.

    Parameters
    ----------
    disc : MixedDiscretization
    law : DamageLaw
        Softening law and equivalent strain.
    params
        The law's parameters (an instance of ``law.parameters``).
    conditions : Conditions
    stiffness_factor, damageable
        As for :class:`ContinuumProblem`.
    symmetry_planes : sequence of (axis, coordinate)
        Symmetry planes x[axis] = coordinate [mm] of a half or quarter model (used by the integral
        formulation, whose average reaches across the plane).
    """

    def __init__(self, disc: MixedDiscretization, law: DamageLaw, params, conditions: Conditions, *,
                 stiffness_factor=1.0, damageable=1.0, symmetry_planes=()):
        if not isinstance(params, law.parameters):
            raise TypeError(f"params must be {law.parameters.__name__}, got {type(params).__name__}")
        self.law = law
        super().__init__(disc, params, conditions, stiffness_factor=stiffness_factor, damageable=damageable)
        self.symmetry_planes = tuple(symmetry_planes)

    def onset_ratio(self, kappa: np.ndarray) -> float:
        """Largest history variable relative to the damage threshold (< 1: still undamaged)."""
        return float(kappa.max()) / self.law.softening.onset(self.params)

    def _element_arrays(self, qe, kappa_old):
        return local_damage(self.disc, self.law, self.params, self.const, qe, kappa_old, self._tangent)

    # direct differentiation (docs/theory.md, section 6): the formulations differ only by their
    # driving strain (local eps_eq, its average, or the nodal ebar) and the ebar equation's rows

    @property
    def differentiable(self) -> tuple:
        """Parameters this problem differentiates with respect to: all of the law's, if the law gives
        its parameter derivatives (none otherwise)."""
        return tuple(self.law.parameters.names()) if self.law.differentiable else ()

    def differentiate(self, q, kappa_old, kappa_old_rate, names) -> "ds.StepDerivative":
        """The pseudo-load of a converged step and how to complete its derivatives (see
        :class:`~fracid.fem.formulations.damage_sensitivity.StepDerivative`)."""
        names = ds.check_names(names, self.differentiable)
        qe, n_u = self.gather(q), self.dofs.n_u
        driving, eps, eq, d_eq = self._driving(qe)
        loading = driving >= kappa_old
        kappa = np.where(loading, driving, kappa_old)
        omega, d_omega = masked_damage(self.law, self.params, self.const, kappa)
        law_rate = ds.damage_parameter_derivatives(self.law, self.params, self.const, kappa, names)
        explicit = self._driving_parameter_rate(eps, eq, names)
        omega_rate = law_rate + d_omega[..., None] * np.where(loading[..., None], explicit, kappa_old_rate)
        ue = qe[:, :n_u]
        stress = ds.unit_stress_forces(self.disc, self.const, ue)  # shared by the pseudo-load and the energy
        force = ds.equilibrium_pseudo_load(self.disc, self.params, self.const, ue, omega, omega_rate, names, stress)
        pseudo_load = self.assemble_columns(self._with_field_rows(force, qe, eps, names))

        def complete(dq):
            dqe = self.gather_columns(dq)
            rate = ds.history_derivative(loading, self._driving_response(dqe, eps, d_eq) + explicit, kappa_old_rate)
            total_omega = law_rate + d_omega[..., None] * rate
            energy = ds.elastic_energy_derivative(self.disc, self.params, self.const, ue, dqe[:, :n_u], omega,
                                                  total_omega, names, stress)
            return rate, self.symmetry_factor * energy

        return ds.StepDerivative(pseudo_load, complete)

    def _strain(self, qe):
        """The strain at every point (n_el, n_q, n_strain) of element dof values ``qe``."""
        return strain_of(self.disc.strain_operator, qe[:, : self.dofs.n_u])

    def _driving(self, qe):
        """The strain that drives kappa at every point, the strain, eps_eq and d eps_eq / d eps (these two
        None where the formulation's derivatives do not use them)."""
        eps = self._strain(qe)
        eq, d_eq = self.law.equivalent_strain(self.disc.strain_state, eps, self.params)
        return eq, eps, eq, d_eq

    def _driving_parameter_rate(self, eps, eq, names):
        """d driving / d x at fixed q, (n_el, n_q, p)."""
        return ds.equivalent_strain_parameter_derivatives(self.law, self.params, self.disc.strain_state, eps, names)

    def _driving_response(self, dqe, eps, d_eq):
        """d driving / d q . q' at every point, (n_el, n_q, p), for element dof rates ``dqe`` (n_el, n_dof_el, p)."""
        return np.einsum("eqs,eqsi,eip->eqp", d_eq, self.disc.strain_operator, dqe[:, : self.dofs.n_u])

    def _with_field_rows(self, force, qe, eps, names):
        """Element pseudo-loads of all dofs from those of equilibrium (the ebar rows of the gradient model)."""
        return force


class GradientDamageProblem(DamageProblem):
    """Implicit gradient-enhanced damage: the nonlocal strain ebar is a nodal field on the element
    corners solving ebar - c laplacian(ebar) = eps_eq (natural boundary condition, which is also the
    symmetry condition)."""

    field_specs = (FieldSpec("ebar", "linear"),)

    def __init__(self, disc, law, params, conditions, **options):
        super().__init__(disc, law, params, conditions, **options)
        e = self.dofs.columns["ebar"]
        self._tangent[:, e, e] = self.const.ebar_matrix

    def _gradient_space(self):
        return self.disc.space(self.field_specs[0].space)

    def _ebar(self, qe):
        """The element values of ebar (n_el, n_e, ...) of element dof values ``qe``."""
        return qe[:, self.dofs.columns["ebar"]]

    def _driving(self, qe):
        # kappa follows the nodal unknown ebar: its derivatives need neither eps_eq nor d eps_eq / d eps
        return self._ebar(qe) @ self._gradient_space().shape.T, self._strain(qe), None, None

    def _driving_parameter_rate(self, eps, eq, names):
        return np.zeros(eps.shape[:-1] + (len(names),))  # kappa follows the nodal unknown ebar

    def _driving_response(self, dqe, eps, d_eq):
        return np.einsum("eip,qi->eqp", self._ebar(dqe), self._gradient_space().shape)

    def _with_field_rows(self, force, qe, eps, names):
        # r_ebar = (M + c K_g) ebar - int N^T eps_eq
        disc, space, ee = self.disc, self._gradient_space(), self._ebar(qe)
        eq_rate = ds.equivalent_strain_parameter_derivatives(self.law, self.params, disc.strain_state, eps, names)
        rows = -np.matmul(space.shape.T, disc.weights[..., None] * eq_rate)  # -int N^T d eps_eq / d x
        if "c" in names:
            rows[..., names.index("c")] += np.einsum("eij,ej->ei", self._gradient_matrix(), ee)
        return np.concatenate([force, rows], axis=1)

    def _gradient_matrix(self):
        """int grad N^T grad N per element (n_el, n_e, n_e), d/dc of the diffusion matrix: built at the
        first derivative asked for, then kept (the plain runs never need it)."""
        if getattr(self, "_gradient_matrix_cache", None) is None:
            self._gradient_matrix_cache = gradient_matrix(self._gradient_space(), self.disc.weights)
        return self._gradient_matrix_cache

    def _element_arrays(self, qe, kappa_old):
        u = self.dofs.columns["u"]
        return gradient_damage(self.disc, self._gradient_space(), self.law, self.params, self.const, qe[:, u],
                               self._ebar(qe), kappa_old, self._tangent)


class IntegralDamageProblem(DamageProblem):
    """Integral-type nonlocal damage: a Gaussian average of internal length l = sqrt(2 c) of the local
    equivalent strain over the integration points (built once here, mirrored across the symmetry planes)."""

    def __init__(self, disc, law, params, conditions, **options):
        super().__init__(disc, law, params, conditions, **options)
        self.averaging = nonlocal_averaging(disc, internal_length(params.c), self.element_dofs, self.n_free,
                                            mirror=self.symmetry_planes)

    def _element_arrays(self, qe, kappa_old):
        return integral_damage(self.disc, self.law, self.params, self.const, qe, kappa_old, self._tangent,
                               self.averaging)

    def _average(self, point_values):
        """A applied to each column of (n_el, n_q, p) point values."""
        flat = point_values.reshape(-1, point_values.shape[-1])
        return (self.averaging.matrix @ flat).reshape(point_values.shape)

    def _driving(self, qe):
        _, eps, eq, d_eq = super()._driving(qe)
        return (self.averaging.matrix @ eq.ravel()).reshape(eq.shape), eps, eq, d_eq

    def _driving_parameter_rate(self, eps, eq, names):
        rate = self._average(super()._driving_parameter_rate(eps, eq, names))
        if "c" in names:  # l = sqrt(2 c): dA/dc = dA/dl / l
            length = internal_length(self.params.c)
            if getattr(self, "_length_derivative", None) is None:
                n_el, n_q = self.disc.weights.shape
                self._length_derivative = averaging_length_derivative(
                    self.disc.points.reshape(n_el * n_q, -1), self.disc.weights.ravel(), length,
                    mirror=self.symmetry_planes)
            rate[..., names.index("c")] += (self._length_derivative @ eq.ravel()).reshape(eq.shape) / length
        return rate

    def _driving_response(self, dqe, eps, d_eq):
        return self._average(super()._driving_response(dqe, eps, d_eq))


# formulation name of the model registry -> problem class
FORMULATIONS = {"gradient": GradientDamageProblem, "local": DamageProblem, "integral": IntegralDamageProblem}
