"""A discrete cohesive crack along a symmetry line: elastic bulk plus a traction-separation law on the crack.

The crack of a symmetric half model lies on its symmetry line (the ligament of a notched beam, the
mid-height section of a dog-bone). Its opening is twice the normal displacement of the nodes on
that line. Before cracking the crack faces are tied
by a stiff penalty (sigma = k w up to ft, at w0 = ft / k); beyond, the traction follows the law
(:class:`~fracid.fem.material.tsl.TractionSeparationLaw`, Hordijk's by default) of the opening in excess of w0
(secant unloading, :func:`~fracid.fem.material.tsl.secant_unloading`);
closure (w < 0) is resisted by the same penalty. The crack edges' nodal forces and tangents are
added to the element arrays of the bulk elements that own the edges, so the problem keeps the
element structure (one sparse pattern) the nonlinear solver expects.
"""

from __future__ import annotations

import numpy as np

from fracid.fem.formulations import damage_sensitivity as ds
from fracid.fem.mesh.assembly import assemble_vector
from fracid.fem.mesh.elements import gauss_line, line_quadratic
from fracid.fem.mesh.level_sets import superlevel_length
from fracid.fem.formulations.problem import ElasticProblem
from fracid.fem.formulations.protocol import HistoryVariable
from fracid.fem.material.tsl import differentiable, secant_unloading, secant_unloading_parameter_derivatives

_GAUSS = 3


def crack_edges(nodes, cells, u_dofs, path_nodes, normal: int):
    """Element edges lying on a crack path: the owning element, the positions of the three edge nodes'
    normal dofs in its dof row (ordered along the path), the nodes' coordinates along the path [mm] and
    the side of the path the element lies on (+1 or -1 along ``normal``).

    Parameters
    ----------
    nodes, cells : ndarray
        Mesh (8-node quadrilaterals or 6-node triangles).
    u_dofs : ndarray of int, shape (n_el, n_u)
        Displacement dofs of each element.
    path_nodes : array_like of int
        The nodes on the crack path (a straight line x[normal] = const).
    normal : int
        Axis normal to the path (0: x, 1: y).
    """
    on_path = np.zeros(len(nodes), dtype=bool)
    on_path[np.asarray(path_nodes, dtype=int)] = True
    along = 1 - normal
    owners, slots, positions, sides = [], [], [], []
    for el, cell in enumerate(cells):
        on_line = [n for n in cell if on_path[n]]
        if len(on_line) != 3:
            continue
        on_line.sort(key=lambda n: nodes[n, along])
        owners.append(el)
        slots.append([int(np.flatnonzero(u_dofs[el] == 2 * n + normal)[0]) for n in on_line])
        positions.append(nodes[on_line, along])
        sides.append(np.sign(nodes[cell, normal].mean() - nodes[on_line[0], normal]))
    if not owners:
        raise ValueError("no element edge lies on the crack path (three nodes of an edge in its node set)")
    return np.array(owners), np.array(slots), np.array(positions), np.array(sides)


def penalty_crack_traction(w, w_max, w0, penalty, envelope):
    """Traction [MPa], its derivative [MPa/mm] and the new history for openings w [mm] of a crack whose
    faces are tied by a penalty until they separate at w0 [mm].

    Penalty branch sigma = penalty * w while uncracked (w_max <= w0 and w <= w0) or closed (w < 0);
    beyond, the law's ``envelope`` of w - w0 with secant unloading
    (:func:`~fracid.fem.material.tsl.secant_unloading`; 0 traction between 0 and w0 once cracked).
    """
    cracked = (w_max > w0) | (w > w0)
    s, dsdw, _ = secant_unloading(np.maximum(w - w0, 0.0), np.maximum(w_max - w0, 0.0), envelope)
    open_side = np.where(w > w0, dsdw, 0.0)
    sigma = np.where(w < 0, penalty * w, np.where(cracked, np.where(w > w0, s, 0.0), penalty * w))
    tangent = np.where(w < 0, penalty, np.where(cracked, open_side, penalty))
    return sigma, tangent, np.maximum(w_max, w)


