"""Element residuals and consistent tangents of the damage models, for all elements at once.

Pure functions over the arrays of a :class:`~fracid.fem.mesh.discretization.MixedDiscretization`:
the material law enters only through a :class:`~fracid.fem.material.laws.DamageLaw` (its softening law and
equivalent strain, values and derivatives) and the history update
:func:`~fracid.fem.material.damage.update_history`.
"""

from __future__ import annotations

import functools
from typing import NamedTuple

import numpy as np

from fracid.fem.material.damage import update_history
from fracid.fem.formulations.nonlocal_average import NonlocalAveraging, bounded_average, softening_coupling


class ElementArrays:
    """Element vectors and matrices of one evaluation, the trial history and the formulation's outputs.

    Parameters
    ----------
    residual : ndarray, shape (n_el, n_dof_el)
        Element internal forces, in the columns of the dof map (displacements first, then each
        named field's).
    tangent : ndarray, shape (n_el, n_dof_el, n_dof_el), or callable
        The element tangents; a function of no argument is called at the first access (an iteration
        of modified Newton needs only the residual; the tangent is half the cost of an evaluation).
        It fills the problem's tangent buffer, so it must be taken before the next evaluation.
    reference : dict {field: ndarray, shape (n_el, n_dof_el of the field)}
        Per field, the element vectors whose assembled norm scales that field's residual.
    history : ndarray or dict of ndarray, or callable
        The trial history at this state, in the layout the problem declares (its ``history_spec``):
        the solver carries it opaquely to the next step. A function of no argument is called at the
        first access (the integral model's needs the average at every point, the residual only near
        the damaged zone).
    coupling : sparse matrix (n_free, n_free), callable or None, optional
        Tangent entries between points of different elements (the integral model) [N/mm]; like the
        tangent, a function of no argument is called at the first access (only the iterations that
        factorize need it, and it costs far more than the residual).
    outputs : dict {name: ndarray}, optional
        Named point outputs the formulation derives from the state (damage, stress, ...).
    """

    __slots__ = ("residual", "_tangent", "reference", "_history", "outputs", "_coupling")

    def __init__(self, residual, tangent, reference, history, *, coupling=None, outputs=None):
        self.residual, self._tangent, self.reference = residual, tangent, reference
        self._history, self._coupling = history, coupling
        self.outputs = dict(outputs or {})

    @property
    def tangent(self) -> np.ndarray:
        if callable(self._tangent):
            self._tangent = self._tangent()
        return self._tangent

    @property
    def history(self):
        if callable(self._history):
            self._history = self._history()
        return self._history

    @property
    def coupling(self):
        if callable(self._coupling):
            self._coupling = self._coupling()
        return self._coupling

    @property
    def omega(self) -> np.ndarray:
        """The point output ``"omega"`` (damage) of the formulations that give one."""
        if "omega" not in self.outputs:
            raise AttributeError(f"these element arrays have no point output 'omega'; outputs: {sorted(self.outputs)}")
        return self.outputs["omega"]

    def _replace(self, **changes) -> "ElementArrays":
        """A copy with some of the constructor's arguments changed."""
        values = dict(residual=self.residual, tangent=self._tangent, reference=self.reference, history=self._history,
                      coupling=self._coupling, outputs=self.outputs)
        values.update(changes)
        return ElementArrays(**values)


def point_outputs(arrays) -> dict:
    """The named point outputs of :class:`ElementArrays`, or ``{"omega": arrays}`` for a bare damage
    array (what ``fields`` and ``elastic_energy`` were given before named outputs)."""
    return arrays.outputs if isinstance(arrays, ElementArrays) else {"omega": arrays}


class ModelConstants(NamedTuple):
    """What the kernels need besides the current state: built once per problem."""

    E: np.ndarray  # Young's modulus at every integration point [MPa], (n_el, n_q)
    D: np.ndarray  # unit elastic matrix (n_strain, n_strain)
    DB: np.ndarray  # D times the strain operator, (n_el, n_q, n_strain, n_u)
    ebar_matrix: np.ndarray  # int N^T N + c grad N^T grad N, (n_el, n_e, n_e): constant (None without the gradient field)
    damageable: np.ndarray  # 1 where the material can damage, 0 in elastic parts (platens), (n_el, n_q)


