"""The public API checks its arguments before any forward run: a specimen given by its name, parameters of the
wrong class, control points that are not a 1-D increasing array, data and covariance whose shapes do not match
the operator's outputs, a space that is not the operator's; and the plausibility of parameter values."""

import numpy as np
import pytest

import fracid
from fracid.inverse.core.forward_operator import ForwardOperator, Observation, RunRecord
from fracid.inverse.core.space import ParameterSpace
from fracid.inverse.methods.knn_gauss_newton import KnnGaussNewton
from fracid.inverse.methods.knn_kalman import KnnKalman
from fracid.inverse.methods.strategy import identify, identify_data
from fracid.models import DamageModel, implausible, usual_range_text

BAR = fracid.BarWithWeakZone(n_elements=40)
POINTS = np.linspace(0.004, 0.03, 12)
SPACE = ParameterSpace(("c", "beta"), [0.5, 100.0], [4.0, 500.0])


class Counting:
    """A fake forward operator of 12 outputs that counts its runs (none may happen when the arguments are bad)."""

    names = ("c", "beta")
    n_outputs = 12
    units = {"c": "mm^2", "beta": "-"}

    def __init__(self):
        self.runs = 0

    def __call__(self, x, needed=None):
        self.runs += 1
        return RunRecord(np.asarray(x, float), np.zeros(self.n_outputs))

    def valid_bounds(self):
        return fracid.DamageParameters.valid_bounds(self.names)


@pytest.fixture
def no_forward_run(monkeypatch):
    """Counts the runs of the damage models: a list that stays empty when no run started."""
    runs = []
    monkeypatch.setattr(DamageModel, "simulate", lambda self, *args, **kwargs: runs.append(args))
    return runs


# ------------------------------------------------------------------------------------ fracid.simulate


def test_simulate_with_a_specimen_name_says_it_needs_an_object_and_lists_the_names(no_forward_run):
    with pytest.raises(TypeError) as caught:
        fracid.simulate("bar", fracid.DamageParameters())
    text = str(caught.value)
    for words in ("'bar' is a name", "specimen object", "fracid.BarWithWeakZone()", "'notched-beam'", "'dogbone'"):
        assert words in text, (words, text)
    assert no_forward_run == []


@pytest.mark.parametrize("specimen, words", [(fracid.BarWithWeakZone, ["class BarWithWeakZone", "instance"]),
                                             (None, ["NoneType", "specimen object"]),
                                             (3.0, ["float", "specimen object"]),
                                             (object(), ["object", "BarWithWeakZone()"])])
def test_simulate_refuses_what_is_not_a_specimen(specimen, words, no_forward_run):
    with pytest.raises(TypeError) as caught:
        fracid.simulate(specimen, fracid.DamageParameters())
    assert all(w in str(caught.value) for w in words), str(caught.value)
    assert no_forward_run == []


def test_simulate_with_a_dict_of_parameters_says_how_to_build_the_class(no_forward_run):
    with pytest.raises(TypeError) as caught:
        fracid.simulate(BAR, {"c": 2.0})
    text = str(caught.value)
    assert "params is a dict" in text and "DamageParameters(**params)" in text and "kappa_i" in text, text
    assert no_forward_run == []


def test_simulate_with_the_parameters_of_another_model_is_refused(no_forward_run):
    from fracid.fem.material.cohesive import CohesiveParameters

    with pytest.raises(TypeError, match="takes a DamageParameters"):
        fracid.simulate(BAR, CohesiveParameters())
    assert no_forward_run == []


# ------------------------------------------------------------------------------------ Observation, ForwardOperator


@pytest.mark.parametrize("points, words", [
    (np.column_stack([POINTS, POINTS]), ["shape (12, 2)", "1-D"]),
    (np.array([]), ["shape (0,)", "non-empty"]),
    (np.array([0.01, np.nan, 0.03]), ["NaN", "finite"]),
    (np.array([0.01, 0.03, 0.02]), ["increase strictly", "point 2"]),
    (np.array([0.01, 0.01, 0.02]), ["increase strictly"]),
])
def test_observation_checks_its_control_points_at_construction(points, words):
    with pytest.raises(ValueError) as caught:
        Observation(BAR, points)
    assert all(w in str(caught.value) for w in words), str(caught.value)


def test_observation_refuses_a_specimen_name_and_a_quantity_that_is_not_a_name():
    with pytest.raises(TypeError, match="'bar' is a name"):
        Observation("bar", POINTS)
    with pytest.raises(TypeError, match="quantity"):
        Observation(BAR, POINTS, quantity=3)


def test_observation_keeps_its_points_as_a_float_array():
    assert Observation(BAR, [0.01, 0.02]).control_points.dtype == float


