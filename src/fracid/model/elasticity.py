"""Strain states: the unit elastic matrix (E = 1) and the matching equivalent strain."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np

from fracid.model.equivalent_strain import modified_von_mises_plane_stress, modified_von_mises_uniaxial


def uniaxial_matrix(nu: float) -> np.ndarray:
    """Elastic matrix of a 1D bar for E = 1 (sigma = E eps)."""
    return np.ones((1, 1))


def plane_stress_matrix(nu: float) -> np.ndarray:
    """Plane-stress elastic matrix for E = 1, acting on (exx, eyy, gxy)."""
    return np.array([[1.0, nu, 0.0], [nu, 1.0, 0.0], [0.0, 0.0, 0.5 * (1.0 - nu)]]) / (1.0 - nu * nu)


@dataclass(frozen=True)
class StrainState:
    """A kinematic assumption: number of strain components, unit elastic matrix and equivalent strain."""

    name: str
    n_components: int
    unit_elastic_matrix: Callable[[float], np.ndarray]
    equivalent_strain: Callable


UNIAXIAL = StrainState("uniaxial", 1, uniaxial_matrix, modified_von_mises_uniaxial)
PLANE_STRESS = StrainState("plane stress", 3, plane_stress_matrix, modified_von_mises_plane_stress)
