"""Young's modulus from the initial slope of a measured curve.

Before damage the model is linear in E: force / control = E * k1, with k1 the specimen's elastic
stiffness per unit modulus. The measured initial slope is the least-squares slope through the origin
of the points before the peak whose force is below a fraction of the peak. One elastic forward run
gives k1, so E = slope / k1. The run goes through the forward-model interface (:mod:`fracid.models`).
"""

from __future__ import annotations

import numpy as np

from fracid.models import DamageModel


def initial_slope(control, force, fraction: float = 0.3) -> float:
    """Least-squares slope through the origin of the pre-peak points with force < fraction * peak [N/mm]."""
    control, force = np.asarray(control, float), np.asarray(force, float)
    if not 0.0 < fraction < 1.0:
        raise ValueError(f"fraction = {fraction}: it must be in (0, 1)")
    peak = int(np.argmax(force))
    use = (np.arange(force.size) <= peak) & (force < fraction * force[peak]) & (control > 0)
    if use.sum() < 2:
        raise ValueError(f"fewer than 2 measured points before the peak below {fraction:g} of it: "
                         "sample the data more finely or raise the fraction")
    return float(np.sum(control[use] * force[use]) / np.sum(control[use] ** 2))


def modulus_from_initial_slope(specimen, params, control, force, *, control_name=None, fraction: float = 0.3,
                               model=None):
    """E [MPa] that makes the model's elastic stiffness equal the measured initial slope.

    ``model`` is the forward model (:mod:`fracid.models`; ``DamageModel("gradient")`` when None); its
    parameters ``params`` have ``E`` and the damage threshold ``kappa_i``, raised here so that the
    run stays elastic.

    Returns
    -------
    E : float
    slope : float
        Measured initial slope [N/mm].
    stiffness : float
        The model's elastic stiffness at ``params.E`` [N/mm].
    """
    slope = initial_slope(control, force, fraction)
    elastic = params.replace(kappa_i=1.0)  # no damage: a linear run
    probe = float(np.asarray(control)[np.argmax(force)]) * 1e-3
    model = DamageModel("gradient") if model is None else model
    run = model.simulate(specimen, elastic, control=control_name, target=probe, stop_force_fraction=None)
    stiffness = float(run.force[-1] / run.control[-1])
    return params.E * slope / stiffness, slope, stiffness
