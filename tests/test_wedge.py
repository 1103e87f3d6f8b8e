"""The wedge-splitting test, built through the mesh mechanism: its geometry and groups, the splitting force,
the cohesive crack's energy, and a noise-free twin identification of (ft, Gf)."""

import math

import numpy as np
import pytest

import fracid
from fracid.fem.material.cohesive import CohesiveParameters
from fracid.inverse.core.forward_operator import ForwardOperator, Observation
from fracid.inverse.methods.gauss_newton import gauss_newton
from fracid.models import CohesiveCrackModel, DamageModel
from fracid.specimens import SPECIMENS
from fracid.specimens.wedge import WedgeSplitting

HORDIJK = CohesiveParameters(E=30000.0, nu=0.2, ft=3.0, Gf=0.1)


def test_geometry_groups_and_splitting_force():
    w = WedgeSplitting()
    d = w.describe()
    ligament = d.nodes[d.nodes_of("ligament")]
    np.testing.assert_allclose(ligament[:, 0], 0.0, atol=1e-12)
    assert ligament[:, 1].min() == 0.0 and ligament[:, 1].max() == pytest.approx(w.ligament)
    piece = d.nodes[d.nodes_of("loading_piece")]
    np.testing.assert_allclose(piece[:, 0], w.groove_width / 2)
    assert np.all(np.abs(piece[:, 1] - w.load_height) <= w.load_piece / 2 + 1e-9)
    np.testing.assert_allclose(d.nodes[d.nodes_of("support")], [[0.0, 0.0]])
    assert d.cells.shape[1] == 8 and d.crack.mirrored and d.symmetry_factor == 2.0
    assert w.splitting_force(2.0 * math.tan(math.radians(7.5))) == pytest.approx(1.0)
    assert SPECIMENS["wedge-splitting"] is WedgeSplitting


@pytest.mark.parametrize("field, value, words", [
    ("notch_depth", 20.0, "groove_depth = 30.0 < notch_depth = 20.0"),
    ("groove_width", 300.0, "groove_width = 300.0 < width"),
    ("load_height", 100.0, "the loading piece must lie on the groove wall"),
    ("wedge_angle", 190.0, "wedge_angle = 190.0 degrees"),
])
def test_bad_geometry_is_refused(field, value, words):
    with pytest.raises(ValueError, match=words):
        WedgeSplitting(**{field: value})


def test_the_cohesive_crack_dissipates_gf_times_the_ligament():
    """The halves turn about the support, so the crack's last stretch opens as theta y and the energy left to
    dissipate falls as 1 / opening. At a load-line opening of 3 mm (18 w_c) the crack has dissipated over 95 % of
    Gf A and never more than Gf A; extrapolated in 1 / opening from 2 and 3 mm to separation, Gf A within 2 %.
    After the peak the force falls monotonically towards zero (a rigid tie of the loading piece made it rise)."""
    w = WedgeSplitting(h_fine=10.0, h_coarse=40.0)
    run = CohesiveCrackModel().simulate(w, HORDIJK, stop_force_fraction=None, target=3.0, checkpoints=[2.0, 3.0])
    full = HORDIJK.Gf * w.ligament * w.thickness
    dissipated = run.observables["dissipated_energy"] / full
    assert np.all(np.diff(dissipated) > -1e-6) and 0.95 < dissipated[-1] <= 1.0
    at_2, at_3 = np.interp([2.0, 3.0], run.control, dissipated)
    assert (3.0 * at_3 - 2.0 * at_2) / (3.0 - 2.0) == pytest.approx(1.0, abs=0.02)
    after = run.force[np.argmax(run.force):]
    assert np.all(np.diff(after) <= 1e-6 * run.peak_force) and after[-1] < 0.01 * run.peak_force


def test_damage_model_runs_and_records_the_fpz_width():
    run = DamageModel().simulate(WedgeSplitting(h_fine=10.0, h_coarse=40.0), fracid.DamageParameters(E=30000.0),
                                 target=0.05, stop_force_fraction=None)
    assert run.peak_force > 0 and run.observables["fpz_width"][-1] > 0


@pytest.mark.slow
def test_twin_identification_of_ft_and_gf():
    """Noise-free data of the cohesive crack at (ft, Gf) = (3, 0.1): Gauss-Newton with the exact sensitivities
    from (2.6, 0.13) finds them back within 1 %."""
    w = WedgeSplitting(h_fine=10.0, h_coarse=40.0)
    points = np.linspace(0.02, 0.4, 12)
    operator = ForwardOperator([Observation(w, points, control="cmod")], HORDIJK, ("ft", "Gf"),
                               model=CohesiveCrackModel())
    truth = np.array([3.0, 0.1])
    y = operator(truth).y
    std = 0.01 * np.abs(y).max()
    result = gauss_newton(operator.differentiated(), y, np.eye(y.size) * std**2, np.array([2.6, 0.13]),
                          np.diag([1.0, 0.05]) ** 2, bounds=(np.array([1.0, 0.02]), np.array([6.0, 0.5])), tol=1e-3)
    np.testing.assert_allclose(result.x, truth, rtol=1e-2)
