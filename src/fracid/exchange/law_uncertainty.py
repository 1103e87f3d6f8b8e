"""How far to trust the exported law's strength and fracture energy: the identification's covariance carried to
them by linearisation (:func:`law_std`)."""

from __future__ import annotations

import numpy as np

#: the central differences' step in the parameters' std: small against the uncertainty, large against the noise of
#: a bar run's adaptive steps (relative 1e-4 on the energy)
STEP_IN_STD = 0.1


def _strength_and_energy(identified, params) -> np.ndarray:
    table = identified.model.cohesive_law(params)
    return np.array([table.strength, table.fracture_energy])


def law_std(identified) -> tuple[float, float] | None:
    """(std of the strength [MPa], std of the fracture energy [N/mm]) of the law at the estimate, from the
    identification's covariance C by central differences of the law over the identified parameters
    (J C J^T); None without a finite covariance. Linearised: trust it as far as the Gaussian of C (the
    identification's report says whether the posterior departs from it)."""
    C = identified.covariance
    if C is None or not np.all(np.isfinite(C)):
        return None
    names, std = list(identified.std), np.array(list(identified.std.values()))
    J = np.zeros((2, len(names)))
    for j, name in enumerate(names):
        if std[j] == 0.0:
            continue
        step = STEP_IN_STD * std[j]
        value = getattr(identified.params, name)
        up = _strength_and_energy(identified, identified.params.replace(**{name: value + step}))
        down = _strength_and_energy(identified, identified.params.replace(**{name: value - step}))
        J[:, j] = (up - down) / (2.0 * step)
    variance = np.clip(np.diag(J @ C @ J.T), 0.0, None)
    return float(np.sqrt(variance[0])), float(np.sqrt(variance[1]))
