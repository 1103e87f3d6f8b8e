"""KNN search, strategy and twin experiments (synthetic data from known parameters, identified back)."""

import json

import numpy as np
import pytest

import fracid
from fracid.inverse.core.forward_operator import ForwardOperator, Observation
from fracid.inverse.methods.kalman import kalman_filter
from fracid.inverse.core.space import ParameterSpace
from fracid.inverse.core.misfit import objective
from fracid.inverse.methods.knn import design, knn_from_population, knn_search
from fracid.inverse.methods.strategy import identify

BAR = fracid.BarWithWeakZone(n_elements=100)
POINTS = np.linspace(0.004, 0.03, 16)  # end displacement [mm]: pre-peak, peak and softening
TRUTH = np.array([2.0, 250.0])  # c [mm^2], beta [-]
SPACE = ParameterSpace(("c", "beta"), [0.5, 100.0], [4.0, 500.0])
GROUPS = [range(i, i + 4) for i in range(0, 16, 4)]


@pytest.fixture(scope="module")
def bar_operator():
    return ForwardOperator([Observation(BAR, POINTS)], fracid.DamageParameters(), ("c", "beta"))


@pytest.fixture(scope="module")
def bar_data(bar_operator):
    y = bar_operator(TRUTH).y
    std = 0.02 * np.abs(y).max()  # 2 % of the peak force
    return y, std


def test_designs_respect_bounds_and_scale():
    space = ParameterSpace(("c", "beta"), [0.5, 10.0], [8.0, 1000.0], log=(False, True))
    for method, n, size in (("sobol", 32, 32), ("lhs", 20, 20), ("grid", 5, 25)):
        pts = design(space, n, method)
        assert pts.shape == (size, 2)
        assert np.all(pts >= space.lower) and np.all(pts <= space.upper)
    # log scale: as many points per decade
    pts = design(space, 64, "sobol")
    assert abs(np.sum(pts[:, 1] < 100.0) - 32) <= 6
    np.testing.assert_allclose(space.from_unit(space.to_unit(pts)), pts)
    with pytest.raises(ValueError, match="log scale"):
        ParameterSpace(("c",), [0.0], [1.0], log=(True,))
    with pytest.raises(ValueError, match="lower"):
        ParameterSpace(("c",), [2.0], [1.0])


def test_objective_and_ranking_with_failures():
    C = np.diag([1.0, 4.0])
    Y = np.array([[1.0, 2.0], [0.0, 0.0], [np.nan, np.nan], [1.0, 4.0]])
    f = objective([1.0, 2.0], C, Y)
    np.testing.assert_allclose(f, [0.0, 2.0, np.inf, 1.0])
    pts = np.array([[1.0], [2.0], [3.0], [4.0]])
    space = ParameterSpace(("c",), [1.0], [4.0])
    res = knn_from_population(space, pts, Y, ["ok", "ok", "failed", "ok"], ["", "", "diverged", ""], [1.0, 2.0], C, 2)
    assert res.order.tolist() == [0, 3, 1, 2]  # the failed run ranks last
    assert res.x0[0] == pytest.approx(2.5)
    assert "failed: diverged" in res.table()
    with pytest.raises(ValueError, match="k = 4"):
        knn_from_population(space, pts, Y, ["ok", "ok", "failed", "ok"], [""] * 4, [1.0, 2.0], C, 4)


def test_failed_forward_runs_are_recorded_and_do_not_stop_the_study(bar_operator, bar_data):
    y, std = bar_data
    space = ParameterSpace(("c", "beta"), [0.01, 100.0], [4.0, 20000.0], log=(True, True))
    res = knn_search(bar_operator, y, np.eye(y.size) * std**2, space, n=16, k=3)
    assert res.n_failed > 0  # brittle corners of the space snap back under end-displacement control
    failed = [i for i, s in enumerate(res.status) if s != "ok"]
    assert all("forward run failed" in res.errors[i] for i in failed)
    assert np.all(np.isinf(res.f[failed])) and set(res.order[-len(failed):]) == set(failed)
    # the Kalman filter cannot do without its own point: it stops, says why and never raises
    result = kalman_filter(bar_operator, y, np.eye(y.size) * std**2, np.array([0.02, 20000.0]), np.diag([0.01, 1e6]))
    assert result.failed and result.status.startswith("failed:") and "forward run failed" in result.status
    assert result.failures and result.failures[0]["x"] == [0.02, 20000.0]


