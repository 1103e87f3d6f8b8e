"""Parameter derivatives of the continuum damage formulations, for the direct differentiation.

Pure functions over all integration points, beside the residuals and tangents of
:mod:`fracid.fem.formulations.forms`. At a converged step of a path, with the load factor and the control held,
the derivative z' = d(q, lambda)/dx of the state solves the step's bordered tangent system with the
right-hand side -dr/dx taken at fixed q (the *pseudo-load*). The history variable kappa = max(kappa_old,
driving) enters the pseudo-load by its explicit part: at loading points the parameter derivative of the
driving strain at fixed q, elsewhere the derivative kappa_old' carried from the last step
(docs/theory.md, section 6). After the solve, :func:`history_derivative` gives the new kappa'.

Units: the derivatives are per unit of each parameter (per MPa for E, per mm^2 for c, ...).
"""

from __future__ import annotations

import numpy as np

from fracid.fem.formulations.forms import bt, strain_of


def check_names(names, known) -> tuple:
    """``names`` as a tuple, or ValueError naming the unknown ones and the known."""
    names = tuple(names)
    unknown = [n for n in names if n not in known]
    if unknown:
        raise ValueError(f"cannot differentiate with respect to {unknown}: the parameters are {list(known)}")
    return names


def stacked(derivatives: dict, names, shape) -> np.ndarray:
    """The arrays ``derivatives[name]`` stacked on a last axis in the order of ``names`` (zeros for
    parameters the quantity does not depend on)."""
    out = np.zeros(tuple(shape) + (len(names),))
    for k, name in enumerate(names):
        if name in derivatives:
            out[..., k] = derivatives[name]
    return out


def damage_parameter_derivatives(law, params, const, kappa, names) -> np.ndarray:
    """d omega / d x at fixed kappa, shape kappa.shape + (p,) (zero where the material cannot damage)."""
    partial = law.softening.parameter_derivatives(kappa, params)
    return stacked(partial, names, kappa.shape) * const.damageable[..., None]


def equivalent_strain_parameter_derivatives(law, params, strain_state, eps, names) -> np.ndarray:
    """d eps_eq / d x at fixed strain, shape eps.shape[:-1] + (p,)."""
    return stacked(law.equivalent_strain.parameter_derivatives(strain_state, eps, params), names, eps.shape[:-1])


def unit_stress_forces(disc, const, ue):
    """B^T D eps at every point and the energy density eps . D eps, both per unit E.

    Parameters
    ----------
    disc : MixedDiscretization
    const : ModelConstants
    ue : ndarray, shape (n_el, n_u)
        Element displacements [mm].

    Returns
    -------
    bt_sigma : ndarray, shape (n_el, n_q, n_u)
        B^T D B ue at every point [N/mm^2 per unit E, times mm].
    density : ndarray, shape (n_el, n_q)
        eps . D eps = ue . B^T D eps at every point [per unit E].
    """
    bt_sigma = bt(strain_of(const.DB, ue), disc.strain_operator)
    return bt_sigma, np.einsum("eqi,ei->eq", bt_sigma, ue)


def _nu_stress_rate(disc, params, ue):
    """d(D)/d nu eps at every point (n_el, n_q, n_strain), per unit E, and the strain eps."""
    eps = strain_of(disc.strain_operator, ue)
    return np.einsum("st,eqt->eqs", disc.strain_state.unit_elastic_matrix_derivative(params.nu), eps), eps


def equilibrium_pseudo_load(disc, params, const, ue, omega, omega_rate, names, stress=None) -> np.ndarray:
    """d f_u / d x at fixed displacements, per element: shape (n_el, n_u, p) [N per unit parameter].

    f_u = sum_q w (1 - omega) E B^T D(nu) eps; ``omega_rate`` (n_el, n_q, p) is the explicit
    derivative of the damage (the law's, plus d omega / d kappa times the explicit kappa').
    ``stress``: :func:`unit_stress_forces` of ``ue`` when the caller has it (computed otherwise).
    """
    bt_sigma, _ = stress if stress is not None else unit_stress_forces(disc, const, ue)
    w_E = const.E * disc.weights
    intact = (1.0 - omega) * w_E
    factors = -omega_rate * w_E[..., None]  # (n_el, n_q, p)
    if "E" in names:
        factors[..., names.index("E")] += intact / params.E
    out = np.matmul(bt_sigma.transpose(0, 2, 1), factors)  # sum over the points, all parameters at once
    if "nu" in names:
        d_sigma, _ = _nu_stress_rate(disc, params, ue)
        out[..., names.index("nu")] += np.einsum("eqi,eq->ei", bt(d_sigma, disc.strain_operator), intact)
    return out


def elastic_energy_derivative(disc, params, const, ue, due, omega, omega_rate, names, stress=None) -> np.ndarray:
    """d/dx of the recoverable energy 1/2 int (1 - omega) E eps . D eps dV [N mm per unit parameter],
    given the total derivatives of the element displacements ``due`` (n_el, n_u, p) and of the damage
    ``omega_rate`` (n_el, n_q, p); ``stress`` as for :func:`equilibrium_pseudo_load`.

    The term of the displacements' derivatives, int (1 - omega) E eps' . D eps dV, is taken as the
    work of the element internal forces sum_q w (1 - omega) E B^T D eps on ``due`` (the same sum,
    without forming the strains' derivatives at the points).
    """
    bt_sigma, density = stress if stress is not None else unit_stress_forces(disc, const, ue)
    w_E = const.E * disc.weights
    intact = (1.0 - omega) * w_E
    internal = np.einsum("eqi,eq->ei", bt_sigma, intact)  # element internal forces
    out = -0.5 * np.einsum("eqp,eq->p", omega_rate, w_E * density) + np.einsum("eip,ei->p", due, internal)
    if "E" in names:
        out[names.index("E")] += 0.5 * np.sum(intact * density) / params.E
    if "nu" in names:
        d_sigma, eps = _nu_stress_rate(disc, params, ue)
        out[names.index("nu")] += 0.5 * np.sum(intact * np.sum(eps * d_sigma, axis=-1))
    return out


def history_derivative(loading, driving_rate, kappa_old_rate) -> np.ndarray:
    """kappa' after a step: the total derivative of the driving strain where the point loads, the
    previous kappa' where it unloads or stays (Kuhn-Tucker, as :func:`~fracid.fem.material.damage.update_history`)."""
    return np.where(loading[..., None], driving_rate, kappa_old_rate)


class StepDerivative:
    """The direct differentiation of one converged step, as a formulation gives it.

    Attributes
    ----------
    pseudo_load : ndarray, shape (n_free, p)
        d r / d x at the step's q, with kappa's explicit part (see the module docstring).
    complete : callable(dq) -> (history_rate, elastic_energy_rate)
        Given the solved q' (n_free, p): the new history derivative (history.shape + (p,)) and the
        derivative of the recoverable energy (p,) [N mm per unit parameter].
    """

    def __init__(self, pseudo_load, complete):
        self.pseudo_load, self.complete = pseudo_load, complete
