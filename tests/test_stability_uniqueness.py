"""Uniqueness, stability and the verdict: analytic checks, then the bar (fast) for the nonlinear ones."""

from functools import partial

import numpy as np
import pytest

import fracid
from fracid.inverse.core.forward_operator import ForwardOperator, Observation
from fracid.inverse.core.space import ParameterSpace
from fracid.inverse.methods.kalman import kalman_filter
from fracid.inverse.methods.knn import knn_from_population
from fracid.inverse.studies.stability import noisy_replicates, stability
from fracid.inverse.studies.uniqueness import bounds_covariance, multi_start, objective_maps, starting_points, valley_level
from fracid.inverse.studies.verdict import DataDescription, parameter_verdicts

TRUTH = np.array([2.0, 250.0])
SPACE = ParameterSpace(("c", "beta"), [0.5, 100.0], [5.0, 600.0])


def test_noise_replicates_have_the_stated_covariance_and_are_reproducible():
    C = np.array([[4.0, 1.0], [1.0, 2.0]])
    draws = noisy_replicates([1.0, -1.0], C, 20000, seed=3)
    np.testing.assert_allclose(np.cov(draws.T), C, rtol=0.05, atol=0.05)
    np.testing.assert_array_equal(draws[:5], noisy_replicates([1.0, -1.0], C, 5, seed=3)[:5])


def test_valley_of_a_linear_model_follows_its_null_direction():
    # y depends on a + b only: the valley is the line a + b = const, correlation -1 in the population
    space = ParameterSpace(("a", "b"), [0.0, 0.0], [1.0, 1.0])
    g = np.linspace(0, 1, 21)
    points = np.array([[a, b] for a in g for b in g])
    A = np.array([[1.0, 1.0], [2.0, 2.0]])
    Y = points @ A.T
    knn = knn_from_population(space, points, Y, ["ok"] * len(points), [""] * len(points), A @ [0.3, 0.4],
                              np.eye(2) * 1e-2, k=5)
    [m] = objective_maps(knn)
    assert m.level == pytest.approx(valley_level(2)) and m.correlation < -0.9
    on_line = np.abs(m.points.sum(axis=1) - 0.7) < 0.02
    assert np.all(m.valley[on_line]) and m.valley.sum() < 0.2 * len(points)
    starts = starting_points(knn, 3, separation=0.25)
    assert len(starts) == 3 and np.min(np.linalg.norm(np.diff(starts, axis=0), axis=1)) >= 0.25


def test_verdict_rules_on_a_known_covariance():
    x = np.array([2.0, 250.0, 1e-4])
    std = np.array([0.6, 40.0, 2e-6])  # c and beta 30 % / 16 %, kappa_i 2 %
    corr = np.array([[1.0, 0.995, 0.0], [0.995, 1.0, 0.0], [0.0, 0.0, 1.0]])
    C = corr * np.outer(std, std)
    verdict = parameter_verdicts(["c", "beta", "kappa_i"], x, C, np.diag([4.0, 1e4, 1e-9]),
                                 data=DataDescription(sizes=1, local=False))
    assert verdict["c"].status == "correlated" and verdict["c"].partner == "beta"
    assert verdict["kappa_i"].status == "identified" and not verdict["kappa_i"].suggestions
    assert any("size" in s for s in verdict["c"].suggestions) and any("local" in s for s in verdict["c"].suggestions)
    text = verdict.text()
    assert "c: correlated with beta (r = +0.995)" in text and "kappa_i: identified" in text
    # uncorrelated but imprecise: not identifiable; with both extra data present, no size/local advice
    C2 = np.diag(std**2)
    v2 = parameter_verdicts(["c", "beta", "kappa_i"], x, C2, np.diag([0.5, 1e4, 1e-9]),
                            data=DataDescription(sizes=3, local=True))
    assert v2["c"].status == "not identifiable" and "more precise data" in v2["c"].suggestions[0]


def _bar_operator(lengths):
    observations = []
    for L in lengths:
        bar = fracid.BarWithWeakZone(length=L, n_elements=60)
        stop = 0.03 * L / 100 + 0.01
        observations.append(Observation(bar, np.linspace(0.004, stop, 10), name=f"L{L:g}"))
    return ForwardOperator(observations, fracid.DamageParameters(), ("c", "beta"))


@pytest.fixture(scope="module")
def executor():
    from fracid.runtime.executors import make_executor

    with make_executor(2) as ex:
        yield ex