def law_crack_traction(law, params, w, w_max, penalty):
    """:func:`penalty_crack_traction` of a traction-separation law ``law`` with parameters ``params``
    (w0 = ft / penalty, ft = ``law.strength(params)``)."""
    return penalty_crack_traction(w, w_max, law.strength(params) / penalty, penalty,
                                  lambda v: law.traction(v, params))


def crack_traction_parameter_derivatives(law, w, w_max, params, penalty, penalty_rates):
    """Derivatives of the traction of :func:`law_crack_traction` at fixed opening w and history w_max.

    Parameters
    ----------
    law : TractionSeparationLaw
        With ``parameter_derivatives``.
    w, w_max : ndarray
        Openings and largest openings reached before the step [mm].
    params : ParameterSet
        The law's parameters (and E, nu of the bulk).
    penalty : float
        [MPa/mm].
    penalty_rates : dict {name: float}
        d penalty / d name for the parameters the penalty depends on.

    Returns
    -------
    rates : dict {name: ndarray}
        d sigma / d name at fixed w and w_max for every parameter of ``params`` [MPa per unit
        parameter]. The penalty branch moves with the penalty; the cracked branch, the law of w - w0
        (w0 = ft / penalty), with the law's parameters and with w0 (ft's derivatives are the
        traction's at w = 0).
    d_sigma_d_w_max : ndarray
        [MPa/mm], nonzero where a cracked point unloads (secant branch).
    """
    w0 = law.strength(params) / penalty
    strength_rates = law.parameter_derivatives(np.zeros(1), params)
    cracked = (w_max > w0) | (w > w0)
    penalty_branch = (w < 0) | ~cracked
    open_side = cracked & (w > w0)
    e, m = np.maximum(w - w0, 0.0), np.maximum(w_max - w0, 0.0)
    envelope = lambda v: law.traction(v, params)  # noqa: E731
    law_rates, d_m = secant_unloading_parameter_derivatives(e, m, envelope,
                                                            lambda v: law.parameter_derivatives(v, params))
    _, d_e, _ = secant_unloading(e, m, envelope)
    rates = {}
    for name in params.names():
        d_penalty = penalty_rates.get(name, 0.0)
        d_ft = float(strength_rates[name][0]) if name in strength_rates else 0.0
        d_w0 = (d_ft - w0 * d_penalty) / penalty
        # both e = w - w0 and m = w_max - w0 move by -w0' (m only matters where the point unloads)
        cracked_rate = law_rates.get(name, 0.0) - (d_e + d_m) * d_w0
        rates[name] = np.where(penalty_branch, d_penalty * w, np.where(open_side, cracked_rate, 0.0))
    return rates, np.where(open_side, d_m, 0.0)


