"""Fit diagnostics (fracid.inverse.core.diagnostics): elastic slope and peak of the computed curve against the
measured one, the worst residual, their warnings; in the result (summary, warnings, JSON) and a twin whose
bar is shorter than the test's (stiffer) that gets the elastic-slope warning."""

import json

import numpy as np
import pytest

import fracid
from fracid.inverse.core.diagnostics import (PEAK_TOLERANCE, SLOPE_TOLERANCE, diagnostic_warnings, elastic_points,
                                             fit_diagnostics, origin_slope)
from fracid.inverse.core.method import MethodResult, estimate_text

CONTROL = np.linspace(0.0, 1.0, 41)  # [mm]
STD = np.full(CONTROL.size, 0.1)  # [N]


def curve(stiffness=100.0, peak=30.0, end=1.0):
    """Linear rise at ``stiffness`` [N/mm] to ``peak`` [N], then linear softening to 0 at ``end`` [mm]."""
    x_peak = peak / stiffness
    return np.where(CONTROL <= x_peak, stiffness * CONTROL, peak * (end - CONTROL) / (end - x_peak))


def diagnose(y_fit, y=None, control=CONTROL, blocks=(("global", 0, 41),)):
    y = curve() if y is None else y
    return fit_diagnostics(control, y, STD, y_fit, blocks)


def test_a_model_25_percent_stiffer_gets_the_slope_warning_only():
    d = diagnose(curve(stiffness=125.0))
    block, = d["blocks"]
    assert block["slope_data"] == pytest.approx(100.0) and block["slope_ratio"] == pytest.approx(1.25)
    assert block["elastic_points"] == 4  # 0.025 to 0.1 mm: up to 35 % of the 30 N peak (control 0 tells nothing)
    assert block["elastic_points_model"] == 3  # its own: up to 35 % of its own peak
    assert block["peak_ratio"] > 1 - PEAK_TOLERANCE
    warnings = diagnostic_warnings(d)
    assert len(warnings) == 1
    assert warnings[0].startswith("the model is 25 % stiffer than the data in block 'global'")
    assert "notch depth" in warnings[0] and "E, and the units" in warnings[0]


def test_a_softer_model_is_said_softer():
    warnings = diagnostic_warnings(diagnose(curve(stiffness=80.0, peak=30.0)))
    assert any(w.startswith("the model is 20 % softer") for w in warnings)


def test_a_fit_20_percent_below_the_peak_gets_the_peak_warning_only():
    d = diagnose(np.minimum(curve(), 24.0))
    block, = d["blocks"]
    assert block["peak_ratio"] == pytest.approx(0.8) and block["slope_ratio"] == pytest.approx(1.0)
    assert block["control_peak_data"] == pytest.approx(0.3)
    warnings = diagnostic_warnings(d)
    assert len(warnings) == 1 and warnings[0].startswith("the model's peak is 20 % below the measured one")
    assert "likely causes" in warnings[0]


def test_a_good_fit_gets_no_warning_and_the_worst_residual_is_located():
    rng = np.random.default_rng(1)
    y = curve() + rng.normal(0.0, 0.1, CONTROL.size)
    y_fit = curve()
    y_fit[17] += 0.5  # 5 std above the point
    d = diagnose(y_fit, y)
    assert diagnostic_warnings(d) == []
    block, = d["blocks"]
    assert abs(block["slope_ratio"] - 1) < SLOPE_TOLERANCE and abs(block["peak_ratio"] - 1) < PEAK_TOLERANCE
    worst = d["worst"]
    assert worst["index"] == 17 and worst["block"] == "global" and worst["control"] == pytest.approx(CONTROL[17])
    assert worst["residual_std"] == pytest.approx((y_fit[17] - y[17]) / 0.1)


def test_a_departure_within_the_scatter_of_few_points_is_no_warning():
    """One elastic point at 0.01 mm with a std of 2 N (slope std 200 N/mm): a slope 20 % off is not significant."""
    y = np.array([0.0, 10.0, 20.0, 30.0, 20.0, 10.0])
    y_fit = y + np.array([1.0, -2.0, 1.0, -1.0, 1.0, -1.0])
    d = fit_diagnostics(np.linspace(0, 0.05, 6), y, np.full(6, 2.0), y_fit, [("global", 0, 6)])
    assert d["blocks"][0]["slope_ratio"] == pytest.approx(0.8) and diagnostic_warnings(d) == []


def test_width_blocks_have_no_slope_or_peak_and_the_index_replaces_a_missing_control():
    y = np.concatenate([curve(), [1.0, 2.0, 3.0]])
    y_fit = np.concatenate([curve(stiffness=125.0), [1.0, 2.0, 9.0]])
    std = np.concatenate([STD, [0.1] * 3])
    blocks = [("global", 0, 41), ("fpz_width", 41, 44)]
    d = fit_diagnostics(None, y, std, y_fit, blocks, quantities=["force", "fpz_width"])
    assert [b["block"] for b in d["blocks"]] == ["global"] and d["control"] == "index"
    assert d["worst"]["index"] == 43 and d["worst"]["block"] == "fpz_width"
    assert d["blocks"][0]["slope_ratio"] == pytest.approx(1.25)  # evenly spaced points: the same ratio
    d = fit_diagnostics(None, y, std, y_fit, blocks, quantities=["force", "force"])
    assert len(d["blocks"]) == 2  # the quantities decide, not the names
    d = fit_diagnostics(None, y, std, y_fit, blocks)
    assert len(d["blocks"]) == 2  # none recorded: every block is taken for a force (its default quantity)


