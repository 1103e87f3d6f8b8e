import numpy as np
import pytest

import fracid
from fracid.inverse.studies.elastic import initial_slope, modulus_from_initial_slope


def test_initial_slope_through_origin():
    control = np.linspace(0.0, 1.0, 11)
    force = np.where(control < 0.5, 200.0 * control, 100.0 - 50 * (control - 0.5))
    force[5] = 100.0
    assert initial_slope(control, force, fraction=0.5) == pytest.approx(200.0)
    with pytest.raises(ValueError, match="fewer than 2"):
        initial_slope(control, force, fraction=0.05)


def test_modulus_recovered_from_synthetic_bar_curve():
    bar = fracid.BarWithWeakZone(n_elements=40)
    truth = fracid.DamageParameters(E=25000.0)
    run = fracid.simulate(bar, truth, target=0.03, stop_force_fraction=None, checkpoints=np.linspace(0.001, 0.03, 30))
    E, slope, stiffness = modulus_from_initial_slope(bar, truth.replace(E=40000.0), run.control, run.force)
    assert E == pytest.approx(25000.0, rel=1e-6)
    assert stiffness == pytest.approx(slope * 40000.0 / 25000.0, rel=1e-6)