class CohesiveCrackProblem(ElasticProblem):
    """An elastic plane-stress bulk with a cohesive crack on a symmetry line of a half model.

    Parameters
    ----------
    disc : MixedDiscretization
    law : TractionSeparationLaw
        E.g. :class:`~fracid.fem.material.laws.HordijkLaw`.
    params : ParameterSet
        E, nu of the bulk and the law's parameters (``law.parameters``).
    conditions : Conditions
        Without a symmetry condition on the crack path's normal dofs.
    edges : tuple
        Output of :func:`crack_edges`.
    thickness : float
        [mm].
    penalty : float
        Stiffness tying the uncracked faces [MPa/mm].
    stiffness_factor : float or ndarray
        Young's modulus relative to ``params.E`` at the integration points [-].
    penalty_follows_E : bool
        Whether the penalty is proportional to E (the model's ``penalty_factor * E / h``), so that a
        derivative with respect to E moves it too (:meth:`differentiate`); False holds it fixed.
    """

    #: parameters :meth:`differentiate` differentiates with respect to with Hordijk's law (all of
    #: CohesiveParameters); an instance's are all of its ``params`` if its law gives parameter derivatives
    differentiable = ("E", "nu", "ft", "Gf", "c1", "c2")

    def __init__(self, disc, law, params, conditions, edges, thickness, penalty, *, stiffness_factor=1.0,
                 penalty_follows_E=True):
        super().__init__(disc, params, conditions, stiffness_factor=stiffness_factor)
        self.law, self.penalty = law, float(penalty)
        self.differentiable = tuple(params.names()) if differentiable(law) else ()
        self.penalty_rates = {"E": self.penalty / params.E} if penalty_follows_E else {}
        self.owners, self.slots, positions, self.sides = edges
        s, weights = gauss_line(_GAUSS)
        self.N = line_quadratic(s)[0]  # (n_g, 3), nodes ordered along the path
        jac = 0.5 * (positions[:, 2] - positions[:, 0])
        self.dA = thickness * jac[:, None] * weights[None, :]  # crack area per edge Gauss point [mm^2]
        self.y = positions[:, [0]] + (1.0 + s[None, :]) * jac[:, None]  # Gauss points along the path [mm]

    @property
    def history_spec(self) -> dict:
        """The largest opening reached at each crack Gauss point [mm], shape (n_edges, n_g)."""
        return {"crack_opening_max": HistoryVariable(points=self.dA.shape)}

    def openings(self, q):
        """Crack opening at the Gauss points [mm]: twice the normal displacement away from the line."""
        u_n = self.gather(q)[self.owners[:, None], self.slots] * self.sides[:, None]  # (n_edges, 3)
        return 2.0 * u_n @ self.N.T  # (n_edges, n_g)

    def onset_ratio(self, w_max):
        return float(w_max.max()) * self.penalty / self.law.strength(self.params)

    def _traction(self, w, w_max_old):
        return law_crack_traction(self.law, self.params, w, w_max_old, self.penalty)

    def evaluate(self, q, w_max_old):
        residual, arrays, references = super().evaluate(q, None)
        w = self.openings(q)
        sigma, dsigma, w_max = self._traction(w, w_max_old)
        # nodal forces on the half: int N_a sigma dA; d/d u_b: int N_a N_b dsigma/dw * 2 dA
        force = np.einsum("eg,ga->ea", sigma * self.dA, self.N) * self.sides[:, None]
        stiffness = 2.0 * np.einsum("eg,ga,gb->eab", dsigma * self.dA, self.N, self.N)
        element_force = np.zeros((len(self.owners), self.element_dofs.shape[1]))
        np.put_along_axis(element_force, self.slots, force, axis=1)
        tangent = arrays.tangent
        rows = self.slots[:, :, None]
        cols = self.slots[:, None, :]
        tangent[self.owners[:, None, None], rows, cols] += stiffness
        residual = residual + assemble_vector(self.element_dofs[self.owners], element_force, self.n_free)
        return residual, arrays._replace(tangent=tangent, history=w_max), references

    def cracked_length(self, w_max) -> float:
        """Length of the crack path where the faces have separated (opening beyond w0) [mm]."""
        order = np.argsort(self.y.ravel())
        y, w = self.y.ravel()[order], w_max.ravel()[order]
        return superlevel_length(y, w, self.law.strength(self.params) / self.penalty, y[0], y[-1])

    def fields(self, q, w_max, arrays):
        out = super().fields(q, np.zeros(self.disc.weights.shape), arrays)
        out.update(crack_opening_max=w_max.copy())
        return out

    def elastic_energy(self, q, w_max, arrays):
        """Bulk strain energy plus the energy the crack gives back on unloading (penalty and secant) [N mm]."""
        w = self.openings(q)
        sigma, _, _ = self._traction(w, w_max)
        crack = 0.5 * np.sum(sigma * w * self.dA)  # w is the full opening: the crack of the whole specimen
        return super().elastic_energy(q, w_max, np.zeros(self.disc.weights.shape)) + crack

    # direct differentiation (fracid.fem.path.ddm): elastic bulk plus the interface's tractions

    def _edge_vectors(self, traction):
        """Element vectors (n_el, n_dof_el, p) of crack tractions (n_edges, n_g, p): int N_a t dA on the
        crack edges' normal dofs, zero elsewhere."""
        out = np.zeros(self.element_dofs.shape + traction.shape[-1:])
        force = np.einsum("egp,ga->eap", traction * self.dA[..., None], self.N) * self.sides[:, None, None]
        np.add.at(out, (self.owners[:, None], self.slots), force)
        return out

    def _opening_columns(self, dq):
        """Openings (n_edges, n_g, p) of p free-dof vectors dq (n_free, p)."""
        u_n = self.gather_columns(dq)[self.owners[:, None], self.slots] * self.sides[:, None, None]
        return 2.0 * np.einsum("eap,ga->egp", u_n, self.N)

    def differentiate(self, q, w_max_old, w_max_old_rate, names) -> "ds.StepDerivative":
        """The pseudo-load of a converged step and how to complete its derivatives (see
        :class:`~fracid.fem.formulations.damage_sensitivity.StepDerivative`); the history is the largest opening.

        The bulk's pseudo-load is that of an undamaged continuum (E, nu); the crack's, the traction's
        derivative at fixed opening and history (:func:`crack_traction_parameter_derivatives`), with
        the carried d w_max / d x where a cracked point unloads (secant branch). The opening has no
        explicit parameter dependence, so at loading points w_max' = w'. With the penalty
        proportional to E (``penalty_follows_E``), d/dE also moves the penalty and w0 = ft / penalty.

        Non-differentiable points, where the one-sided derivative of the branch the point is on is
        used: the crack tip, where a point's opening crosses w0 (the traction's parameter derivatives
        jump from the penalty branch to the law, e.g. d sigma / d ft from 0 to
        1 - sigma'(0) / penalty); the opening w - w0 = wc where the law's traction reaches zero (the
        derivative with respect to wc jumps to 0), a kink of the law (the bilinear law's w1); and w = w_max (loading or unloading). A point
        exactly on such a kink at a recorded step is rare; across steps the derivative stays
        one-sided per step (the path's derivative is then that of the branches the points are on).
        """
        names = ds.check_names(names, self.differentiable)
        p = len(names)
        ue = self.gather(q)[:, : self.dofs.n_u]
        no_damage = np.zeros(self.disc.weights.shape)
        no_damage_rate = np.zeros(no_damage.shape + (p,))
        bulk = ds.equilibrium_pseudo_load(self.disc, self.params, self.const, ue, no_damage, no_damage_rate, names)
        w = self.openings(q)
        sigma, tangent, _ = self._traction(w, w_max_old)
        rates, d_w_max = crack_traction_parameter_derivatives(self.law, w, w_max_old, self.params, self.penalty,
                                                              self.penalty_rates)
        loading = w >= w_max_old
        explicit = ds.stacked(rates, names, w.shape) + d_w_max[..., None] * w_max_old_rate
        pseudo_load = self.assemble_columns(bulk + self._edge_vectors(explicit))  # displacement dofs only

        def complete(dq):
            dw = self._opening_columns(dq)
            rate = ds.history_derivative(loading, dw, w_max_old_rate)
            d_sigma = explicit + tangent[..., None] * dw
            crack = 0.5 * np.einsum("egp,eg->p", d_sigma * w[..., None] + sigma[..., None] * dw, self.dA)
            due = self.gather_columns(dq)[:, : self.dofs.n_u]
            energy = ds.elastic_energy_derivative(self.disc, self.params, self.const, ue, due, no_damage,
                                                  no_damage_rate, names)
            return rate, self.symmetry_factor * energy + crack

        return ds.StepDerivative(pseudo_load, complete)
