"""A discrete cohesive crack along a symmetry line: elastic bulk plus Hordijk tractions on the crack.

The crack of a symmetric half model lies on its symmetry line (the ligament of a notched beam, the
mid-height section of a dog-bone). Its opening is twice the normal displacement of the nodes on
that line. Before cracking the crack faces are tied
by a stiff penalty (sigma = k w up to ft, at w0 = ft / k); beyond, the traction follows Hordijk's law
of the opening in excess of w0 (secant unloading, :func:`~fracid.fem.cohesive.cohesive_traction`);
closure (w < 0) is resisted by the same penalty. The crack edges' nodal forces and tangents are
added to the element arrays of the bulk elements that own the edges, so the problem keeps the
element structure (one sparse pattern) the nonlinear solver expects.
"""

from __future__ import annotations

import numpy as np

from fracid.fem import damage_sensitivity as ds
from fracid.fem.assembly import assemble_vector
from fracid.fem.cohesive import cohesive_traction, cohesive_traction_parameter_derivatives
from fracid.fem.elements import gauss_line, line_quadratic
from fracid.fem.level_sets import superlevel_length
from fracid.fem.problem import ElasticProblem

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


def crack_traction(w, w_max, ft, wc, c1, c2, penalty):
    """Traction [MPa], its derivative [MPa/mm] and the new history for openings w [mm].

    Penalty branch sigma = penalty * w while uncracked (w_max <= w0 = ft / penalty) or closed (w < 0);
    Hordijk's law of w - w0 after cracking (0 traction between 0 and w0 once cracked).
    """
    w0 = ft / penalty
    cracked = (w_max > w0) | (w > w0)
    s, dsdw, s_max = cohesive_traction(np.maximum(w - w0, 0.0), np.maximum(w_max - w0, 0.0), ft, wc, c1, c2)
    open_side = np.where(w > w0, dsdw, 0.0)
    sigma = np.where(w < 0, penalty * w, np.where(cracked, np.where(w > w0, s, 0.0), penalty * w))
    tangent = np.where(w < 0, penalty, np.where(cracked, open_side, penalty))
    return sigma, tangent, np.maximum(w_max, w)


def crack_traction_parameter_derivatives(w, w_max, params, penalty, penalty_rates):
    """Derivatives of the traction of :func:`crack_traction` at fixed opening w and history w_max.

    Parameters
    ----------
    w, w_max : ndarray
        Openings and largest openings reached before the step [mm].
    params : CohesiveParameters
        The law's parameters (ft, wc, c1, c2 from ``params.law()``).
    penalty : float
        [MPa/mm].
    penalty_rates : dict {name: float}
        d penalty / d name for the parameters the penalty depends on.

    Returns
    -------
    rates : dict {"E", "nu", "ft", "Gf", "c1", "c2": ndarray}
        d sigma / d name at fixed w and w_max [MPa per unit parameter]. The penalty branch moves with
        the penalty; the cracked branch, Hordijk's law of w - w0 (w0 = ft / penalty), with the law's
        parameters and with w0.
    d_sigma_d_w_max : ndarray
        [MPa/mm], nonzero where a cracked point unloads (secant branch).
    """
    ft, wc, c1, c2 = params.law()
    w0 = ft / penalty
    cracked = (w_max > w0) | (w > w0)
    penalty_branch = (w < 0) | ~cracked
    open_side = cracked & (w > w0)
    e, m = np.maximum(w - w0, 0.0), np.maximum(w_max - w0, 0.0)
    law_rates, d_m = cohesive_traction_parameter_derivatives(e, m, ft, wc, c1, c2, params)
    _, d_e, _ = cohesive_traction(e, m, ft, wc, c1, c2)
    rates = {}
    for name in params.names():
        d_penalty = penalty_rates.get(name, 0.0)
        d_w0 = ((1.0 if name == "ft" else 0.0) - w0 * d_penalty) / penalty
        # both e = w - w0 and m = w_max - w0 move by -w0' (m only matters where the point unloads)
        cracked_rate = law_rates.get(name, 0.0) - (d_e + d_m) * d_w0
        rates[name] = np.where(penalty_branch, d_penalty * w, np.where(open_side, cracked_rate, 0.0))
    return rates, np.where(open_side, d_m, 0.0)


