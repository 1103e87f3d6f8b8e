"""Strain states (kinematic assumptions): the number of strain components and the unit elastic matrix (E = 1).

The equivalent strain that drives damage is a material law (:mod:`fracid.fem.material.laws`), not part of the
kinematics."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np


def uniaxial_matrix(nu: float) -> np.ndarray:
    """Elastic matrix of a 1D bar for E = 1 (sigma = E eps)."""
    return np.ones((1, 1))


def plane_stress_matrix(nu: float) -> np.ndarray:
    """Plane-stress elastic matrix for E = 1, acting on (exx, eyy, gxy)."""
    return np.array([[1.0, nu, 0.0], [nu, 1.0, 0.0], [0.0, 0.0, 0.5 * (1.0 - nu)]]) / (1.0 - nu * nu)


def uniaxial_matrix_derivative(nu: float) -> np.ndarray:
    """d/d nu of :func:`uniaxial_matrix`: zero."""
    return np.zeros((1, 1))


def plane_stress_matrix_derivative(nu: float) -> np.ndarray:
    """d/d nu of :func:`plane_stress_matrix`."""
    numerator = np.array([[1.0, nu, 0.0], [nu, 1.0, 0.0], [0.0, 0.0, 0.5 * (1.0 - nu)]])
    d_numerator = np.array([[0.0, 1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, -0.5]])
    return d_numerator / (1.0 - nu * nu) + numerator * 2.0 * nu / (1.0 - nu * nu) ** 2


@dataclass(frozen=True)
class StrainState:
    """A kinematic assumption: its name, number of strain components, unit elastic matrix and the
    matrix's derivative with respect to Poisson's ratio."""

    name: str
    n_components: int
    unit_elastic_matrix: Callable[[float], np.ndarray]
    unit_elastic_matrix_derivative: Callable[[float], np.ndarray]


UNIAXIAL = StrainState("uniaxial", 1, uniaxial_matrix, uniaxial_matrix_derivative)
PLANE_STRESS = StrainState("plane stress", 3, plane_stress_matrix, plane_stress_matrix_derivative)
