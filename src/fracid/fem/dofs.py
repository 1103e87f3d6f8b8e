"""Boundary conditions and the numbering of the unknowns, shared by every formulation.

A specimen's supports, loads, tied groups and functionals become a :class:`Conditions` (in global
dofs); a :class:`DofMap` numbers the unknowns of one formulation (displacements, plus the nonlocal
strain of the gradient model) with the fixed dofs eliminated and each tied group sharing one unknown,
and maps vectors between the free unknowns and all dofs.
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


@dataclass(frozen=True, eq=False)
class DofMap:
    """The free unknowns of a discretisation under :class:`Conditions`.

    Attributes
    ----------
    free_index : ndarray of int, shape (n_dofs,)
        Unknown of every dof: -1 if fixed or not part of the formulation, shared within a tied group.
    n_free : int
    element_dofs : ndarray of int, shape (n_el, n_dof_el)
        Unknowns of each element's dofs (displacements first, then ebar), -1 for eliminated ones.
    blocks : dict {field: ndarray of int}
        Unknowns of each field (``"u"``, and ``"ebar"`` for the gradient model).
    load_vector : ndarray, shape (n_free,)
    functionals : dict {name: ndarray, shape (n_free,)}
    """

    disc: object
    free_index: np.ndarray
    element_dofs: np.ndarray
    blocks: dict
    load_vector: np.ndarray = field(repr=False)
    functionals: dict = field(repr=False)

    @property
    def n_free(self) -> int:
        return int(self.free_index.max()) + 1

    @property
    def n_u(self) -> int:
        """Displacement dofs per element."""
        return self.disc.u_dofs.shape[1]

    def gather(self, q: np.ndarray) -> np.ndarray:
        """Element dof values from the free-dof vector (eliminated dofs are zero)."""
        return np.append(q, 0.0)[self.element_dofs]

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


def number_dofs(disc, conditions: Conditions, *, with_ebar: bool) -> DofMap:
    """The :class:`DofMap` of ``disc`` under ``conditions``; ``with_ebar``: the nonlocal-strain dofs are
    unknowns too (gradient model). Raises ValueError for dofs out of range, a tied group holding a
    fixed dof, a load on fixed dofs only."""
    n_active = disc.n_dofs if with_ebar else disc.n_u_dofs
    fixed = np.unique(np.asarray(conditions.fixed_dofs, dtype=int))
    if fixed.size and (fixed.min() < 0 or fixed.max() >= disc.n_u_dofs):
        raise ValueError(f"fixed dofs must be displacement dofs in [0, {disc.n_u_dofs}); got {fixed.tolist()}")
    free_index = _number_unknowns(disc, n_active, fixed, conditions.tied)
    n_free = int(free_index.max()) + 1
    dofs = np.concatenate([disc.u_dofs, disc.ebar_dofs], axis=1) if with_ebar else disc.u_dofs
    u_index = free_index[: disc.n_u_dofs]
    blocks = {"u": np.unique(u_index[u_index >= 0])}
    if with_ebar:
        blocks["ebar"] = free_index[disc.n_u_dofs :]
    load = _dense(disc, free_index, n_free, conditions.load, "load")
    if not np.any(load):
        raise ValueError("the load pattern is empty or acts only on fixed dofs")
    functionals = {name: _dense(disc, free_index, n_free, f, f"functional {name!r}")
                   for name, f in conditions.functionals.items()}
    return DofMap(disc, free_index, free_index[dofs], blocks, load, functionals)


def _number_unknowns(disc, n_active, fixed, tied) -> np.ndarray:
    """Unknown index of every dof: -1 if fixed or absent, shared within a tied group."""
    representative = np.arange(disc.n_dofs)
    for group in tied:
        group = np.asarray(group, dtype=int)
        if group.size == 0 or group.min() < 0 or group.max() >= disc.n_u_dofs:
            raise ValueError(f"a tied group must hold displacement dofs in [0, {disc.n_u_dofs})")
        if np.intersect1d(group, fixed).size:
            raise ValueError("a tied group contains a fixed dof; fix the whole group instead")
        representative[group] = group[0]
    active = np.zeros(disc.n_dofs, dtype=bool)
    active[:n_active] = True
    active[fixed] = False
    leaders = np.unique(representative[active])
    number = np.full(disc.n_dofs, -1)
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