class CohesiveCrackProblem(ElasticProblem):
    """An elastic plane-stress bulk with a cohesive crack on a symmetry line of a half model.

    Parameters
    ----------
    disc : MixedDiscretization
    law : HordijkLaw
    params : CohesiveParameters
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

    #: parameters :meth:`differentiate` differentiates with respect to (all of CohesiveParameters)
    differentiable = ("E", "nu", "ft", "Gf", "c1", "c2")

    def __init__(self, disc, law, params, conditions, edges, thickness, penalty, *, stiffness_factor=1.0,
                 penalty_follows_E=True):
        super().__init__(disc, params, conditions, stiffness_factor=stiffness_factor)
        self.law, self.penalty = law, float(penalty)
        self.penalty_rates = {"E": self.penalty / params.E} if penalty_follows_E else {}
        self.owners, self.slots, positions, self.sides = edges
        s, weights = gauss_line(_GAUSS)
        self.N = line_quadratic(s)[0]  # (n_g, 3), nodes ordered along the path
        jac = 0.5 * (positions[:, 2] - positions[:, 0])
        self.dA = thickness * jac[:, None] * weights[None, :]  # crack area per edge Gauss point [mm^2]
        self.y = positions[:, [0]] + (1.0 + s[None, :]) * jac[:, None]  # Gauss points along the path [mm]

    def initial_history(self):
        """Largest opening reached at each crack Gauss point [mm], shape (n_edges, n_g)."""
        return np.zeros(self.dA.shape)

    def openings(self, q):
        """Crack opening at the Gauss points [mm]: twice the normal displacement away from the line."""
        u_n = self.gather(q)[self.owners[:, None], self.slots] * self.sides[:, None]  # (n_edges, 3)
        return 2.0 * u_n @ self.N.T  # (n_edges, n_g)

    def onset_ratio(self, w_max):
        return float(w_max.max()) * self.penalty / self.params.ft

    def _traction(self, w, w_max_old):
        return crack_traction(w, w_max_old, *self.params.law(), self.penalty)

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
        return residual, arrays._replace(tangent=tangent, kappa=w_max), references

    def cracked_length(self, w_max) -> float:
        """Length of the crack path where the faces have separated (opening beyond w0) [mm]."""
        order = np.argsort(self.y.ravel())
        y, w = self.y.ravel()[order], w_max.ravel()[order]
        return superlevel_length(y, w, self.params.ft / self.penalty, y[0], y[-1])

    def fields(self, q, w_max, omega):
        out = super().fields(q, np.zeros(self.disc.weights.shape), omega)
        out.update(crack_opening_max=w_max.copy())
        return out

    def elastic_energy(self, q, w_max, omega):
        """Bulk strain energy plus the energy the crack gives back on unloading (penalty and secant) [N mm]."""
        w = self.openings(q)
        sigma, _, _ = self._traction(w, w_max)
        crack = 0.5 * np.sum(sigma * w * self.dA)  # w is the full opening: the crack of the whole specimen
        return super().elastic_energy(q, w_max, np.zeros(self.disc.weights.shape)) + crack

    # direct differentiation (fracid.fem.ddm): elastic bulk plus the interface's tractions

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
        :class:`~fracid.fem.damage_sensitivity.StepDerivative`); the history is the largest opening.

        The bulk's pseudo-load is that of an undamaged continuum (E, nu); the crack's, the traction's
        derivative at fixed opening and history (:func:`crack_traction_parameter_derivatives`), with
        the carried d w_max / d x where a cracked point unloads (secant branch). The opening has no
        explicit parameter dependence, so at loading points w_max' = w'. With the penalty
        proportional to E (``penalty_follows_E``), d/dE also moves the penalty and w0 = ft / penalty.

        Non-differentiable points, where the one-sided derivative of the branch the point is on is
        used: the crack tip, where a point's opening crosses w0 (the traction's parameter derivatives
        jump from the penalty branch to Hordijk's law, e.g. d sigma / d ft from 0 to
        1 - sigma_H'(0) / penalty); the opening w - w0 = wc where the law's traction reaches zero (the
        derivative with respect to wc jumps to 0); and w = w_max (loading or unloading). A point
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
        rates, d_w_max = crack_traction_parameter_derivatives(w, w_max_old, self.params, self.penalty,
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
