"""A specimen as a description every model builds its problem from.

A specimen (a laboratory test) says *what* is tested: a mesh with named node sets, the material
regions, supports, loads, tied groups and symmetry, the named functionals that controls and
observables read, where a crack runs, and where the width of the damaged zone is measured. It knows
no model: a forward model (:mod:`fracid.models`) turns a :class:`Description` into the problem of its
formulation with :func:`discretize` and :func:`conditions`.

Coordinates and lengths in mm, forces in N.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable, Mapping

import numpy as np

from fracid.fem.mesh.discretization import MixedDiscretization, bar_discretization, plane_stress_discretization
from fracid.fem.mesh.dofs import Conditions


@dataclass(frozen=True)
class Support:
    """The ``component`` (0: x, 1: y) of the nodes of set ``nodes`` held at zero. With ``point``
    (a one-node set), a model of an open crack holds that node only (a roller instead of a
    support plate)."""

    nodes: str
    component: int
    point: str | None = None


@dataclass(frozen=True)
class Load:
    """A force ``total`` [N per unit load factor] on the ``component`` of the nodes of set ``nodes``.

    ``rigid``: the nodes move together (a rigid plate; the force acts on the set's first node), else
    the force is spread evenly. ``rigid_under_open_crack``: the same for the models of an open crack
    (None: as ``rigid``), whose halves a rigid plate would clamp.
    """

    nodes: str
    component: int
    total: float
    rigid: bool = True
    rigid_under_open_crack: bool | None = None

    def is_rigid(self, open_crack: bool) -> bool:
        return self.rigid if not open_crack or self.rigid_under_open_crack is None else self.rigid_under_open_crack


@dataclass(frozen=True)
class Measure:
    """``weight`` times the mean displacement along ``component`` of the nodes of set ``nodes`` (a
    term of a named functional) [mm]."""

    nodes: str
    component: int
    weight: float = 1.0


@dataclass(frozen=True)
class CrackPath:
    """Where a crack runs.

    Parameters
    ----------
    nodes : str or None
        Node set on the straight crack line (the symmetry line of a half model); None: the crack may
        form anywhere (a crack band only).
    normal : int
        Axis normal to the crack (0: x, 1: y).
    mirrored : bool
        The line is a symmetry line of the model: the crack's opening is twice the normal displacement,
        a band along it is half of a band centred on it.
    element_size : float, optional
        Nominal element size along the path [mm] (a discrete crack's penalty stiffness is E / size
        times a factor); the shortest edge on the path if None.
    """

    nodes: str | None
    normal: int
    mirrored: bool = True
    element_size: float | None = None


@dataclass(frozen=True)
class ZoneWidth:
    """Where a damage model measures the width of its damaged zone, recorded as observable ``name``.

    2D: the largest extent across the crack path x[axis] = 0, over ``along_range`` of the other
    coordinate, doubled if ``mirror`` (a half model). 1D: the length along the bar.
    """

    name: str
    axis: int = 0
    mirror: bool = False
    along_range: tuple = (-np.inf, np.inf)


_PLANE_CELL_TYPES = {8: "quad8", 6: "triangle6"}  # VTK cell type of a plane mesh by nodes per cell


def uniform(points) -> np.ndarray:
    """1 at every point (the default of a description's fields)."""
    return np.ones(np.shape(points)[:-1])


@dataclass(frozen=True, eq=False)
class Description:
    """What a specimen is, for any model.

    Parameters
    ----------
    nodes : ndarray, shape (n_nodes, dim)
        Node coordinates [mm]: dim 1 for a bar (quadratic elements, vertex i is node 2 i), 2 for
        plane stress (8-node quadrilaterals or 6-node triangles, the first ``n_vertices`` nodes are
        the corners).
    cells : ndarray of int
        The vertices of each 1D element (shape (n_el, 2)), the 8 nodes of each quadrilateral or the
        6 nodes of each triangle (corners first, see
        :func:`~fracid.fem.mesh.discretization.plane_stress_discretization`).
    node_sets : mapping {name: ndarray of int}
        Named sets of nodes that the conditions below refer to.
    loads, supports : tuples of Load and Support
    symmetry : tuple of (node set, component)
        Symmetry conditions: the normal displacement of the set held at zero.
    functionals : mapping {name: tuple of Measure}
        The controls and measured displacements.
    section : float or ndarray, shape (n_el,)
        Thickness [mm] (plane stress) or cross-section of each element [mm^2] (bar).
    n_vertices : int
        Corner nodes of a plane-stress mesh (the nonlocal-strain nodes).
    symmetry_factor : float
        Copies of the model in the whole specimen.
    symmetry_planes : tuple of (axis, coordinate)
        Symmetry planes of a half or quarter model.
    stiffness_factor, damageable, strength_factor : callable (points (..., dim)) -> ndarray (...), or ndarray (n_el,)
        Young's modulus relative to the material's, 1 where the material may soften (0 in elastic
        loading blocks), tensile strength relative to the material's (an imperfection), at any points.
    crack : CrackPath, optional
    zone : ZoneWidth, optional
    cell_type : str, optional
        VTK cell type of the output mesh; by default that of the cells ("line3", "quad8" or
        "triangle6").
    """

    nodes: np.ndarray
    cells: np.ndarray
    node_sets: Mapping[str, np.ndarray]
    loads: tuple
    functionals: Mapping[str, tuple]
    section: object
    supports: tuple = ()
    symmetry: tuple = ()
    n_vertices: int = 0
    symmetry_factor: float = 1.0
    symmetry_planes: tuple = ()
    stiffness_factor: Callable = uniform
    damageable: Callable = uniform
    strength_factor: Callable = uniform
    crack: CrackPath | None = None
    zone: ZoneWidth | None = None
    cell_type: str | None = None
    _cache: dict = field(default_factory=dict, repr=False)

    @property
    def dim(self) -> int:
        return self.nodes.shape[1]

    @property
    def corners(self) -> np.ndarray:
        """The corner nodes of each plane cell (3 of a T6, 4 of a Q8), or the two vertices of a bar element."""
        if self.dim == 1:
            return self.cells
        return self.cells[:, :3] if self.cells.shape[1] == 6 else self.cells[:, :4]

    def nodes_of(self, name: str) -> np.ndarray:
        try:
            return np.asarray(self.node_sets[name], dtype=int)
        except KeyError:
            raise ValueError(f"no node set {name!r}; the specimen names {sorted(self.node_sets)}") from None

    def dofs(self, nodes, component: int) -> np.ndarray:
        """Global displacement dofs of ``nodes`` (indices or a set's name) along ``component``."""
        nodes = self.nodes_of(nodes) if isinstance(nodes, str) else np.asarray(nodes, dtype=int)
        return self.dim * nodes + component

    def output_mesh(self):
        """Nodes, cells and VTK cell type, for :func:`fracid.report.write_result_vtk`."""
        if self.dim == 1:
            el = np.arange(len(self.cells))
            return self.nodes, np.stack([2 * el, 2 * el + 2, 2 * el + 1], axis=1), "line3"
        return self.nodes, self.cells, self.cell_type or _PLANE_CELL_TYPES[self.cells.shape[1]]


def described(specimen) -> Description:
    """The specimen's :class:`Description` (``specimen.describe()``; a description is its own)."""
    return specimen if isinstance(specimen, Description) else specimen.describe()


def discretize(description: Description) -> MixedDiscretization:
    """The mixed discretisation of the description's mesh (built once per description)."""
    if "disc" not in description._cache:
        d = description
        if d.dim == 1:
            disc = bar_discretization(d.nodes[0::2, 0], d.section)
        else:
            disc = plane_stress_discretization(d.nodes, d.cells, d.n_vertices, float(d.section))
        description._cache["disc"] = disc
    return description._cache["disc"]


def conditions(description: Description, *, open_crack: bool = False, discrete_crack: bool = False) -> Conditions:
    """The :class:`~fracid.fem.mesh.dofs.Conditions` of the description.

    ``open_crack``: for a model whose crack opens fully (plates and supports as
    :class:`Load` and :class:`Support` say for that case); ``discrete_crack``: the crack path's
    symmetry condition is left to the model's crack interface.
    """
    d = description
    released = set()
    if discrete_crack:
        if d.crack is None or d.crack.nodes is None or not d.crack.mirrored:
            raise ValueError("this specimen has no crack path on a symmetry line for a discrete crack")
        released = set(d.dofs(d.crack.nodes, d.crack.normal).tolist())
    fixed = [np.array([dof for dof in d.dofs(name, comp) if dof not in released], dtype=int) for name, comp in d.symmetry]
    for support in d.supports:
        nodes = support.point if open_crack and support.point else support.nodes
        fixed.append(d.dofs(nodes, support.component))
    tied, load, rigid = [], {}, {}
    for item in d.loads:
        dofs = d.dofs(item.nodes, item.component)
        if item.is_rigid(open_crack):
            rigid[(item.nodes, item.component)] = int(dofs[0])
            if dofs.size > 1:
                tied.append(dofs)
            load[int(dofs[0])] = load.get(int(dofs[0]), 0.0) + item.total
        else:
            for dof in dofs:
                load[int(dof)] = load.get(int(dof), 0.0) + item.total / dofs.size
    functionals = {name: _functional(d, terms, rigid) for name, terms in d.functionals.items()}
    return Conditions(load=load, functionals=functionals, fixed_dofs=np.concatenate(fixed) if fixed else (),
                      tied=tuple(tied), symmetry_factor=d.symmetry_factor)


def _functional(d: Description, terms, rigid: dict) -> dict:
    """Coefficients {dof: c} of a functional: a rigid set's mean is its first node's displacement."""
    out = {}
    for term in terms:
        master = rigid.get((term.nodes, term.component))
        dofs = [master] if master is not None else d.dofs(term.nodes, term.component).tolist()
        for dof in dofs:
            out[int(dof)] = out.get(int(dof), 0.0) + term.weight / len(dofs)
    return out


def at_points(function, disc) -> np.ndarray:
    """A description's field (stiffness, damageable, strength) at the integration points: a function of
    the points, or an array of one value per element (a mesh's regions)."""
    if callable(function):
        return np.broadcast_to(np.asarray(function(disc.points), dtype=float), disc.weights.shape)
    return np.broadcast_to(np.asarray(function, dtype=float)[:, None], disc.weights.shape)