def test_study_counts_failed_runs_and_stays_in_the_bounds(bar_operator, bar_data):
    """A population with failing corners: the study goes on and states the failures in its summary (verdict.txt)."""
    from fracid.data import ExperimentalData
    from fracid.inverse.studies.study import StudySettings, run_study

    y, std = bar_data
    data = ExperimentalData(control=POINTS, y=y, covariance=np.eye(y.size) * std**2, blocks=[("global", 0, y.size)])
    space = ParameterSpace(("c", "beta"), [0.01, 100.0], [4.0, 20000.0], log=(True, True))
    settings = StudySettings().replace(starts=0, replicates=0, n=16, k=3, groups=GROUPS)
    study = run_study(bar_operator, data, space, settings)
    total, failed = study.runs["KNN"]
    assert total == 16 and failed > 0 and f"KNN 16 ({failed} failed)" in study.summary()
    assert f"{failed} of 16 KNN runs failed" in study.summary()
    ident = study.identification
    assert np.all(ident.x >= space.lower) and np.all(ident.x <= space.upper) and ident.status


def test_twin_noise_free_bar(bar_operator, bar_data):
    y, _ = bar_data
    C_exp = np.eye(y.size) * (1e-3 * np.abs(y).max()) ** 2  # noise-free: data far more precise than the prior
    # KNN on a grid through the truth: the run at the truth reproduces the data (f = 0) and ranks first.
    # (For a truth between grid points, the nearest point in parameter space need not fit best: c and
    # beta trade off along a valley of the objective, which the next assertion measures.)
    grid = ParameterSpace(("c", "beta"), [1.0, 150.0], [3.0, 350.0])
    knn = knn_search(bar_operator, y, C_exp, grid, n=5, method="grid", k=4)
    nearest = np.argmin(np.sum((grid.to_unit(knn.points) - grid.to_unit(TRUTH)) ** 2, axis=1))
    assert knn.order[0] == nearest and knn.f[nearest] < 1e-12
    res = identify(bar_operator, y, C_exp, SPACE, n=32, k=4, groups=GROUPS)
    np.testing.assert_allclose(res.x, TRUTH, rtol=0.01)
    assert res.converged
    # one global curve of one size: c and beta strongly correlated (the thesis's finding)
    assert abs(res.correlation[0, 1]) > 0.9


def test_twin_noisy_bar_truth_within_two_sigma(bar_operator, bar_data, tmp_path):
    y, std = bar_data
    rng = np.random.default_rng(7)
    noisy = y + rng.normal(scale=std, size=y.size)
    res = identify(bar_operator, noisy, np.eye(y.size) * std**2, SPACE, n=32, k=4, groups=GROUPS)
    assert np.all(np.abs(res.x - TRUTH) <= 2 * res.std), (res.x, res.std)
    saved = json.loads(res.save(tmp_path / "result.json").read_text())
    assert saved["names"] == ["c", "beta"] and len(saved["history"]) == len(res.history)
    assert saved["runs"]["knn"] == 32 and saved["runs"]["kalman"] > 0


@pytest.mark.slow
def test_twin_noise_free_dogbone():
    from fracid.specimens.dogbone import DogBone

    specimen = DogBone(size=50.0, h_fine=2.5)
    params = fracid.DamageParameters(E=30000.0, kappa_i=1e-4, alpha=0.99, beta=300.0, c=16.0)
    points = np.linspace(0.004, 0.05, 12)
    op = ForwardOperator([Observation(specimen, points)], params, ("c", "beta"))
    truth = np.array([16.0, 300.0])
    y = op(truth).y
    std = 1e-3 * np.abs(y).max()  # noise-free: data far more precise than the prior
    space = ParameterSpace(("c", "beta"), [6.0, 150.0], [30.0, 600.0])
    res = identify(op, y, np.eye(y.size) * std**2, space, n=16, k=4, groups=[range(0, 6), range(6, 12)])
    np.testing.assert_allclose(res.x, truth, rtol=0.01)