def model_constants(disc, params, stiffness_factor, damageable=1.0, gradient_space=None) -> ModelConstants:
    """Precompute the parts of the tangent that do not change during a computation (with
    ``gradient_space``, a :class:`~fracid.fem.mesh.discretization.ScalarSpace`: also the matrix of the
    gradient model's diffusion equation on it, which needs ``params.c``)."""
    E = params.E * np.broadcast_to(stiffness_factor, disc.weights.shape)
    mask = np.broadcast_to(np.asarray(damageable, dtype=float), disc.weights.shape)
    D = disc.strain_state.unit_elastic_matrix(params.nu)
    DB = np.einsum("st,eqtj->eqsj", D, disc.strain_operator)
    M = None
    if gradient_space is not None:
        N, w = gradient_space.shape, disc.weights
        M = np.einsum("eq,qi,qj->eij", w, N, N) + params.c * gradient_matrix(gradient_space, w)
    return ModelConstants(E, D, DB, M, mask)


def gradient_matrix(space, weights) -> np.ndarray:
    """int grad N^T grad N of a scalar field at every element: the part of the diffusion equation's
    matrix that ``c`` multiplies.

    Parameters
    ----------
    space : ScalarSpace
        The field's interpolation (its ``gradient``, shape (n_el, n_q, dim, n_e)).
    weights : ndarray, shape (n_el, n_q)
        The integration weights.

    Returns
    -------
    ndarray, shape (n_el, n_e, n_e)
    """
    G = space.gradient
    return np.einsum("eq,eqdi,eqdj->eij", weights, G, G)


def btdb(weighted_B, DB):
    """Sum over the points and strain components of B^T (D B): the element stiffness.

    Parameters
    ----------
    weighted_B : ndarray, shape (n_el, n_q, n_strain, n_u)
        The strain operator times the point weights (and the secant modulus).
    DB : ndarray, shape (n_el, n_q, n_strain, n_u)
        The elastic matrix times the strain operator.

    Returns
    -------
    ndarray, shape (n_el, n_u, n_u)
    """
    # a batched matmul, 6x faster than einsum here
    n_el, n_u = DB.shape[0], DB.shape[-1]
    return np.matmul(weighted_B.reshape(n_el, -1, n_u).transpose(0, 2, 1), DB.reshape(n_el, -1, n_u))


def strain_of(B, ue):
    """B u at every integration point (a batched product over the points of each element; 1.5x faster than
    the equivalent einsum).

    Parameters
    ----------
    B : ndarray, shape (n_el, n_q, n_strain, n_u)
        A strain operator (or the elastic matrix times it).
    ue : ndarray, shape (n_el, n_u)

    Returns
    -------
    ndarray, shape (n_el, n_q, n_strain)
    """
    n_el, n_q, n_s, n_u = B.shape
    return np.matmul(B.reshape(n_el, n_q * n_s, n_u), ue[:, :, None]).reshape(n_el, n_q, n_s)


def bt_sum(B, values):
    """sum over the points and strain components of B^T v: the element vectors of point values.

    Parameters
    ----------
    B : ndarray, shape (n_el, n_q, n_strain, n_u)
    values : ndarray, shape (n_el, n_q, n_strain)
        Point values, the integration weights included.

    Returns
    -------
    ndarray, shape (n_el, n_u)
    """
    n_el, n_q, n_s, n_u = B.shape
    return np.matmul(values.reshape(n_el, 1, n_q * n_s), B.reshape(n_el, n_q * n_s, n_u))[:, 0, :]


def bt(vector, B):
    """B^T v at every integration point.

    Parameters
    ----------
    vector : ndarray, shape (n_el, n_q, n_strain)
    B : ndarray, shape (n_el, n_q, n_strain, n_u)

    Returns
    -------
    ndarray, shape (n_el, n_q, n_u)
    """
    return np.matmul(vector[..., None, :], B)[..., 0, :]


