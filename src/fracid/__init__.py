"""fracid: parameter identification for models of localized failure in quasi-brittle materials.

Units throughout: N, mm, MPa (N/mm^2); the gradient parameter ``c`` in mm^2.
"""

from fracid.fem.parameters import DamageParameters
from fracid.fem.path_following import ConvergenceError, PathResult, StepOptions, follow_path
from fracid.fem.solver import NewtonOptions
from fracid.specimens.bar import BarWithWeakZone
from fracid.forward import simulate

__all__ = [
    "BarWithWeakZone",
    "ConvergenceError",
    "DamageParameters",
    "NewtonOptions",
    "PathResult",
    "StepOptions",
    "follow_path",
    "simulate",
]
__version__ = "0.1.0"