@pytest.mark.slow
def test_twin_noisy_dogbone_truth_within_two_sigma():
    from fracid.specimens.dogbone import DogBone

    specimen = DogBone(size=50.0, h_fine=2.5)
    params = fracid.DamageParameters(E=30000.0, kappa_i=1e-4, alpha=0.99, beta=300.0, c=16.0)
    op = ForwardOperator([Observation(specimen, np.linspace(0.004, 0.05, 12))], params, ("c", "beta"))
    truth = np.array([16.0, 300.0])
    y = op(truth).y
    std = 0.02 * np.abs(y).max()
    noisy = y + np.random.default_rng(11).normal(scale=std, size=y.size)
    space = ParameterSpace(("c", "beta"), [6.0, 150.0], [30.0, 600.0])
    res = identify(op, noisy, np.eye(y.size) * std**2, space, n=16, k=4, groups=[range(0, 6), range(6, 12)])
    assert np.all(np.abs(res.x - truth) <= 2 * res.std), (res.x, res.std)


@pytest.mark.slow
def test_global_and_local_blocks_from_experimental_data(bar_operator):
    """Force curve plus the damaged-zone width (local data) as a second block, through fracid.data."""
    from fracid.data import ExperimentalData, stack
    from fracid.inverse.methods.strategy import identify_data

    op = ForwardOperator([Observation(BAR, POINTS, name="global"),
                          Observation(BAR, POINTS[4:], quantity="damaged_zone_width", name="local")],
                         fracid.DamageParameters(), ("c", "beta"))
    y = op(TRUTH).y
    force, width = y[:16], y[16:]
    blocks = [ExperimentalData(POINTS, force, np.eye(16) * (1e-3 * force.max()) ** 2, (("global", 0, 16),), ("force",)),
              ExperimentalData(POINTS[4:], width, np.eye(12) * (1e-3 * width.max()) ** 2, (("local", 0, 12),), ("width",))]
    data = stack(*blocks)
    res = identify_data(op, data, SPACE, n=32, k=4, groups=[range(0, 8), range(8, 16), range(16, 28)])
    np.testing.assert_allclose(res.x, TRUTH, rtol=0.01)
    assert [b[0] for b in res.blocks] == ["global", "local"]
    # the width of the damaged zone fixes the internal length: the c-beta correlation drops
    global_only = identify(bar_operator, force, blocks[0].covariance, SPACE, n=32, k=4, groups=GROUPS)
    assert abs(res.correlation[0, 1]) < abs(global_only.correlation[0, 1])
    with pytest.raises(ValueError, match="data hold"):
        identify_data(bar_operator, data, SPACE)


def test_force_and_local_data_of_one_test_share_one_forward_run(monkeypatch):
    from fracid.models import DamageModel

    both = ForwardOperator([Observation(BAR, POINTS, name="global"),
                            Observation(fracid.BarWithWeakZone(n_elements=100), POINTS[4:],
                                        quantity="damaged_zone_width", name="local", damage_threshold=0.3)],
                           fracid.DamageParameters(), ("c", "beta"))
    separate = [ForwardOperator([obs], fracid.DamageParameters(), ("c", "beta")) for obs in both.observations]
    calls = []
    original = DamageModel.simulate
    monkeypatch.setattr(DamageModel, "simulate", lambda self, *a, **kw: calls.append(kw) or original(self, *a, **kw))
    y = both(TRUTH).y
    assert len(calls) == 1 and calls[0]["damage_threshold"] == 0.3  # equal frozen specimens: one run
    # equal up to the Newton tolerance: the shared run also stops at the force block's checkpoints
    np.testing.assert_allclose(y, np.concatenate([op(TRUTH).y for op in separate]), rtol=1e-4)
    assert len(calls) == 3
    # a threshold changes the measured width, so it is part of the observation
    loose = ForwardOperator([Observation(BAR, POINTS[4:], quantity="damaged_zone_width")], fracid.DamageParameters(),
                            ("c", "beta"))
    assert np.all(loose(TRUTH).y >= y[16:]) and np.any(loose(TRUTH).y > y[16:])