def test_elastic_points_and_slopes_of_degenerate_blocks():
    points, within = elastic_points([0.0, 1.0, 2.0], [5.0, 1.0, 0.5])
    assert points.size == 0 and not within  # the peak at control 0: nothing rises
    points, within = elastic_points([0.0, 1.0, 2.0, 3.0], [0.0, 20.0, 30.0, 10.0])
    np.testing.assert_array_equal(points, [1])  # none below 35 %: the first rising point, a secant (a bound)
    assert not within
    points, within = elastic_points([0.0, 1.0, 2.0, 3.0, 4.0], [0.0, 5.0, 10.0, 40.0, 10.0])
    np.testing.assert_array_equal(points, [1, 2]) and within
    assert np.isnan(origin_slope([], [])[0]) and np.isnan(origin_slope([0.0], [2.0])[0])
    slope, std = origin_slope([1.0, 2.0], [2.0, 4.0], [1.0, 1.0])
    assert slope == pytest.approx(2.0) and std == pytest.approx(np.sqrt(1 / 5))


def result_of(y_fit, control=CONTROL):
    return MethodResult(names=["c"], x=np.array([21.27436]), C=np.array([[4.2**2]]), y_exp=curve(), y_fit=y_fit,
                        std_exp=STD, blocks=[("global", 0, 41)], units={"c": "mm^2"}, status="converged",
                        converged=True, control=control, control_names=["cmod"], quantities=["force"])


def test_the_result_warns_prints_and_saves_its_diagnostics(tmp_path):
    stiff = result_of(curve(stiffness=125.0))
    assert any(w.startswith("the model is 25 % stiffer") for w in stiff.warnings())
    summary = stiff.summary()
    assert "c = 21.3 +- 4.2 mm^2" in summary  # rounded to two significant digits of the std
    assert "fit diagnostics:" in summary and "elastic slope model/data 125 %" in summary
    assert "worst residual:" in summary
    saved = json.loads(stiff.save(tmp_path / "result.json").read_text())
    assert saved["diagnostics"]["blocks"][0]["slope_ratio"] == pytest.approx(1.25)
    assert saved["control"] == pytest.approx(CONTROL.tolist()) and saved["control_names"] == ["cmod"]
    assert result_of(curve()).warnings() == []
    low = result_of(np.minimum(curve(), 24.0), control=None)
    assert any(w.startswith("the model's peak is 20 % below") for w in low.warnings())
    assert any(w.startswith("the model's peak is 20 % below") for w in low.warnings(control=CONTROL))


@pytest.mark.parametrize("value, std, text", [(21.27436, 4.2, "21.3 +- 4.2"), (312.7, 18.3, "313 +- 18"),
                                              (4.7893e-5, 4.2e-6, "4.79e-05 +- 4.2e-06"), (21.3, 9.96, "21 +- 10"),
                                              (2.0, 0.0, "2 +- 0")])
def test_estimates_are_rounded_to_two_digits_of_their_std(value, std, text):
    assert estimate_text(value, std) == text


def test_a_twin_on_a_shorter_bar_gets_the_elastic_slope_warning():
    """Data from a 100 mm bar, identified (c, beta) with a 70 mm model of it: E fixed, the model is about
    100/70 times stiffer, which no (c, beta) mends; the result says so."""
    from fracid.inverse.core.forward_operator import ForwardOperator, Observation
    from fracid.inverse.core.space import ParameterSpace
    from fracid.inverse.methods.strategy import identify_data
    from fracid.inverse.studies.twin import synthetic_data

    points = np.linspace(0.001, 0.03, 20)  # end displacement [mm]
    truth = ForwardOperator([Observation(fracid.BarWithWeakZone(n_elements=20), points)], fracid.DamageParameters(),
                            ("c", "beta"))
    data = synthetic_data(truth, np.array([2.0, 250.0]), {"global:relative": 0.01}, seed=None)
    wrong = ForwardOperator([Observation(fracid.BarWithWeakZone(n_elements=20, length=70.0), points)],
                            fracid.DamageParameters(), ("c", "beta"))
    space = ParameterSpace(("c", "beta"), [0.5, 100.0], [4.0, 500.0])
    result = identify_data(wrong, data, space, n=8, k=3, groups="all", max_iterations=3, progress=False)
    np.testing.assert_allclose(result.control, points)
    assert result.control_names == ["end_displacement"] and result.quantities == ["force"]
    slope = [w for w in result.warnings() if w.startswith("the model is")]
    assert len(slope) == 1 and "% stiffer than the data in block 'global'" in slope[0]
    ratio = result.diagnostics()["blocks"][0]["slope_ratio"]
    assert 1.3 < ratio < 1.5  # about 100 / 70
