"""Direct differentiation of a run against central differences of runs at the same control values (shared by the
PF-CZM's tests)."""

import numpy as np

from fracid.fem.path.solver import NewtonOptions
from fracid.models import StepOptions

QUANTITIES = ("force", "external_work", "elastic_energy")


def fixed_steps(target: float, n: int, **options) -> dict:
    """``simulate`` options with one step per checkpoint (n of them up to ``target``), the equilibrium and the phase
    field converged to 1e-10 so that differences of runs see no Newton noise."""
    checkpoints = np.linspace(0.0, target, n + 1)[1:]
    return dict(target=target, checkpoints=checkpoints, stop_force_fraction=None,
                steps=StepOptions(initial=target / n, onset_fraction=1.0, max_factor=1.0, jump_to_onset=False),
                newton=NewtonOptions(field_rtol={"d": 1e-10}, rtol_u=1e-10), **options)


def largest_errors(model, specimen, params, names, options, relative_step=1e-6):
    """``(force at the checkpoints, {(name, quantity): max |DDM - central difference| / max |difference|})``; a
    parameter at 0 gets the absolute step ``relative_step``."""
    run = model.simulate(specimen, params, sensitivities=names, **options)
    rows = np.array([int(np.argmin(np.abs(run.control - c))) for c in options["checkpoints"]])
    errors = {}
    for k, name in enumerate(names):
        value = getattr(params, name)
        step = relative_step * value if value != 0.0 else relative_step
        up, down = (model.simulate(specimen, params.replace(**{name: value + s * step}), **options) for s in (1.0, -1.0))
        assert np.array_equal(up.control, run.control) and np.array_equal(down.control, run.control), name
        for quantity in QUANTITIES:
            curve = (lambda r: r.force) if quantity == "force" else (lambda r, q=quantity: r.observables[q])
            fd = (curve(up)[rows] - curve(down)[rows]) / (2.0 * step)
            errors[name, quantity] = float(np.max(np.abs(run.derivatives[quantity][rows, k] - fd)) / np.max(np.abs(fd)))
    return run.force[rows], errors