def masked_damage(law, params, const, kappa):
    """The damage and its derivative d omega / d kappa of ``law`` at every point, zero where the material
    cannot damage (``const.damageable``).

    Parameters
    ----------
    law : DamageLaw
    params : parameter object of the law
    const : ModelConstants
    kappa : ndarray, shape (n_el, n_q)
        The history variable.

    Returns
    -------
    omega, d_omega : ndarray, shape (n_el, n_q)
    """
    omega, d_omega = law.damage(kappa, params)
    return omega * const.damageable, d_omega * const.damageable


def _secant_equilibrium(B, const, w, ue, omega):
    """Shared by the models: D eps at the points (stress per unit E), the internal forces and the weights
    of the secant stiffness (``btdb(B * w_sec, DB)``). ``bt(sigma_eff, B)``, the points' share of the
    forces, is left to the tangents that need it: a residual does not."""
    sigma_eff = strain_of(const.DB, ue)
    w_sec = w * (1.0 - omega) * const.E
    return sigma_eff, bt_sum(B, sigma_eff * w_sec[..., None]), w_sec


def _secant(B, const, w_sec):
    return btdb(B * w_sec[..., None, None], const.DB)


def gradient_damage(disc, space, law, params, const: ModelConstants, ue, ee, kappa_old, out_tangent) -> ElementArrays:
    """Implicit gradient-enhanced damage: residuals of equilibrium and of the diffusion equation.

    Parameters
    ----------
    space : ScalarSpace
        The interpolation of the nonlocal strain ebar.
    law : DamageLaw
    params
        The law's parameters (``E``, ``nu`` and ``c`` besides the law's own).
    ue, ee : ndarray, shape (n_el, n_u) and (n_el, n_e)
        Element displacements [mm] and nonlocal strains [-].
    kappa_old : ndarray, shape (n_el, n_q)
        History variable at the end of the last converged step.
    out_tangent : ndarray, shape (n_el, n_u + n_e, n_u + n_e)
        Buffer for the element tangents; its ebar-ebar block must already hold ``const.ebar_matrix``.
    """
    B, N, w = disc.strain_operator, space.shape, disc.weights
    nu = B.shape[-1]
    eps = strain_of(B, ue)
    ebar = ee @ N.T
    eq, d_eq = law.equivalent_strain(disc.strain_state, eps, params)
    kappa, loading = update_history(kappa_old, ebar)
    omega, d_omega = masked_damage(law, params, const, kappa)
    sigma_eff, f_u, w_sec = _secant_equilibrium(B, const, w, ue, omega)
    f_eq = (w * eq) @ N
    f_e = np.matmul(const.ebar_matrix, ee[:, :, None])[:, :, 0] - f_eq

    def tangent():
        out_tangent[:, :nu, :nu] = _secant(B, const, w_sec)
        w_ue = -(w * const.E * d_omega * loading)
        out_tangent[:, :nu, nu:] = np.matmul((bt(sigma_eff, B) * w_ue[..., None]).transpose(0, 2, 1), N)
        out_tangent[:, nu:, :nu] = -np.matmul(N.T, bt(d_eq * w[..., None], B))
        return out_tangent

    return ElementArrays(np.concatenate([f_u, f_e], axis=1), tangent, {"u": f_u, "ebar": f_eq}, kappa,
                         outputs={"omega": omega})


def local_damage(disc, law, params, const: ModelConstants, ue, kappa_old, out_tangent) -> ElementArrays:
    """Local damage (no regularisation): kappa follows the local equivalent strain; mesh-dependent."""
    B, w = disc.strain_operator, disc.weights
    eps = strain_of(B, ue)
    eq, d_eq = law.equivalent_strain(disc.strain_state, eps, params)
    kappa, loading = update_history(kappa_old, eq)
    omega, d_omega = masked_damage(law, params, const, kappa)
    sigma_eff, f_u, w_sec = _secant_equilibrium(B, const, w, ue, omega)

    def tangent():
        softening = np.matmul((bt(sigma_eff, B) * (w * const.E * d_omega * loading)[..., None]).transpose(0, 2, 1),
                              bt(d_eq, B))
        out_tangent[:] = _secant(B, const, w_sec) - softening
        return out_tangent

    return ElementArrays(f_u, tangent, {"u": f_u}, kappa, outputs={"omega": omega})


