"""fracid: parameter identification for models of localized failure in quasi-brittle materials.

Units throughout: N, mm, MPa (N/mm^2); the gradient parameter ``c`` in mm^2.
"""

import importlib

# imported when first used (PEP 562), so that `fracid` on the command line starts at once and a Ctrl-C
# while it starts finds the command's handler, not a half-imported scipy
_EXPORTS = {
    "BarWithWeakZone": "fracid.specimens.bar",
    "ConvergenceError": "fracid.fem.path.path_following",
    "DamageParameters": "fracid.fem.material.parameters",
    "NewtonOptions": "fracid.fem.path.solver",
    "PathResult": "fracid.fem.path.path_following",
    "StepOptions": "fracid.fem.path.path_following",
    "follow_path": "fracid.fem.path.path_following",
    "simulate": "fracid.models.forward",
}


def __getattr__(name):
    if name in _EXPORTS:
        value = getattr(importlib.import_module(_EXPORTS[name]), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module 'fracid' has no attribute {name!r}")


def __dir__():
    return sorted([*globals(), *_EXPORTS])


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
