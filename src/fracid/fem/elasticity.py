"""Strain states (kinematic assumptions): the number of strain components and the unit elastic matrix (E = 1).

The equivalent strain that drives damage is a material law (:mod:`fracid.fem.laws`), not part of the
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


@dataclass(frozen=True)
class StrainState:
    """A kinematic assumption: its name, number of strain components and unit elastic matrix."""

    name: str
    n_components: int
    unit_elastic_matrix: Callable[[float], np.ndarray]


UNIAXIAL = StrainState("uniaxial", 1, uniaxial_matrix)
PLANE_STRESS = StrainState("plane stress", 3, plane_stress_matrix)
