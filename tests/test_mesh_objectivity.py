"""Mesh objectivity of the gradient model, mesh dependence of the local model (both directions)."""

import pytest

import fracid
from fracid.models import DamageModel

PARAMS = fracid.DamageParameters(alpha=0.99, beta=300.0, c=1.0)


def run(n, regularization, profile, control, target):
    bar = fracid.BarWithWeakZone(n_elements=n, profile=profile)
    result = fracid.simulate(bar, PARAMS, model=DamageModel(regularization), control=control, target=target, stop_force_fraction=None)
    assert result.status == "target reached"
    return result.peak_force, result.observables["dissipated_energy"][-1], result.force[-1]


def test_gradient_model_is_mesh_objective():
    # end displacement 0.04 mm: the force is down to about 7 % of the peak
    peak_200, energy_200, final_200 = run(200, "gradient", "step", "end_displacement", 0.04)
    peak_400, energy_400, final_400 = run(400, "gradient", "step", "end_displacement", 0.04)
    assert final_200 < 0.1 * peak_200  # the comparison covers the softening branch
    assert peak_400 == pytest.approx(peak_200, rel=0.01)
    assert energy_400 == pytest.approx(energy_200, rel=0.01)


def test_local_model_is_mesh_dependent():
    # the hat-shaped weak zone makes the local model localise in the central elements;
    # elongation control of the weak zone passes the snap-back of the local model
    peak_200, energy_200, _ = run(200, "local", "hat", "weak_zone_elongation", 0.01)
    peak_400, energy_400, final_400 = run(400, "local", "hat", "weak_zone_elongation", 0.01)
    assert final_400 < 0.05 * peak_400
    assert energy_400 < 0.75 * energy_200  # the energy goes with the element size (ratio ~ 0.55)
    assert peak_400 < peak_200
