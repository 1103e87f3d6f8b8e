"""Boundary conditions and the numbering of the unknowns, shared by every formulation.

A specimen's supports, loads, tied groups and functionals become a :class:`Conditions` (in global
displacement dofs); a :class:`DofMap` numbers the unknowns of one formulation (the displacements,
plus any named scalar fields the formulation declares as :class:`FieldSpec`, each on a scalar space
of the discretisation) with the fixed dofs eliminated and each tied group sharing one unknown, and
maps vectors between the free unknowns and all dofs.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Mapping

import numpy as np


@dataclass(frozen=True, eq=False)
class Conditions:
    """Boundary conditions, load pattern and named functionals in global displacement dofs.

    Parameters
    ----------
    fixed_dofs : sequence of int
        Displacement dofs held at zero.
    load : mapping {dof: weight}
        The force pattern f_hat; the applied force is lambda * f_hat [N].
    functionals : mapping {name: {dof: coefficient}}
        Linear functionals of the displacement (control quantities, observables) [mm].
    tied : sequence of sequences of int
        Groups of displacement dofs that share one unknown (a rigid loading plate).
    symmetry_factor : float
        Copies of the model in the whole specimen (2 for a half, 4 for a quarter model); the
        energies are reported for the whole specimen.
    """

    load: Mapping[int, float]
    functionals: Mapping[str, Mapping[int, float]]
    fixed_dofs: tuple = ()
    tied: tuple = ()
    symmetry_factor: float = 1.0


@dataclass(frozen=True)
class FieldSpec:
    """A named scalar nodal field of a formulation, besides the displacements.

    Parameters
    ----------
    name : str
        The field's name: its block of unknowns, its tolerance in
        :meth:`~fracid.fem.path.solver.NewtonOptions.tolerance`, its entry in the recorded fields.
    space : str
        The interpolation it lives on, a key of the discretisation's ``spaces`` (``"linear"``: the
        element corners, ``"quadratic"``: all the displacement nodes).
    """

    name: str
    space: str = "linear"

    def __post_init__(self):
        if not isinstance(self.name, str) or not self.name.isidentifier() or self.name == "u":
            raise ValueError(f"FieldSpec name = {self.name!r}: a field needs an identifier other than 'u' "
                             "(the displacements)")


def field_specs(fields) -> tuple:
    """Normalise a declaration of named fields to a tuple of :class:`FieldSpec`.

    Parameters
    ----------
    fields : sequence of FieldSpec, or mapping {name: space}
        E.g. ``{"phi": "linear"}``; order is numbering order.
    """
    items = fields.items() if hasattr(fields, "items") else fields
    specs = tuple(f if isinstance(f, FieldSpec) else FieldSpec(*f) for f in items)
    names = [f.name for f in specs]
    if len(set(names)) != len(names):
        raise ValueError(f"fields {names}: each named field must appear once")
    return specs


@dataclass(frozen=True, eq=False)
class DofMap:
    """The free unknowns of a discretisation under :class:`Conditions`.

    All dofs are numbered displacements first (``0 .. disc.n_u_dofs - 1``), then each named field's
    nodes in the order of ``fields``; the unknowns follow the same order.

    Attributes
    ----------
    fields : tuple of FieldSpec
        The named scalar fields besides the displacements.
    free_index : ndarray of int, shape (n_dofs,)
        Unknown of every dof: -1 if fixed or in no element, shared within a tied group.
    n_free : int
    element_dofs : ndarray of int, shape (n_el, n_dof_el)
        Unknowns of each element's dofs (displacements first, then each field's), -1 for eliminated ones.
    columns : dict {field: slice}
        The columns of each field (``"u"`` first) in ``element_dofs`` and in element vectors.
    ranges : dict {field: slice}
        The dofs of each field in the vector of all dofs (:meth:`full_vector`).
    blocks : dict {field: ndarray of int}
        Unknowns of each field (``"u"`` and the named fields).
    load_vector : ndarray, shape (n_free,)
    functionals : dict {name: ndarray, shape (n_free,)}
    """

    disc: object
    fields: tuple
    free_index: np.ndarray
    element_dofs: np.ndarray
    columns: dict
    ranges: dict
    blocks: dict
    load_vector: np.ndarray = field(repr=False)
    functionals: dict = field(repr=False)

    @property
    def n_free(self) -> int:
        return int(self.free_index.max()) + 1

    @property
    def n_dofs(self) -> int:
        """All dofs, eliminated ones included."""
        return self.free_index.size

    @property
    def n_u(self) -> int:
        """Displacement dofs per element."""
        return self.disc.u_dofs.shape[1]

    def gather(self, q: np.ndarray) -> np.ndarray:
        """Element dof values from the free-dof vector (eliminated dofs are zero)."""
        return np.append(q, 0.0)[self.element_dofs]

    def full_vector(self, q: np.ndarray) -> np.ndarray:
        """All dofs (displacements, then each field's), eliminated ones zero."""
        return np.where(self.free_index >= 0, np.append(q, 0.0)[self.free_index], 0.0)

    def restrict(self, full: np.ndarray) -> np.ndarray:
        """Free-dof vector from all dofs (displacements, then the fields' if any; missing trailing
        entries are zero): inverse of :meth:`full_vector`."""
        full = np.asarray(full, dtype=float)
        if full.ndim != 1 or full.size > self.n_dofs:
            raise ValueError(f"restrict: expected at most {self.n_dofs} dof values in a 1D array, got shape {full.shape}")
        padded = np.zeros(self.n_dofs)
        padded[: full.size] = full
        active = self.free_index >= 0
        q = np.zeros(self.n_free)
        q[self.free_index[active]] = padded[active]
        return q

    def split(self, q: np.ndarray) -> dict:
        """Nodal values of every field, ``{"u": ..., name: ...}``, from the free-dof vector."""
        full = self.full_vector(q)
        return {name: full[r] for name, r in self.ranges.items()}


def number_dofs(disc, conditions: Conditions, fields=()) -> DofMap:
    """The :class:`DofMap` of ``disc`` under ``conditions`` with the named scalar ``fields``.

    Parameters
    ----------
    disc : MixedDiscretization
    conditions : Conditions
        In displacement dofs; the named fields have natural boundary conditions only.
    fields : sequence of FieldSpec, or mapping {name: space}
        The formulation's named scalar fields (none: displacements only).

    Raises
    ------
    ValueError
        For dofs out of range, a tied group holding a fixed dof, a load on fixed dofs only, an
        unknown space or a repeated field name.
    """
    specs = field_specs(fields)
    spaces = [disc.space(f.space) for f in specs]
    sizes = [disc.n_u_dofs] + [s.n_nodes for s in spaces]
    offsets = np.cumsum([0] + sizes)
    names = ["u"] + [f.name for f in specs]
    ranges = {name: slice(int(offsets[k]), int(offsets[k + 1])) for k, name in enumerate(names)}
    dofs = np.concatenate([disc.u_dofs] + [offsets[k + 1] + s.nodes for k, s in enumerate(spaces)], axis=1)
    widths = np.cumsum([0, disc.u_dofs.shape[1]] + [s.nodes.shape[1] for s in spaces])
    columns = {name: slice(int(widths[k]), int(widths[k + 1])) for k, name in enumerate(names)}
    fixed = np.unique(np.asarray(conditions.fixed_dofs, dtype=int))
    if fixed.size and (fixed.min() < 0 or fixed.max() >= disc.n_u_dofs):
        raise ValueError(f"fixed dofs must be displacement dofs in [0, {disc.n_u_dofs}); got {fixed.tolist()}")
    used = np.zeros(offsets[-1], dtype=bool)
    used[: disc.n_u_dofs] = True  # displacement dofs in no element are left to the conditions (as before)
    used[dofs[:, columns["u"].stop:].ravel()] = True
    free_index = _number_unknowns(disc, used, fixed, conditions.tied)
    n_free = int(free_index.max()) + 1
    u_index = free_index[: disc.n_u_dofs]
    blocks = {"u": np.unique(u_index[u_index >= 0])}
    blocks.update({name: np.unique(free_index[r][free_index[r] >= 0]) for name, r in ranges.items() if name != "u"})
    load = _dense(disc, free_index, n_free, conditions.load, "load")
    if not np.any(load):
        raise ValueError("the load pattern is empty or acts only on fixed dofs")
    functionals = {name: _dense(disc, free_index, n_free, f, f"functional {name!r}")
                   for name, f in conditions.functionals.items()}
    return DofMap(disc, specs, free_index, free_index[dofs], columns, ranges, blocks, load, functionals)


def _number_unknowns(disc, active, fixed, tied) -> np.ndarray:
    """Unknown index of every dof: -1 if fixed or inactive, shared within a tied group."""
    n_dofs = active.size
    representative = np.arange(n_dofs)
    for group in tied:
        group = np.asarray(group, dtype=int)
        if group.size == 0 or group.min() < 0 or group.max() >= disc.n_u_dofs:
            raise ValueError(f"a tied group must hold displacement dofs in [0, {disc.n_u_dofs})")
        if np.intersect1d(group, fixed).size:
            raise ValueError("a tied group contains a fixed dof; fix the whole group instead")
        representative[group] = group[0]
    active = active.copy()
    active[fixed] = False
    leaders = np.unique(representative[active])
    number = np.full(n_dofs, -1)
    number[leaders] = np.arange(leaders.size)
    return np.where(active, number[representative], -1)


def _dense(disc, free_index, n_free, entries: Mapping[int, float], what: str) -> np.ndarray:
    vec = np.zeros(n_free)
    for dof, value in entries.items():
        if not 0 <= dof < disc.n_u_dofs:
            raise ValueError(f"{what}: dof {dof} is not a displacement dof")
        if free_index[dof] >= 0:
            vec[free_index[dof]] += value
        elif what == "load":
            raise ValueError(f"load: dof {dof} is fixed; a load on a support does no work")
    return vec
