"""Mixed discretisations: everything about the mesh that assembly needs, computed once per mesh.

A :class:`MixedDiscretization` stores, for all elements and integration points at once, the strain
operator of the displacement field, the integration weights (including cross-section or thickness)
and the global dof numbers of the displacements, and the interpolation spaces a formulation may put
its named scalar fields on (:class:`ScalarSpace`: ``"linear"`` on the element corners,
``"quadratic"`` on all the nodes of the displacement field). The material law and the solver never
see the mesh; they work on these arrays.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np

from fracid.fem.material.elasticity import UNIAXIAL, StrainState
from fracid.fem.mesh.elements import (gauss_line, gauss_quad, gauss_triangle, line_linear, line_quadratic, quad_linear,
                                 quad_serendipity, triangle_linear, triangle_quadratic)


@dataclass(frozen=True, eq=False)
class ScalarSpace:
    """An interpolation of a scalar nodal field over the elements of a discretisation.

    Attributes
    ----------
    shape : ndarray, shape (n_q, n_e)
        Shape functions at the integration points (the same reference rule in every element).
    gradient : ndarray, shape (n_el, n_q, dim, n_e)
        Their spatial gradients [1/mm].
    nodes : ndarray of int, shape (n_el, n_e)
        The space's node of each element node, numbered 0 .. n_nodes - 1.
    n_nodes : int
        Number of nodes (values of one field on this space).
    """

    shape: np.ndarray
    gradient: np.ndarray
    nodes: np.ndarray
    n_nodes: int


@dataclass(frozen=True, eq=False)
class MixedDiscretization:
    """Precomputed element arrays of the displacement field and of the scalar spaces.

    Attributes
    ----------
    strain_state : StrainState
        Kinematic assumption (uniaxial, plane stress).
    weights : ndarray, shape (n_el, n_q)
        Integration weight times Jacobian times cross-section (1D, mm^2) or thickness (2D, mm) [mm^3].
    strain_operator : ndarray, shape (n_el, n_q, n_strain, n_u)
        B: engineering strains at the integration points from the element displacement dofs [1/mm].
    u_dofs : ndarray of int, shape (n_el, n_u)
        Global displacement dof numbers, 0 .. n_u_dofs - 1.
    points : ndarray, shape (n_el, n_q, dim)
        Coordinates of the integration points [mm].
    n_u_dofs : int
        Number of displacement dofs.
    spaces : dict {name: ScalarSpace}
        The interpolations a named scalar field may use: ``"linear"`` (element corners) and
        ``"quadratic"`` (all the nodes of the displacement field).
    """

    strain_state: StrainState
    weights: np.ndarray
    strain_operator: np.ndarray
    u_dofs: np.ndarray
    points: np.ndarray
    n_u_dofs: int
    spaces: dict

    @property
    def n_elements(self) -> int:
        return self.weights.shape[0]

    def space(self, name: str) -> ScalarSpace:
        """The scalar space ``name``; ValueError naming the spaces there are."""
        if name not in self.spaces:
            raise ValueError(f"unknown scalar space {name!r}; this discretisation offers {sorted(self.spaces)}")
        return self.spaces[name]


def bar_discretization(vertices, areas, n_gauss: int = 3) -> MixedDiscretization:
    """Mixed 1D bar elements: quadratic displacement; linear and quadratic scalar spaces.

    Parameters
    ----------
    vertices : array_like, shape (n_el + 1,)
        Increasing element end coordinates [mm].
    areas : array_like, shape (n_el,) or float
        Cross-section of each element [mm^2].
    n_gauss : int
        Gauss points per element (3 integrates the elastic quadratic-element stiffness exactly
        and the element mass of a linear scalar field exactly).

    Notes
    -----
    Displacement nodes are the vertices and the element mid-points, numbered along the bar
    (vertex i is u node 2 i); the nodes of the linear space are the vertices, those of the
    quadratic space the displacement nodes.
    """
    x = np.asarray(vertices, dtype=float)
    if x.ndim != 1 or x.size < 2 or np.any(np.diff(x) <= 0):
        raise ValueError("bar vertices must be a strictly increasing 1D array of at least two coordinates")
    n_el = x.size - 1
    areas = np.broadcast_to(np.asarray(areas, dtype=float), (n_el,))
    if np.any(~np.isfinite(areas)) or np.any(areas <= 0):
        raise ValueError("every element cross-section must be positive and finite")
    xi, gw = gauss_line(n_gauss)
    Nu, dNu = line_quadratic(xi)
    Ne, dNe = line_linear(xi)
    half = 0.5 * np.diff(x)  # Jacobian dx/dxi
    mid = 0.5 * (x[:-1] + x[1:])
    el = np.arange(n_el)
    u_nodes = np.stack([2 * el, 2 * el + 1, 2 * el + 2], axis=1)
    dNu_dx = (dNu[None, :, :] / half[:, None, None])[:, :, None, :]
    spaces = {"linear": ScalarSpace(Ne, (dNe[None, :, :] / half[:, None, None])[:, :, None, :],
                                    np.stack([el, el + 1], axis=1), n_el + 1),
              "quadratic": ScalarSpace(Nu, dNu_dx, u_nodes, 2 * n_el + 1)}
    return MixedDiscretization(
        strain_state=UNIAXIAL,
        weights=(gw[None, :] * half[:, None]) * areas[:, None],
        strain_operator=dNu_dx,
        u_dofs=u_nodes,
        points=(mid[:, None] + half[:, None] * xi[None, :])[:, :, None],
        n_u_dofs=2 * n_el + 1,
        spaces=spaces,
    )


@dataclass(frozen=True)
class _Family:
    """A mixed plane element: displacement (and geometry) shape functions on all its nodes, linear
    shape functions on its corners, and the quadrature rule of the reference element."""

    name: str
    n_corners: int
    displacement: Callable
    corners: Callable
    rule: Callable
    default_order: int


# element family by the number of nodes per cell
_PLANE_FAMILIES = {
    8: _Family("8-node quadrilaterals", 4, quad_serendipity, quad_linear, gauss_quad, 3),
    6: _Family("6-node triangles", 3, triangle_quadratic, triangle_linear, gauss_triangle, 4),
}


def plane_stress_discretization(nodes, cells, n_vertices: int, thickness: float,
                                n_gauss: int | None = None) -> MixedDiscretization:
    """Mixed plane-stress elements: quadratic displacement; scalar spaces linear on the corners and
    quadratic on all nodes.

    The family follows from the width of ``cells``: 8-node serendipity quadrilaterals (Q8) with a
    bilinear 4-node linear space, or 6-node triangles (T6) with a linear 3-node one. One family per mesh.

    Parameters
    ----------
    nodes : ndarray, shape (n_nodes, 2)
        Node coordinates [mm]; the element corners (vertices) come first, numbered 0..n_vertices-1,
        then the mid-edge nodes.
    cells : ndarray of int, shape (n_el, 8) or (n_el, 6)
        Corners counterclockwise, then the mid-edge nodes of edges 0-1, 1-2, 2-3, 3-0 (Q8) or
        0-1, 1-2, 2-0 (T6).
    n_vertices : int
        Number of corner nodes (the nodes of the linear space).
    thickness : float
        Out-of-plane thickness [mm].
    n_gauss : int, optional
        Q8: Gauss points per direction (default 3: full integration of the quadratic element). T6:
        polynomial degree the triangle rule integrates exactly (default 4: 6 points, since the
        damage field varies inside the element).

    Notes
    -----
    Displacement dofs of node j are 2 j (x) and 2 j + 1 (y); vertex v is node v of the linear
    space, node j node j of the quadratic space. The geometry is isoparametric with the quadratic element (curved edges allowed).
    """
    from fracid.fem.material.elasticity import PLANE_STRESS

    nodes = np.asarray(nodes, dtype=float)
    cells = np.asarray(cells, dtype=int)
    family = _PLANE_FAMILIES.get(cells.shape[1]) if cells.ndim == 2 else None
    if family is None:
        raise ValueError(f"cells must be (n_el, 8) quadrilaterals or (n_el, 6) triangles; got shape {cells.shape}")
    corners = cells[:, :family.n_corners]
    if np.any(corners >= n_vertices):
        raise ValueError(f"cells of {family.name} must list their {family.n_corners} corners first, as vertices "
                         f"(< n_vertices = {n_vertices})")
    if not thickness > 0:
        raise ValueError(f"thickness = {thickness!r} mm; it must be positive")
    pts, gw = family.rule(family.default_order if n_gauss is None else n_gauss)
    Nu, dNu = family.displacement(pts)
    Ne, dNe = family.corners(pts)
    X = nodes[cells]  # (n_el, n_nodes per cell, 2)
    J = np.einsum("qai,eaj->eqij", dNu, X)  # d x_j / d xi_i
    detJ = J[..., 0, 0] * J[..., 1, 1] - J[..., 0, 1] * J[..., 1, 0]
    if np.any(detJ <= 0):
        bad = np.unique(np.nonzero(detJ <= 0)[0])
        raise ValueError(f"elements {bad[:10].tolist()} are inverted or degenerate (Jacobian <= 0)")
    Jinv = np.linalg.inv(J)
    dNu_dx = np.einsum("eqij,qaj->eqai", Jinv, dNu)  # (n_el, n_q, n_nodes per cell, 2)
    dNe_dx = np.einsum("eqij,qaj->eqai", Jinv, dNe)
    n_el, n_q = detJ.shape
    n_u = 2 * cells.shape[1]
    B = np.zeros((n_el, n_q, 3, n_u))
    B[:, :, 0, 0::2] = dNu_dx[..., 0]
    B[:, :, 1, 1::2] = dNu_dx[..., 1]
    B[:, :, 2, 0::2] = dNu_dx[..., 1]
    B[:, :, 2, 1::2] = dNu_dx[..., 0]
    u_dofs = np.empty((n_el, n_u), dtype=int)
    u_dofs[:, 0::2], u_dofs[:, 1::2] = 2 * cells, 2 * cells + 1
    spaces = {"linear": ScalarSpace(Ne, np.swapaxes(dNe_dx, -1, -2), corners, int(n_vertices)),
              "quadratic": ScalarSpace(Nu, np.swapaxes(dNu_dx, -1, -2), cells, nodes.shape[0])}
    return MixedDiscretization(
        strain_state=PLANE_STRESS,
        weights=gw[None, :] * detJ * thickness,
        strain_operator=B,
        u_dofs=u_dofs,
        points=np.einsum("qa,eai->eqi", Nu, X),
        n_u_dofs=2 * nodes.shape[0],
        spaces=spaces,
    )
