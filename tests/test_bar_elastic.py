"""Elastic bar: the exact linear solution (piecewise-linear displacement, force = stiffness x u)."""

import numpy as np
import pytest

import fracid


@pytest.mark.parametrize("weakening", ["modulus", "area"])
@pytest.mark.parametrize("n", [7, 40])
def test_elastic_bar_is_exact(weakening, n):
    params = fracid.DamageParameters(E=30000.0, kappa_i=1e-3)
    bar = fracid.BarWithWeakZone(length=80.0, area=25.0, weak_zone_width=20.0, weak_zone_factor=0.5, weakening=weakening, n_elements=n)
    u_end = 0.01  # well below onset (0.08 mm for a uniform bar)
    result = fracid.simulate(bar, params, target=u_end, stop_force_fraction=None)
    x = bar.vertices()
    x_weak = bar.weak_zone_width
    compliance = (bar.length - x_weak) / (params.E * bar.area) + x_weak / (0.5 * params.E * bar.area)
    force = u_end / compliance
    assert result.force[-1] == pytest.approx(force, rel=1e-10)
    # exact displacement at every node (vertices and mid-points)
    nodes = np.sort(np.concatenate([x, 0.5 * (x[:-1] + x[1:])]))
    stiffness_a = params.E * bar.area * bar.weakness(nodes)  # step profile: EA along the bar
    a, b = 30.0, 50.0
    u_exact = force * (np.minimum(nodes, a) + np.clip(nodes - a, 0, b - a) / 0.5 + np.clip(nodes - b, 0, None)) / (params.E * bar.area)
    assert stiffness_a.shape == nodes.shape
    np.testing.assert_allclose(result.fields[result.n_steps]["u"], u_exact, rtol=1e-10, atol=1e-14)
    assert result.observables["damaged_zone_width"][-1] == 0.0
    assert np.all(result.fields[result.n_steps]["omega"] == 0.0)
    # elastic energy = external work for a linear response
    assert result.observables["dissipated_energy"][-1] == pytest.approx(0.0, abs=1e-12 * result.observables["external_work"][-1])