@pytest.mark.parametrize("kwargs, error, words", [
    ({"names": ("c", "gamma")}, ValueError, ["gamma", "not among"]),
    ({"names": "c"}, TypeError, ["'c' is a string", "('c',)"]),
    ({"base": {"c": 2.0}}, TypeError, ["base is a dict", "DamageParameters"]),
    ({"observations": [POINTS]}, TypeError, ["sequence of Observation", "ndarray"]),
])
def test_forward_operator_checks_its_arguments(kwargs, error, words):
    arguments = {"observations": [Observation(BAR, POINTS)], "base": fracid.DamageParameters(), "names": ("c", "beta"),
                 **kwargs}
    with pytest.raises(error) as caught:
        ForwardOperator(**arguments)
    assert all(w in str(caught.value) for w in words), str(caught.value)


# ------------------------------------------------------------------------------------ identify


def _data(n=12):
    return np.ones(n), np.eye(n) * 0.01


@pytest.mark.parametrize("y, C, error, words", [
    (np.ones(12), np.eye(11), ValueError, ["C_exp has shape (11, 11)", "(12, 12)"]),
    (np.ones(12), np.ones(12) * 0.01, ValueError, ["C_exp has shape (12,)", "np.diag(std**2)"]),
    (np.ones(11), np.eye(11), ValueError, ["y_exp has shape (11,)", "computes 12 values"]),
    (np.ones((12, 1)), np.eye(12), ValueError, ["y_exp has shape (12, 1)"]),
    (np.ones(12), np.diag(np.r_[np.ones(11), 0.0]), ValueError, ["not positive definite", "std > 0"]),
    (np.ones(12), np.eye(12) + np.triu(np.ones((12, 12)), 1) * 0.1, ValueError, ["not symmetric"]),
    (np.r_[np.ones(11), np.nan], np.eye(12), ValueError, ["y_exp holds 1 NaN"]),
    (["a"] * 12, np.eye(12), TypeError, ["y_exp", "not an array of numbers"]),
])
def test_identify_checks_the_data_against_the_operator_before_any_run(y, C, error, words):
    operator = Counting()
    with pytest.raises(error) as caught:
        identify(operator, y, C, SPACE, n=4, k=2)
    assert all(w in str(caught.value) for w in words), str(caught.value)
    assert operator.runs == 0


@pytest.mark.parametrize("method", [KnnKalman(), KnnGaussNewton()])
def test_the_methods_check_the_covariance_before_the_population(method):
    operator = Counting()
    with pytest.raises(ValueError, match="C_exp has shape"):
        method(operator, np.ones(12), np.eye(3), SPACE)
    assert operator.runs == 0


def test_identify_refuses_a_space_of_other_parameters_or_of_another_type():
    operator = Counting()
    y, C = _data()
    with pytest.raises(ValueError, match=r"space's parameters \['beta', 'c'\] are not the operator's"):
        identify(operator, y, C, ParameterSpace(("beta", "c"), [100.0, 0.5], [500.0, 4.0]), n=4, k=2)
    with pytest.raises(TypeError, match="ParameterSpace"):
        identify(operator, y, C, {"c": (0.5, 4.0), "beta": (100.0, 500.0)}, n=4, k=2)
    with pytest.raises(TypeError, match="method is a int"):
        identify(operator, y, C, SPACE, method=3)
    assert operator.runs == 0


def test_identify_data_refuses_arrays_instead_of_experimental_data():
    operator = Counting()
    with pytest.raises(TypeError, match="ExperimentalData"):
        identify_data(operator, np.ones(12), SPACE)
    assert operator.runs == 0


# ------------------------------------------------------------------------------------ plausibility


def test_a_value_far_outside_the_usual_range_is_implausible_with_the_reason():
    reason = implausible("kappa_i", 0.2)
    assert "kappa_i = 0.2" in reason and "200 times" in reason and usual_range_text("kappa_i") in reason
    assert "1/" in implausible("E", 20.0) and "[MPa]" in implausible("E", 20.0)
    assert implausible("kappa_i", 1e-4) is None and implausible("beta", 0.0) is None
    assert implausible("no_such_parameter", 1e9) is None


def test_bounds_far_outside_the_usual_range_are_refused_naming_the_bound(tmp_path):
    from fracid.config import ConfigError, load_config

    (tmp_path / "bar.csv").write_text("u_mm,F_N\n0,0\n0.03,1\n")
    config = tmp_path / "cfg.toml"
    config.write_text('[specimen]\ntype = "bar"\n[[experiments]]\nfile = "bar.csv"\ncontrol_column = "u_mm"\n'
                      'control_unit = "mm"\nforce_unit = "N"\nkind = "single"\nforce_columns = ["F_N"]\nstd = 0.02\n'
                      'n_points = 12\n[identify]\nparameters = ["c", "kappa_i"]\n[identify.bounds]\n'
                      'c = [0.5, 4.0]\nkappa_i = [1e-4, 0.2]\n')
    with pytest.raises(ConfigError) as caught:
        load_config(config)
    text = str(caught.value)
    assert "identify.bounds.kappa_i" in text and "the upper bound is implausible" in text and "control_unit" not in text
