"""Discrete cohesive crack (Hordijk) along the ligament of the notched beam ([6/6] item 3)."""

import numpy as np
import pytest

from fracid.fem.material.cohesive import CohesiveParameters, dissipated_energy_density
from fracid.fem.formulations.cohesive_problem import law_crack_traction
from fracid.fem.material.laws import HordijkLaw
from fracid.models import CohesiveCrackModel
from fracid.specimens.beam import NotchedBeam

PARAMS = CohesiveParameters(E=37000.0, nu=0.2, ft=3.0, Gf=0.1)


def test_crack_traction_tangent_matches_finite_differences():
    ft, wc, c1, c2 = PARAMS.law()
    penalty = 1e6
    w0 = ft / penalty
    w = np.array([-1e-5, 0.5 * w0, 0.3 * wc, 0.6 * wc, 0.2 * wc, 1.2 * wc])
    w_max = np.array([0.0, 0.0, 0.25 * wc, 0.7 * wc, 0.4 * wc, 0.0])  # closed, uncracked, loading, unloading ...
    sigma, tangent, _ = law_crack_traction(HordijkLaw(), PARAMS, w, w_max, penalty)
    h = 1e-7 * wc
    plus, _, _ = law_crack_traction(HordijkLaw(), PARAMS, w + h, w_max, penalty)
    minus, _, _ = law_crack_traction(HordijkLaw(), PARAMS, w - h, w_max, penalty)
    np.testing.assert_allclose(tangent, (plus - minus) / (2 * h), rtol=1e-5)
    assert sigma[0] < 0 and sigma[1] == pytest.approx(0.5 * ft) and sigma[-1] == 0.0


@pytest.fixture(scope="module")
def separated():
    beam = NotchedBeam(h_fine=2.0, h_coarse=6.0)
    problem = CohesiveCrackModel().build(beam, PARAMS)
    result = CohesiveCrackModel().simulate(beam, PARAMS, target=7.0, stop_force_fraction=None, field_steps="last")
    return beam, problem, result


def test_dissipated_energy_at_separation_is_gf_times_the_ligament_area(separated):
    beam, problem, result = separated
    ligament = (beam.depth - beam.notch_depth) * beam.thickness
    dissipated = result.observables["dissipated_energy"][-1]
    assert result.force[-1] < 0.002 * result.force.max()  # separated: the force has gone
    # the work still to come in the tail, F ~ 1 / delta^2: int_delta^inf F = F delta (about 1.5 %)
    tail = result.force[-1] * result.observables["load_point_displacement"][-1]
    assert dissipated + tail == pytest.approx(PARAMS.Gf * ligament, rel=0.02)
    assert dissipated == pytest.approx(PARAMS.Gf * ligament, rel=0.03)
    # the global energy balance equals the energy the crack dissipated, point by point
    w_max = result.fields[max(result.fields)]["crack_opening_max"]
    w0 = PARAMS.ft / problem.penalty
    local = np.sum(dissipated_energy_density(np.maximum(w_max - w0, 0.0), *PARAMS.law()) * problem.dA)
    assert dissipated == pytest.approx(local, rel=0.01)


def test_cohesive_beam_curve_peaks_then_softens(separated):
    _, _, result = separated
    peak = int(np.argmax(result.force))
    assert 0 < peak < len(result.force) - 10
    assert np.all(np.diff(result.observables["crack_length"]) >= -1e-9)  # the crack only grows


@pytest.mark.slow
def test_twin_experiment_recovers_ft_and_gf_noise_free():
    from fracid.inverse.core.forward_operator import Observation, ForwardOperator
    from fracid.inverse.core.space import ParameterSpace
    from fracid.inverse.methods.strategy import identify
    from fracid.inverse.studies.twin import synthetic_data
    from fracid.runtime.executors import make_executor

    beam = NotchedBeam(h_fine=4.0, h_coarse=8.0)  # coarse: data and model share the mesh
    op = ForwardOperator([Observation(beam, np.linspace(0.01, 0.3, 15), control="cmod")], PARAMS, ("ft", "Gf"),
                         model=CohesiveCrackModel())
    data = synthetic_data(op, [3.0, 0.1], {"global:relative": 0.01}, seed=None)
    space = ParameterSpace(("ft", "Gf"), [1.5, 0.04], [5.0, 0.25])
    with make_executor(2) as executor:
        result = identify(op, data.y, data.covariance, space, n=12, k=3, groups=[np.arange(15)], executor=executor)
    np.testing.assert_allclose(result.x, [3.0, 0.1], rtol=0.01)
    assert result.units == {"ft": "MPa", "Gf": "N/mm"}
