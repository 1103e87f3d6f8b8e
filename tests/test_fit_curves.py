"""The fit figures draw the forward run's own curve at the estimate (issue 38, item 14): a computed peak between
two data points is drawn, not clipped to a flat top; the identify, compare and posterior figures alike, and a
result without the run's curve (an older result.json) still draws, through the data's points, and says so."""

from types import SimpleNamespace

import numpy as np
import pytest

from fracid.inverse.core.method import MethodResult
from fracid.report.compare import fits_figure
from fracid.report.figures import AT_DATA_POINTS, fit_figure, to_png
from fracid.report.posterior import predictive_figure

CONTROL = np.linspace(0.0, 0.5, 11)  # the data's points [mm], 0.05 mm apart
STEPS = np.linspace(0.0, 0.5, 201)  # the run's steps [mm]


def computed(x):
    """A curve peaking at 0.125 mm, between the data's points 0.10 and 0.15 mm [N]."""
    x = np.asarray(x, float)
    return np.where(x <= 0.125, 800.0 * x, 100.0 * np.exp(-(x - 0.125) / 0.1))


def result(curves=True) -> MethodResult:
    y_fit = computed(CONTROL)
    curve = [{"control": STEPS.tolist(), "values": computed(STEPS).tolist()}] if curves else []
    return MethodResult(names=["c"], x=np.array([2.0]), C=np.array([[0.1]]), y_exp=y_fit * 1.02, y_fit=y_fit,
                        std_exp=np.full(CONTROL.size, 2.0), blocks=[("global", 0, CONTROL.size)], control=CONTROL,
                        control_names=["cmod"], quantities=["force"], curves=curve)


def line(fig, label_start):
    lines = [ln for ax in fig.axes for ln in ax.get_lines() if ln.get_label().startswith(label_start)]
    assert len(lines) == 1, [ln.get_label() for ax in fig.axes for ln in ax.get_lines()]
    return lines[0]


def _check_run_curve(drawn):
    x, y = drawn.get_xdata(), drawn.get_ydata()
    sampled_peak = computed(CONTROL).max()  # 85.5 N at 0.15 mm: the data's points miss the peak
    assert x.size > CONTROL.size and x.max() == pytest.approx(CONTROL.max())
    assert y.max() == pytest.approx(100.0) and y.max() > sampled_peak + 10.0
    assert AT_DATA_POINTS not in drawn.get_label()


def _check_fallback(drawn):
    assert drawn.get_xdata().size == CONTROL.size and drawn.get_ydata().max() == pytest.approx(computed(CONTROL).max())
    assert AT_DATA_POINTS in drawn.get_label()  # it says it is not the run's curve


def test_the_fit_figure_draws_the_runs_own_curve_to_the_end_of_the_data():
    fig = fit_figure(result())
    _check_run_curve(line(fig, "computed at the estimate"))
    measured = line(fig, "measured")
    assert measured.get_zorder() > line(fig, "computed at the estimate").get_zorder()  # the points over the curve
    fallback = fit_figure(result(curves=False))
    _check_fallback(line(fallback, "computed at the estimate"))
    assert to_png(fallback)[:4] == b"\x89PNG"


def test_a_saved_and_loaded_result_keeps_its_curve(tmp_path):
    loaded = MethodResult.load(result().save(tmp_path / "result.json"))
    _check_run_curve(line(fit_figure(loaded), "computed at the estimate"))
    d = loaded.diagnostics()
    assert d["blocks"][0]["run_curve"] and d["blocks"][0]["peak_model"] == pytest.approx(100.0)
    assert d["blocks"][0]["control_peak_model"] == pytest.approx(0.125)
    assert "forward run's own curve" in d["note"]
    old = result(curves=False).diagnostics()
    assert old["blocks"][0]["peak_model"] == pytest.approx(computed(CONTROL).max())
    assert "data's control values only" in old["note"]


def _comparison(identification):
    data = SimpleNamespace(y=identification.y_exp, std=identification.std_exp, control=CONTROL,
                           blocks=identification.blocks)
    score = SimpleNamespace(identification=identification, rank=1, label="model A", rms_percent=2.0)
    return SimpleNamespace(data=data, scores=[score])


def test_the_compare_figure_draws_every_models_run_curve():
    _check_run_curve(line(fits_figure(_comparison(result())), "1. model A"))
    _check_fallback(line(fits_figure(_comparison(result(curves=False))), "1. model A"))


def test_the_posterior_predictive_figure_draws_the_identifications_run_curve():
    ident = result()
    band = np.vstack([ident.y_fit * 0.95, ident.y_fit, ident.y_fit * 1.05])
    post = SimpleNamespace(y_exp=ident.y_exp, std_exp=ident.std_exp, predictive_band=lambda level: band)
    _check_run_curve(line(predictive_figure(post, CONTROL, ident.blocks, ident), "identification's fit"))
    _check_fallback(line(predictive_figure(post, CONTROL, ident.blocks, result(curves=False)), "identification's fit"))
    _check_fallback(line(predictive_figure(post, CONTROL, ident.blocks, ident.y_fit), "identification's fit"))


def test_the_reports_computed_peak_is_the_runs_own():
    from fracid.report import fit_metrics

    assert fit_metrics(result())[0]["peak_computed"] == pytest.approx(100.0)
    assert fit_metrics(result(curves=False))[0]["peak_computed"] == pytest.approx(computed(CONTROL).max())
