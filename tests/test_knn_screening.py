"""The KNN population on a screening mesh (``[identify.knn] screening``, fracid.inverse.methods.knn_screening): the
setting, the fallback to the configured mesh (said, never silent), the plan's line and time, and a twin on the bar
whose estimate equals the one without screening within 0.1 std."""

from dataclasses import replace
from types import SimpleNamespace

import numpy as np
import pytest

import fracid
from fracid.inverse.core.forward_operator import ForwardOperator
from fracid.inverse.core.observations import Observation
from fracid.inverse.core.plans import RunTimes, method_plan, stage_seconds
from fracid.inverse.core.space import ParameterSpace
from fracid.inverse.methods.knn_kalman import KnnKalman
from fracid.inverse.methods.knn_screening import RESOLVED_SHARE, screened
from fracid.inverse.methods.knn_settings import DEFAULT_SCREENING, MAX_SCREENING, KnnSettings, knn_from_table
from fracid.inverse.methods.kalman_settings import KalmanSettings
from fracid.settings.checks import SettingError, SettingsContext

CONTEXT = SettingsContext(n_y=12, parameters=("c", "beta"))


# ------------------------------------------------------------------------------------------------ the setting


@pytest.mark.parametrize("raw, expected", [({}, DEFAULT_SCREENING), ({"screening": 1}, 1.0), ({"screening": 2.5}, 2.5),
                                           ({"screening": MAX_SCREENING}, MAX_SCREENING)])
def test_screening_is_read_with_its_default(raw, expected):
    assert knn_from_table({"n": 8, **raw}, CONTEXT).screening == expected


@pytest.mark.parametrize("value", [0.5, 0.999, 0, -2.0, MAX_SCREENING + 0.5, 100, "2", True, float("nan"), [2.0]])
def test_a_bad_screening_is_refused_naming_the_key_and_the_range(value):
    with pytest.raises(SettingError) as err:
        knn_from_table({"n": 8, "screening": value}, CONTEXT)
    text = str(err.value)
    assert err.value.key == "knn.screening", text
    assert "1 <= screening <= 4" in text and "element-size factor" in text, text


def test_the_library_default_is_the_configured_mesh():
    """KnnSettings() (the library's identify) keeps the population on the operator's mesh: only the configuration
    asks for a screening mesh by default."""
    assert KnnSettings().screening == 1.0


# ------------------------------------------------------------------------------------------------ the mesh


def _bar_operator(n_elements=120, c_bounds=(1.5, 4.0), names=("c", "beta")):
    spec = fracid.BarWithWeakZone(n_elements=n_elements)
    obs = Observation(spec, np.linspace(0.004, 0.03, 12))
    op = ForwardOperator([obs], fracid.DamageParameters(c=2.0, beta=250.0), names)
    bounds = {"c": c_bounds, "beta": (100.0, 500.0)}
    space = ParameterSpace(names, [bounds[n][0] for n in names], [bounds[n][1] for n in names])
    return op, space


def test_screening_coarsens_the_population_mesh_and_says_so():
    op, space = _bar_operator()
    mesh = screened(op, 2.0, space)
    assert mesh.coarse and not mesh.fallback and mesh.factor == pytest.approx(2.0)
    assert mesh.operator.observations[0].specimen.n_elements == 60
    assert op.observations[0].specimen.n_elements == 120  # the fit's operator unchanged
    assert "screening mesh 2 times coarser" in mesh.text and "[identify.knn] screening = 2" in mesh.text, mesh.text
    assert "the fit runs on the configured mesh" in mesh.text, mesh.text


def test_screening_1_is_the_configured_mesh_silently():
    op, space = _bar_operator()
    mesh = screened(op, 1.0, space)
    assert mesh.operator is op and not mesh.coarse and not mesh.fallback and mesh.text == "on the configured mesh"


@pytest.mark.parametrize("n_elements, factor, fallback", [(120, 2.0, False), (40, 2.0, True), (40, 1.5, True),
                                                         (120, 3.5, True)])
