"""The elastic-slope warning points the right way when the computed and measured curves differ a lot (issue 38,
item 2): a model twice as stiff whose peak comes earlier (a wedge-splitting specimen with a ligament too long),
a softer model, three or four points on the rising branch, noisy data; with the run's own curve and without it."""

import numpy as np
import pytest

from fracid.inverse.core.diagnostics import diagnostic_warnings, fit_diagnostics

DATA_CONTROL = np.round(np.arange(0.01, 0.301, 0.01), 6)  # CMOD [mm]: 4 points before the data's peak
RUN_CONTROL = np.linspace(0.0, 0.3, 601)  # the steps of a forward run [mm]


def quasi_brittle(x, stiffness, peak, width=0.05):
    """A force-CMOD curve as a test gives it [N]: linear at ``stiffness`` [N/mm] to 60 % of ``peak`` [N], a
    parabola to the peak (no kink), then exponential softening over ``width`` [mm]."""
    x = np.asarray(x, float)
    linear_end, top = 0.6 * peak / stiffness, 1.4 * peak / stiffness
    rising = np.where(x <= linear_end, stiffness * x, peak - 0.4 * peak * ((top - x) / (top - linear_end)) ** 2)
    return np.where(x <= top, rising, peak * np.exp(-(x - top) / width))


def diagnose(model, data, *, run_curve: bool, noise=0.0, control=DATA_CONTROL, seed=3):
    """Diagnostics of the model (stiffness, peak) against the data (stiffness, peak); with the run's own curve
    or its values at the data's points only; the data with a relative noise of the peak."""
    y = quasi_brittle(control, *data)
    std = np.full(control.size, max(noise, 0.005) * data[1])
    y = y + np.random.default_rng(seed).normal(0.0, noise * data[1], control.size)
    curves = [{"control": RUN_CONTROL, "values": quasi_brittle(RUN_CONTROL, *model)}] if run_curve else []
    return fit_diagnostics(control, y, std, quasi_brittle(control, *model), [("global", 0, control.size)],
                           curves=curves)


WEDGE_DATA = (98000.0, 3000.0)  # 980 N at the first point (0.01 mm), the peak near 0.04 mm


@pytest.mark.parametrize("model", [(198000.0, 3000.0), (198000.0, 2300.0), (198000.0, 3600.0)],
                         ids=["same-peak", "lower-peak", "higher-peak"])
@pytest.mark.parametrize("noise", [0.0, 0.02])
def test_a_model_twice_as_stiff_with_an_earlier_peak_is_said_stiffer(model, noise):
    """1980 N computed against 980 N measured at the first point; the model peaks before the data's second
    point: at the data's points its rising branch is that one point, past 35 % of its peak."""
    with_run = diagnose(model, WEDGE_DATA, run_curve=True, noise=noise)
    block, = with_run["blocks"]
    assert block["run_curve"] and block["slope_model_elastic"] and block["elastic_points_model"] > 5
    trust = 3 * block["slope_ratio"] * block["slope_std"] / block["slope_data"] + 0.05  # 3 std of the data's slope
    assert block["slope_ratio"] == pytest.approx(198000 / 98000, abs=trust)
    warning = next(w for w in diagnostic_warnings(with_run) if "elastic" in w)
    assert warning.startswith("the model is ") and " % stiffer than the data in block 'global'" in warning
    assert f"against {block['slope_data']:.4g} +- {block['slope_std']:.2g} measured" in warning
    percent = float(warning.split("the model is ")[1].split(" %")[0])
    assert percent == pytest.approx(100 * (198000 / 98000 - 1), abs=100 * trust)
    sampled = diagnose(model, WEDGE_DATA, run_curve=False, noise=noise)
    block, = sampled["blocks"]
    assert not block["run_curve"] and not block["slope_model_elastic"]  # a secant past its elastic part
    warning = next(w for w in diagnostic_warnings(sampled) if "elastic" in w)
    assert warning.startswith("the model is at least ") and "% stiffer than the data" in warning
    assert "a bound only" in "\n".join(_lines(sampled))


@pytest.mark.parametrize("run_curve", [True, False])
@pytest.mark.parametrize("noise", [0.0, 0.02])
def test_a_model_at_60_percent_of_the_slope_with_a_later_peak_is_said_softer(run_curve, noise):
    d = diagnose((60000.0, 3000.0), WEDGE_DATA, run_curve=run_curve, noise=noise)
    block, = d["blocks"]
    trust = 3 * block["slope_ratio"] * block["slope_std"] / block["slope_data"] + 0.03
    assert block["slope_ratio"] == pytest.approx(60000 / 98000, abs=trust)
    warning = next(w for w in diagnostic_warnings(d) if "elastic" in w)
    assert warning.startswith("the model is ") and "% softer than the data in block 'global'" in warning
    assert "at least" not in warning
    assert float(warning.split("the model is ")[1].split(" %")[0]) == pytest.approx(39, abs=100 * trust)


def test_a_point_at_control_zero_changes_nothing():
    control = np.concatenate([[0.0], DATA_CONTROL])
    for model, word in (((198000.0, 3000.0), "stiffer"), ((60000.0, 3000.0), "softer")):
        d = diagnose(model, WEDGE_DATA, run_curve=True, control=control)
        assert any(w.startswith("the model is") and f"% {word} than" in w for w in diagnostic_warnings(d))


def test_data_without_an_elastic_point_give_no_direction_they_cannot_support():
    """The data's first point at 65 % of their peak: their secant is only a lower bound of their slope, so a
    model that looks stiffer cannot be told stiffer (nor softer), while one softer still is."""
    control = DATA_CONTROL[1:]  # 0.02 mm first: 1960 N of 3000 N
    stiff = diagnose((198000.0, 3000.0), WEDGE_DATA, run_curve=True, control=control)
    warning = next(w for w in diagnostic_warnings(stiff) if "elastic" in w)
    assert warning.startswith("the elastic slopes differ in block 'global'")
    assert "the data's rising branch" in warning and "too few points on the rising branch" in warning
    assert "whether the model is stiffer or softer" in warning
    soft = diagnose((40000.0, 3000.0), WEDGE_DATA, run_curve=True, control=control)
    warning = next(w for w in diagnostic_warnings(soft) if "elastic" in w)
    assert warning.startswith("the model is at least ") and "% softer than the data" in warning


def test_a_model_within_the_tolerance_gets_no_slope_warning_either_way():
    for model in ((103000.0, 3000.0), (96000.0, 2900.0)):  # +-4 % of the data (the noise adds up to 6 %)
        for run_curve in (True, False):
            d = diagnose(model, WEDGE_DATA, run_curve=run_curve, noise=0.01)
            assert not [w for w in diagnostic_warnings(d) if "elastic" in w], (model, run_curve)


def _lines(d):
    from fracid.inverse.core.diagnostics import diagnostics_lines

    return diagnostics_lines(d)