def integral_damage(disc, law, params, const: ModelConstants, ue, kappa_old, out_tangent, averaging: NonlocalAveraging) -> ElementArrays:
    """Integral-type nonlocal damage: kappa follows the Gaussian average ebar = A eps_eq of the
    local equivalent strain (see :mod:`fracid.fem.formulations.nonlocal_average`).

    Parameters
    ----------
    ue : ndarray, shape (n_el, n_u)
        Element displacements [mm].
    kappa_old : ndarray, shape (n_el, n_q)
        History variable at the end of the last converged step [-].
    out_tangent : ndarray, shape (n_el, n_u, n_u)
        Buffer for the element tangents.
    averaging : NonlocalAveraging
        The averaging matrix of the mesh and the map of the points to the free dofs.

    Returns
    -------
    ElementArrays
        The element tangent is the secant stiffness minus the softening of each point driven by its
        own strain (A_ii); ``coupling`` is the rest of the consistent tangent, - G A_offdiag H over
        the free dofs, which couples points of different elements (None while nothing softens).
    """
    B, w = disc.strain_operator, disc.weights
    eps = strain_of(B, ue)
    eq, d_eq = law.equivalent_strain(disc.strain_state, eps, params)
    # the damage needs the average only where it can reach the history and the onset (elsewhere kappa
    # stays and omega with it); the history itself, at every point, is built once the step converged
    floor = np.where(const.damageable > 0.0, np.maximum(kappa_old, law.softening.onset(params)), np.inf)
    rows, ebar = bounded_average(averaging, eq.ravel(), floor.ravel())
    kappa, loading = kappa_old.copy(), np.zeros(kappa_old.shape, dtype=bool)
    kappa.flat[rows], loading.flat[rows] = update_history(kappa_old.ravel()[rows], ebar)
    omega, d_omega = masked_damage(law, params, const, kappa)
    sigma_eff, f_u, w_sec = _secant_equilibrium(B, const, w, ue, omega)

    @functools.cache  # shared by the element tangent and the coupling (and a copy of these arrays)
    def softening():
        g = bt(sigma_eff, B) * (w * const.E * d_omega * loading)[..., None]  # d f_u / d ebar at each point
        return g, bt(d_eq, B)  # and d eps_eq / d u at each point

    def tangent():
        g, h = softening()
        out_tangent[:] = _secant(B, const, w_sec) - np.matmul((g * averaging.self_weight[..., None]).transpose(0, 2, 1), h)
        return out_tangent

    @functools.cache
    def coupling():
        return softening_coupling(averaging, *softening(), loading & (d_omega > 0.0))

    # both tangent parts are built only when an iteration factorizes (most iterations of modified
    # Newton need the residual alone)
    @functools.cache
    def history():
        return update_history(kappa_old, (averaging.matrix @ eq.ravel()).reshape(eq.shape))[0]

    return ElementArrays(f_u, tangent, {"u": f_u}, history, coupling=coupling, outputs={"omega": omega})


def elastic_energy(disc, const: ModelConstants, ue, omega) -> float:
    """Recoverable energy 1/2 int (1 - omega) E eps . D eps dV [N mm]."""
    eps = strain_of(disc.strain_operator, ue)
    sigma_eff = strain_of(const.DB, ue)
    return 0.5 * float(np.sum(disc.weights * (1.0 - omega) * const.E * np.sum(eps * sigma_eff, axis=-1)))


def elastic_bulk(disc, const: ModelConstants, ue, out_tangent) -> ElementArrays:
    """Linear elastic material (the bulk of a discrete-crack model): internal forces and stiffness."""
    _, f_u, w_sec = _secant_equilibrium(disc.strain_operator, const, disc.weights, ue, np.zeros(disc.weights.shape))
    out_tangent[:] = _secant(disc.strain_operator, const, w_sec)
    no_history = np.zeros(disc.weights.shape)
    return ElementArrays(f_u, out_tangent, {"u": f_u}, no_history, outputs={"omega": no_history})