def test_a_screening_mesh_that_leaves_the_internal_length_unresolved_falls_back_and_says_why(n_elements, factor,
                                                                                            fallback):
    """l = sqrt(2 c) over c in [1.5, 4]: resolved everywhere at h = 100 / 60 mm, over less than half of the range at
    h = 100 / 20, 100 / 27 and 100 / 34 mm."""
    op, space = _bar_operator(n_elements)
    mesh = screened(op, factor, space)
    assert mesh.fallback == fallback and mesh.coarse == (not fallback), mesh.text
    if fallback:
        assert mesh.operator is op
        assert mesh.text.startswith("on the configured mesh: [identify.knn] screening = "), mesh.text
        assert "internal length l = sqrt(2 c)" in mesh.text and f"at least {RESOLVED_SHARE:.0%} needed" in mesh.text


def test_a_partly_resolved_range_is_said():
    op, space = _bar_operator(120, c_bounds=(1.0, 4.0))  # h = 1.67 mm resolves c >= 1.39 only
    mesh = screened(op, 2.0, space)
    assert mesh.coarse and "is not resolved there below c = 1.39" in mesh.text, mesh.text


def test_a_fixed_internal_length_the_screening_mesh_does_not_resolve_falls_back():
    op, space = _bar_operator(120, names=("beta",))
    op = replace(op, base=fracid.DamageParameters(c=1.0, beta=250.0))  # l = 1.41 mm < 100 / 60 mm
    mesh = screened(op, 2.0, space)
    assert mesh.fallback and "at c = 1 mm^2 would not be resolved" in mesh.text, mesh.text


def test_a_specimen_that_cannot_be_coarsened_falls_back_and_says_why():
    """A kind without a specimen to refine (as a user's mesh file, whose ``refined`` raises ValueError)."""
    op = SimpleNamespace(observations=(object(),))
    mesh = screened(op, 2.0, None)
    assert mesh.fallback and mesh.operator is op, mesh.text
    assert "cannot coarsen it" in mesh.text and "no specimen field" in mesh.text, mesh.text


# ------------------------------------------------------------------------------------------------ plan and time


def test_the_plan_names_the_population_mesh_and_costs_its_runs():
    op, space = _bar_operator()
    method = KnnKalman(KnnSettings(n=8, k=3, screening=2.0), KalmanSettings(groups=[np.arange(6), np.arange(6, 12)]))
    knn, kalman = method_plan(method, op, 12, 2, space)
    assert "on a screening mesh 2 times coarser" in knn.line() and knn.operator is not None, knn.line()
    assert kalman.operator is None
    times = RunTimes(plain=2.0, exact=3.0, workers=2, cores=2, screened=0.5)
    assert stage_seconds(knn, times) == pytest.approx(4 * 0.5)  # 8 runs in 4 rounds of the screening mesh's
    assert stage_seconds(replace(knn, operator=None), times) == pytest.approx(4 * 2.0)
    fine = method_plan(replace(method, knn=KnnSettings(n=8, k=3, screening=1.0)), op, 12, 2, space)[0]
    assert fine.operator is None and "screening" not in fine.line(), fine.line()
    fallback = method_plan(method, _bar_operator(40)[0], 12, 2, space)[0]
    assert fallback.operator is None and "on the configured mesh: [identify.knn] screening = 2" in fallback.line()


# ------------------------------------------------------------------------------------------------ twin


@pytest.mark.slow
def test_the_estimate_with_screening_equals_the_one_without_within_a_tenth_of_its_std():
    """Twin on the 120-element bar, data of (c, beta) = (2, 250): the population on 60 elements starts the filter
    that runs on 120, and its estimate is the one of the population on 120 within 0.1 std (the filter's)."""
    op, space = _bar_operator()
    truth = op(np.array([2.0, 250.0]))
    y, C = truth.y, np.diag(np.full(truth.y.size, 0.02**2))
    results = {}
    for screening in (1.0, 2.0):
        method = KnnKalman(KnnSettings(n=16, k=4, screening=screening), KalmanSettings(groups=[np.arange(6), np.arange(6, 12)]))
        results[screening] = method(op, y, C, space)
    fine, coarse = results[1.0], results[2.0]
    assert "screening mesh 2 times coarser" in coarse.knn["screening"] and fine.knn["screening"] == "on the configured mesh"
    assert any("screening mesh" in note for note in coarse.notes), coarse.notes
    std = np.sqrt(np.diag(fine.C))
    shift = np.abs(coarse.x - fine.x) / std
    assert np.all(shift <= 0.1), (coarse.x, fine.x, std, shift)
    assert not np.allclose(coarse.knn["f"], fine.knn["f"])  # the populations did run on different meshes
