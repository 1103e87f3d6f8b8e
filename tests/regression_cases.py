"""The forward runs of the regression test (tests/test_regression_curves.py): every model on every
specimen it ran on before the specimen/model seams were redrawn, on small meshes.

``python tests/regression_cases.py`` rewrites ``tests/data/regression_curves.npz``: do that only when
a change of the curves is intended (and say so in the commit).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

import fracid
from fracid.specimens.beam import NotchedBeam
from fracid.fem.material.cohesive import CohesiveParameters
from fracid.models import model_from_type
from fracid.specimens.dogbone import DogBone
from fracid.specimens.strip import TensionStrip

REFERENCE = Path(__file__).parent / "data" / "regression_curves.npz"

DAMAGE = fracid.DamageParameters(E=37000.0, nu=0.2, kappa_i=1.1e-4, alpha=0.99, beta=500.0, c=4.0, eta=10.0)
HORDIJK = CohesiveParameters(E=37000.0, nu=0.2, ft=3.0, Gf=0.1)
BAR = fracid.DamageParameters(c=2.0, beta=250.0)


def cases():
    """name -> (model type, specimen, parameters, simulate options)."""
    beam = NotchedBeam(h_fine=4.0, h_coarse=10.0)
    dogbone = DogBone(size=50.0, h_fine=3.0)
    hinged = DogBone(size=50.0, h_fine=3.0, platens="hinged")
    bar = fracid.BarWithWeakZone(n_elements=40)
    out = {}
    for model in ("gradient-damage", "local-damage", "integral-damage"):
        out[f"bar/{model}"] = (model, bar, BAR, {})
        out[f"beam/{model}"] = (model, beam, DAMAGE, {"target": 0.12})
        out[f"dogbone/{model}"] = (model, dogbone, DAMAGE, {"target": 0.02})
    out["dogbone-hinged/gradient-damage"] = ("gradient-damage", hinged, DAMAGE, {"target": 0.02})
    out["beam/cohesive-crack"] = ("cohesive-crack", beam, HORDIJK, {"target": 0.12})
    out["beam/crack-band"] = ("crack-band", beam, HORDIJK, {"target": 0.12})
    out["strip/crack-band"] = ("crack-band", TensionStrip(n_elements=11), HORDIJK, {})
    return out


def run(name):
    """Control, force and every observable of case ``name``, as a dict of arrays."""
    model, specimen, params, options = cases()[name]
    result = model_from_type(model).simulate(specimen, params, stop_force_fraction=None, **options)
    arrays = {"control": np.asarray(result.control), "force": np.asarray(result.force)}
    arrays.update({key: np.asarray(value, dtype=float) for key, value in result.observables.items()})
    return arrays


def main():
    stored = {}
    for name in cases():
        for key, value in run(name).items():
            stored[f"{name}:{key}"] = value
        print(name, "done")
    np.savez_compressed(REFERENCE, **stored)


if __name__ == "__main__":
    main()
