"""What the nonlinear solver and the recorder of a forward run may use of a problem.

Every formulation (the damage problems of :mod:`fracid.fem.formulations.problem`, the crack band, the cohesive
crack, a formulation of a test file) implements :class:`Problem`;
:func:`~fracid.fem.path.path_following.follow_path`, :class:`~fracid.fem.path.solver.ControlledSystem` and the
observers use nothing else. A problem keeps no state between calls: what it returns depends only on
its arguments.

Its unknowns are the displacements and any named scalar fields (its ``blocks``, numbered by a
:class:`~fracid.fem.mesh.dofs.DofMap` from :class:`~fracid.fem.mesh.dofs.FieldSpec` declarations). Its history
is declared as data (:class:`HistoryVariable` per name, as fenics-constitutive's ``history_dim``):
:func:`initial_history` allocates it, and the solver carries it from step to step without looking
inside.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol, runtime_checkable

import numpy as np


@dataclass(frozen=True)
class HistoryVariable:
    """One history variable of a formulation.

    Parameters
    ----------
    shape : tuple of int
        Shape of its value at one point (``()`` a scalar, ``(3,)`` a vector, ...).
    points : tuple of int or None
        The grid of points it lives on; None: the integration points of the discretisation,
        ``disc.weights.shape`` = (n_el, n_q). Another grid (e.g. the Gauss points of a crack
        interface, (n_edges, n_g)) is given explicitly.
    initial : float
        Its value in the virgin state.
    """

    shape: tuple = ()
    points: tuple | None = None
    initial: float = 0.0

    def __post_init__(self):
        for what, value in (("shape", self.shape), ("points", self.points or ())):
            if not all(isinstance(n, (int, np.integer)) and n >= 0 for n in tuple(value)):
                raise ValueError(f"HistoryVariable {what} = {value!r}: a tuple of non-negative integers")
        object.__setattr__(self, "shape", tuple(int(n) for n in self.shape))
        if self.points is not None:
            object.__setattr__(self, "points", tuple(int(n) for n in self.points))


def history_variables(spec) -> dict:
    """A history declaration as ``{name: HistoryVariable}``.

    Parameters
    ----------
    spec : mapping {name: HistoryVariable or tuple}
        A tuple is the shape per integration point: ``{"kappa": ()}``.
    """
    if not hasattr(spec, "items") or not spec:
        raise ValueError(f"history_spec = {spec!r}: a non-empty mapping {{name: HistoryVariable or shape per point}}")
    return {name: v if isinstance(v, HistoryVariable) else HistoryVariable(tuple(v)) for name, v in spec.items()}


def allocate_history(spec, disc):
    """The virgin history of a declaration: an array for a single variable, else a dict of arrays.

    Parameters
    ----------
    spec : mapping {name: HistoryVariable or tuple}
        See :func:`history_variables`.
    disc : MixedDiscretization
        Gives the integration points, ``disc.weights.shape``.
    """
    arrays = {name: np.full((v.points if v.points is not None else disc.weights.shape) + v.shape, float(v.initial))
              for name, v in history_variables(spec).items()}
    return next(iter(arrays.values())) if len(arrays) == 1 else arrays


def initial_history(problem):
    """The history a path starts from: allocated from the problem's ``history_spec``."""
    return allocate_history(problem.history_spec, problem.disc)


def state_fields(problem, q, arrays) -> dict:
    """``problem.fields`` of the converged state q with its element arrays."""
    return problem.fields(q, arrays.history, arrays)


def state_energy(problem, q, arrays) -> float:
    """``problem.elastic_energy`` of the converged state q with its element arrays."""
    return problem.elastic_energy(q, arrays.history, arrays)


@runtime_checkable
class Problem(Protocol):
    """A discretised nonlinear problem r(q, history) - lambda f_hat = 0 with named functionals.

    Attributes
    ----------
    disc : MixedDiscretization
        The discretisation (observers read its integration points).
    n_free : int
        Number of unknowns q.
    element_dofs : ndarray of int, shape (n_el, n_dof_el)
        Unknown of each element dof (-1: eliminated), the sparsity pattern of the tangent.
    blocks : dict {field: ndarray of int}
        The unknowns of each field (``"u"`` and the named fields); the solver checks each field's
        residual against ``NewtonOptions.tolerance(field)``.
    load_vector : ndarray, shape (n_free,)
        The force pattern f_hat [N per unit load factor].
    functionals : dict {name: ndarray, shape (n_free,)}
        Linear functionals of q: the controls and measured displacements [mm].
    symmetry_factor : float
        Copies of the model in the whole specimen (the recorded work and energies are the whole's).
    history_spec : mapping {name: HistoryVariable or shape per point}
        The declared history; :func:`initial_history` allocates it (a problem may instead write its
        own ``initial_history()``).
    """

    disc: object
    n_free: int
    element_dofs: np.ndarray
    blocks: dict
    load_vector: np.ndarray
    functionals: dict
    symmetry_factor: float
    history_spec: dict

    def onset_ratio(self, history) -> float:
        """How far the history is from the onset of softening (< 1: still elastic)."""

    def evaluate(self, q: np.ndarray, history_old):
        """``(residual, arrays, references)``: internal forces r(q) (shape (n_free,)), the element arrays
        (:class:`~fracid.fem.formulations.forms.ElementArrays`: tangents, the trial ``history``, named point
        ``outputs``) and per field the norm that makes its residual relative."""

    def fields(self, q: np.ndarray, history, arrays) -> dict:
        """Named fields of a converged state (nodal ``u`` and the named fields, point history and
        outputs, ...); ``arrays`` are the element arrays of the evaluation at q."""

    def elastic_energy(self, q: np.ndarray, history, arrays) -> float:
        """Recoverable energy of a converged state [N mm]; ``arrays`` as for :meth:`fields`."""
