"""What the nonlinear solver and the recorder of a forward run may use of a problem.

Every formulation (the damage problems of :mod:`fracid.fem.problem`, the crack band, the cohesive
crack) implements :class:`Problem`; :func:`~fracid.fem.path_following.follow_path`,
:class:`~fracid.fem.solver.ControlledSystem` and the observers use nothing else. A problem keeps
no state between calls: what it returns depends only on its arguments.
"""

from __future__ import annotations

from typing import Protocol, runtime_checkable

import numpy as np


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
        The unknowns of each named field; the solver checks each field's residual against
        ``NewtonOptions.tolerance(field)``.
    load_vector : ndarray, shape (n_free,)
        The force pattern f_hat [N per unit load factor].
    functionals : dict {name: ndarray, shape (n_free,)}
        Linear functionals of q: the controls and measured displacements [mm].
    symmetry_factor : float
        Copies of the model in the whole specimen (the recorded work and energies are the whole's).
    """

    disc: object
    n_free: int
    element_dofs: np.ndarray
    blocks: dict
    load_vector: np.ndarray
    functionals: dict
    symmetry_factor: float

    def initial_history(self) -> np.ndarray:
        """History variables of the virgin material."""

    def onset_ratio(self, history: np.ndarray) -> float:
        """How far the history is from the onset of softening (< 1: still elastic)."""

    def evaluate(self, q: np.ndarray, history_old: np.ndarray):
        """``(residual, arrays, references)``: internal forces r(q) (shape (n_free,)), the element arrays
        (:class:`~fracid.fem.forms.ElementArrays`: tangents, trial ``kappa`` = history, ``omega``) and the
        norm that makes each field's residual relative."""

    def fields(self, q: np.ndarray, history: np.ndarray, omega: np.ndarray) -> dict:
        """Named fields of a converged state (nodal ``u``, point ``kappa`` and ``omega``, ...)."""

    def elastic_energy(self, q: np.ndarray, history: np.ndarray, omega: np.ndarray) -> float:
        """Recoverable energy of a converged state [N mm]."""