@pytest.mark.slow
def test_scatter_under_noise_shrinks_with_two_sizes(executor):
    """Same noise level per point (s = 1 % of the peak); two bar lengths vs one."""
    scatter = {}
    for label, lengths in (("one", [100.0]), ("two", [100.0, 60.0])):
        op = _bar_operator(lengths)
        y = op(TRUTH).y
        C = np.eye(y.size) * (0.01 * y.max()) ** 2
        prior = np.diag((0.5 * TRUTH) ** 2)
        st = stability(op, y, C, TRUTH * [1.2, 1.1], prior, replicates=6, seed=5, executor=executor,
                       fit=partial(kalman_filter, groups=[np.arange(y.size)], max_iterations=6), bounds=fracid.DamageParameters.valid_bounds(("c", "beta")))
        assert st.ok.all() and st.noise_level == pytest.approx(np.sqrt(np.mean((0.01 * y.max() / y) ** 2)), rel=1e-6)
        # the scatter is what the posterior covariance predicts (within sampling error of 6 replicates)
        assert np.all(st.scatter < 2.5 * st.posterior_std) and np.all(st.scatter > 0.25 * st.posterior_std)
        scatter[label] = st.relative_scatter
    assert np.all(scatter["two"] < scatter["one"]), scatter


def test_multi_start_ends_agree_when_the_data_identify(executor):
    op = _bar_operator([100.0, 60.0])
    y = op(TRUTH).y
    C = np.eye(y.size) * (0.005 * y.max()) ** 2
    starts = np.array([[1.0, 150.0], [4.0, 450.0]])
    ms = multi_start(op, y, C, starts, bounds_covariance(SPACE), executor=executor,
                     fit=partial(kalman_filter, groups=[np.arange(y.size)], max_iterations=10), bounds=fracid.DamageParameters.valid_bounds(("c", "beta")))
    assert ms.unique(1.0).all() and not ms.failed
    # noise-free data: each end is the truth within its posterior uncertainty (the prior pulls it a little)
    assert np.all(np.abs(ms.ends - TRUTH) <= 2 * ms.stds)
    assert np.all(ms.f < 1.0)  # and fits the data to well under one standard deviation per point


def test_valley_figure_places_multi_start_ends_in_each_pairs_columns():
    from fracid.inverse.studies.uniqueness import MultiStart
    from fracid.report.study import valley_figure

    space = ParameterSpace(("a", "b", "c"), [0.0, 0.0, 0.0], [1.0, 2.0, 3.0])
    points = space.from_unit(np.random.default_rng(0).random((30, 3)))
    knn = knn_from_population(space, points, points, ["ok"] * 30, [""] * 30, [0.5, 1.0, 1.5], np.eye(3), k=3)
    ends = np.array([[0.1, 1.1, 2.1], [0.2, 1.2, 2.2]])
    ms = MultiStart(ends - 0.05, ends, np.ones((2, 3)), np.zeros(2), np.zeros(3))
    fig = valley_figure(objective_maps(knn), ms, truth=[0.5, 1.0, 1.5], names=space.names)
    for ax, (i, j) in zip(fig.axes[:3], [(0, 1), (0, 2), (1, 2)]):  # the pair axes come before the colour bars
        [line] = [ln for ln in ax.get_lines() if ln.get_label() == "multi-start ends"]
        np.testing.assert_allclose(np.column_stack(line.get_data()), ends[:, [i, j]])


def test_study_valley_is_centred_on_the_estimate():
    """A twin (bar, noisy data): the objective maps and the valley are measured from the identification's
    estimate and its objective, not from the best population point (which fits worse)."""
    from fracid.data import ExperimentalData
    from fracid.inverse.core.misfit import objective
    from fracid.inverse.studies.study import StudySettings, run_study

    operator = _bar_operator([100.0])
    y = operator(TRUTH).y
    std = 0.01 * np.abs(y).max()
    y = y + np.random.default_rng(3).normal(scale=std, size=y.size)
    data = ExperimentalData(control=np.linspace(0.004, 0.04, 10), y=y, covariance=np.eye(y.size) * std**2,
                            blocks=[("global", 0, y.size)])
    study = run_study(operator, data, SPACE, StudySettings().replace(starts=0, replicates=0, n=16, k=3))
    ident, [m] = study.identification, study.maps
    f_estimate = objective(y, data.covariance, ident.y_fit)[0]
    population = np.asarray(ident.knn["f"], float)
    population = population[np.isfinite(population)]
    assert m.centred and np.array_equal(m.points[0], ident.x) and m.f[0] == pytest.approx(f_estimate)
    np.testing.assert_array_equal(m.f[1:], population)
    assert f_estimate < population.min() - valley_level(2)  # the fit is better than any population point
    assert m.valley[0] and np.all(m.f[m.valley] - f_estimate <= m.level)
    assert not np.any(m.valley[1:])  # no population point within the chi^2 level of the estimate ...
    assert np.sum(population - population.min() <= m.level) >= 1  # ... which the best point's level circled
    np.testing.assert_array_equal(study.valley_extent, np.zeros(2))  # the valley is the estimate alone
