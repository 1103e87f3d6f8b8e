"""A discrete cohesive crack along a symmetry line: elastic bulk plus Hordijk tractions on the crack.

The crack of a symmetric half model lies on its symmetry line x = 0 (the ligament of a notched
beam). Its opening is w = 2 u_x of the nodes on that line. Before cracking the crack faces are tied
by a stiff penalty (sigma = k w up to ft, at w0 = ft / k); beyond, the traction follows Hordijk's law
of the opening in excess of w0 (secant unloading, :func:`~fracid.model.cohesive.cohesive_traction`);
closure (w < 0) is resisted by the same penalty. The crack edges' nodal forces and tangents are
added to the element arrays of the bulk elements that own the edges, so the problem keeps the
element structure (one sparse pattern) the nonlinear solver expects.
"""

from __future__ import annotations

import numpy as np

from fracid.model.assembly import assemble_vector
from fracid.model.cohesive import cohesive_traction
from fracid.model.elements import gauss_line, line_quadratic
from fracid.model.parameters import DamageParameters
from fracid.model.problem import DamageProblem

_GAUSS = 3


def ligament_edges(nodes, cells, u_dofs, y_from, tol=1e-9):
    """Crack edges on the line x = 0 above ``y_from``: the owning element, the positions of the three
    nodes' x-dofs in its dof row (ordered by y) and the edge's node heights [mm]."""
    owners, slots, heights = [], [], []
    for el, cell in enumerate(cells):
        on_line = [n for n in cell if abs(nodes[n, 0]) < tol and nodes[n, 1] >= y_from - tol]
        if len(on_line) != 3:
            continue
        on_line.sort(key=lambda n: nodes[n, 1])
        owners.append(el)
        slots.append([int(np.flatnonzero(u_dofs[el] == 2 * n)[0]) for n in on_line])
        heights.append(nodes[on_line, 1])
    if not owners:
        raise ValueError(f"no element edge lies on the crack line x = 0 above y = {y_from}")
    return np.array(owners), np.array(slots), np.array(heights)


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


class CohesiveCrackProblem(DamageProblem):
    """An elastic plane-stress problem (a :class:`~fracid.model.problem.DamageProblem` that cannot
    damage) with a cohesive crack on the line x = 0.

    Parameters
    ----------
    disc : MixedDiscretization
    params : CohesiveParameters
    edges : tuple
        Output of :func:`ligament_edges`.
    thickness : float
        [mm].
    penalty : float
        Stiffness tying the uncracked faces [MPa/mm].
    **conditions
        ``fixed_dofs`` (not the crack line's x-dofs), ``load``, ``functionals``, ``tied``,
        ``symmetry_factor`` as for :class:`~fracid.model.problem.DamageProblem`.
    """

    def __init__(self, disc, params, edges, thickness, penalty, **conditions):
        super().__init__(disc, DamageParameters(E=params.E, nu=params.nu), regularization="local", damageable=0.0,
                         **conditions)
        self.crack, self.penalty = params, float(penalty)  # self.params: the elastic bulk
        self.owners, self.slots, heights = edges
        s, weights = gauss_line(_GAUSS)
        self.N = line_quadratic(s)[0]  # (n_g, 3), nodes ordered by height
        jac = 0.5 * (heights[:, 2] - heights[:, 0])
        self.dA = thickness * jac[:, None] * weights[None, :]  # crack area per edge Gauss point [mm^2]
        self.y = heights[:, [0]] + (1.0 + s[None, :]) * jac[:, None]  # heights of the Gauss points [mm]
        self._bulk_history = super().initial_history()
        self._w_max = self.initial_history()  # history of the last evaluation (the converged state when energies are asked)

    def initial_history(self):
        """Largest opening reached at each crack Gauss point [mm], shape (n_edges, n_g)."""
        return np.zeros(self.dA.shape)

    def openings(self, q):
        ux = self.gather(q)[self.owners[:, None], self.slots]  # (n_edges, 3) x-displacements of edge nodes
        return 2.0 * ux @ self.N.T  # (n_edges, n_g)

    def onset_ratio(self, w_max):
        return float(w_max.max()) * self.penalty / self.crack.ft

    def evaluate(self, q, w_max_old):
        residual, arrays, references = super().evaluate(q, self._bulk_history)
        w = self.openings(q)
        sigma, dsigma, w_max = crack_traction(w, w_max_old, *self.crack.law(), self.penalty)
        # nodal forces on the half: int N_a sigma dA; d/d u_b: int N_a N_b dsigma/dw * 2 dA
        force = np.einsum("eg,ga->ea", sigma * self.dA, self.N)
        stiffness = 2.0 * np.einsum("eg,ga,gb->eab", dsigma * self.dA, self.N, self.N)
        element_force = np.zeros((len(self.owners), self.element_dofs.shape[1]))
        np.put_along_axis(element_force, self.slots, force, axis=1)
        tangent = arrays.tangent
        rows = self.slots[:, :, None]
        cols = self.slots[:, None, :]
        tangent[self.owners[:, None, None], rows, cols] += stiffness
        residual = residual + assemble_vector(self.element_dofs[self.owners], element_force, self.n_free)
        self._w_max = w_max
        return residual, arrays._replace(tangent=tangent, kappa=w_max), references

    def cracked_length(self, w_max) -> float:
        """Length of the crack line where the faces have separated (opening beyond w0) [mm]."""
        from fracid.specimens.observables import superlevel_length

        order = np.argsort(self.y.ravel())
        y, w = self.y.ravel()[order], w_max.ravel()[order]
        return superlevel_length(y, w, self.crack.ft / self.penalty, y[0], y[-1])

    def fields(self, q, w_max, omega):
        out = super().fields(q, self._bulk_history, omega)
        out.update(crack_opening_max=w_max.copy())
        return out

    def elastic_energy(self, q, omega):
        """Bulk strain energy plus the energy the crack gives back on unloading (penalty and secant) [N mm]."""
        w = self.openings(q)
        sigma, _, _ = crack_traction(w, self._w_max, *self.crack.law(), self.penalty)
        crack = 0.5 * np.sum(sigma * w * self.dA)  # w is the full opening: the crack of the whole specimen
        return super().elastic_energy(q, omega) + crack
