"""Cross-model calibration and comparison (fracid.inverse.studies.cross_model) on a coarse notched beam.

The cohesive crack's curve is fitted by the gradient damage model and the gradient damage model's
curve by the cohesive crack; then both models are compared on one data set. Small populations and
a coarse mesh (5 mm in the process zone), so the module runs in about 2.5 minutes on two shared
cores; the tolerances were set from measured values (stated beside each) with a margin.
"""

import numpy as np
import pytest

from fracid.inverse.studies.cross_model import compare_models, cross_calibration
from fracid.inverse.studies.model_fit import Candidate, relative_rms
from fracid.inverse.core.space import ParameterSpace
from fracid.fem.material.cohesive import CohesiveParameters
from fracid.fem.material.parameters import DamageParameters
from fracid.fem.path.path_following import StepOptions
from fracid.models import CohesiveCrackModel, DamageModel
from fracid.specimens.beam import NotchedBeam

pytestmark = pytest.mark.slow  # the fast loop (-m "not slow") leaves this module out

BEAM = NotchedBeam(h_fine=5.0, h_coarse=10.0)
CMOD = np.linspace(0.01, 0.2, 10)  # mm
COHESIVE = CohesiveParameters(E=37000.0, nu=0.2, ft=3.0, Gf=0.1)
# the gradient damage fit of the Gregoire beam (docs/demo/result.json), E from its initial slope
GRADIENT = DamageParameters(E=36250.0, nu=0.2, kappa_i=4.80e-5, alpha=0.99, beta=1086.0, c=21.4, eta=10.0)
GRADIENT_SPACE = ParameterSpace(("kappa_i", "beta", "c"), [3e-5, 200.0, 6.0], [1.2e-4, 3000.0, 40.0],
                                log=(False, True, False))
COHESIVE_SPACE = ParameterSpace(("ft", "Gf"), [1.5, 0.04], [6.0, 0.3], log=(False, True))
# the Kalman filter in three steps, with the data's std at 3 % of the peak (relative_std): a
# model mismatch is not noise, and with 1 % the filter's steps overshoot far out of the bounds
# steps of at most 1/30 of the last CMOD (the default is 1/60): the CMOD points are landed on either
# way, and the computed forces there differ by < 0.1 N, the energies by < 0.1 %, at 70 % of the cost
SETTINGS = {"n": 6, "k": 3, "groups": np.array_split(np.arange(CMOD.size), 3), "max_iterations": 2,
            "steps": StepOptions(maximum=CMOD[-1] / 30), "progress": False}


@pytest.fixture(scope="module")
def executor():
    from fracid.runtime.executors import make_executor

    with make_executor(2) as pool:
        yield pool


@pytest.fixture(scope="module")
def cohesive_to_gradient(executor):
    return cross_calibration(CohesiveCrackModel(), COHESIVE, DamageModel("gradient"),
                             DamageParameters(E=COHESIVE.E, nu=0.2, alpha=0.99, eta=10.0), GRADIENT_SPACE.names,
                             GRADIENT_SPACE, BEAM, CMOD, relative_std=0.03, executor=executor, **SETTINGS)


@pytest.fixture(scope="module")
def gradient_to_cohesive(executor):
    return cross_calibration(DamageModel("gradient"), GRADIENT, CohesiveCrackModel(),
                             CohesiveParameters(E=GRADIENT.E, nu=0.2), COHESIVE_SPACE.names, COHESIVE_SPACE, BEAM, CMOD,
                             relative_std=0.03, executor=executor, **SETTINGS)


def _check_cross(cross, source_key, target_key):
    fit = cross.fit
    print(f"\n{source_key} -> {target_key}: x = {dict(zip(fit.names, fit.x))}, std = {fit.std}, "
          f"RMS {100 * fit.rms_relative:.2f} %, energy {cross.source_energy:.4g} -> {fit.dissipated_energy:.4g} N mm "
          f"(ratio {cross.energy_ratio:.4f}), peak {cross.source_peak_force:.1f} -> {fit.peak_force:.1f} N, "
          f"{fit.forward_runs} runs, {fit.seconds:.0f} s")
    assert cross.source_label == source_key and fit.model_key == target_key
    assert fit.names == list(fit.units) and np.all(np.isfinite(fit.x)) and np.all(fit.std > 0)
    # the data are the source curve at the CMOD points
    np.testing.assert_allclose(cross.data.y, np.interp(CMOD, cross.source_control, cross.source_force))
    # the run at the estimate, sampled independently of the filter's y_fit, matches the source curve
    rms = relative_rms(np.interp(CMOD, fit.control, fit.force), cross.data.y)
    assert rms == pytest.approx(fit.rms_relative, abs=0.005)
    return fit, rms


def test_cohesive_curve_is_fitted_by_gradient_damage(cohesive_to_gradient):
    fit, rms = _check_cross(cohesive_to_gradient, "cohesive-crack-hordijk", "gradient-damage")
    assert rms < 0.06  # measured: 5.3 % with the Kalman filter kept inside the bounds (2.9 % when it left them)
    assert fit.params.E == COHESIVE.E and fit.params.alpha == 0.99  # fixed parameters kept
    # both dissipate about the same energy to the last point: measured ratio 0.994
    assert cohesive_to_gradient.energy_ratio == pytest.approx(1.0, abs=0.08)


def test_gradient_curve_is_fitted_by_cohesive_crack(gradient_to_cohesive):
    fit, rms = _check_cross(gradient_to_cohesive, "gradient-damage", "cohesive-crack-hordijk")
    assert rms < 0.07  # measured: 4.4 % of the peak force
    assert gradient_to_cohesive.energy_ratio == pytest.approx(1.0, abs=0.08)  # measured 1.018


@pytest.fixture(scope="module")
def comparison(cohesive_to_gradient, executor):
    """Both models fitted to the cohesive beam's curve (the gradient model with c fixed at 20 mm^2)."""
    candidates = [
        Candidate("cohesive crack", CohesiveCrackModel(), CohesiveParameters(E=COHESIVE.E, nu=0.2), COHESIVE_SPACE.names,
                  COHESIVE_SPACE),
        ("gradient damage", DamageModel("gradient"), DamageParameters(E=COHESIVE.E, nu=0.2, alpha=0.99, c=20.0, eta=10.0),
         ("kappa_i", "beta"), ParameterSpace(("kappa_i", "beta"), [3e-5, 200.0], [1.2e-4, 3000.0], log=(False, True))),
    ]
    lines = []
    table = compare_models(cohesive_to_gradient.data, BEAM, candidates, executor=executor, log=lines.append, **SETTINGS)
    return table, lines


def test_comparison_table_on_one_data_set(comparison, cohesive_to_gradient):
    """The cohesive model finds its own parameters back, the gradient model fits the curve too, and
    the two dissipate about the same energy."""
    table, lines = comparison
    print("\n" + "\n".join(lines))
    rows = table.rows()
    assert [r["label"] for r in rows] == ["cohesive crack", "gradient damage"]
    assert len(lines) == 4  # a line before and after each fit
    for row in rows:
        numbers = [row["rms_percent"], row["peak_force_N"], row["dissipated_energy_Nmm"], row["peak_force_data_N"]]
        numbers += [v for p in row["parameters"].values() for v in (p["value"], p["std"])]
        assert np.all(np.isfinite(numbers)), row
        assert row["forward_runs"] >= SETTINGS["n"] + 1
    cohesive, gradient = table.fit("cohesive crack"), table.fit("gradient damage")
    np.testing.assert_allclose(cohesive.x, [COHESIVE.ft, COHESIVE.Gf], rtol=0.02)  # its own curve: 0.2 % off
    assert cohesive.rms_relative < 0.01 and gradient.rms_relative < 0.06  # measured 0.04 %, 2.6 %
    # the energies of the two fits to the last CMOD agree: measured 57.07 and 55.03 N mm, 3.7 % apart
    assert gradient.dissipated_energy == pytest.approx(cohesive.dissipated_energy, rel=0.08)
    assert cohesive.dissipated_energy == pytest.approx(cohesive_to_gradient.source_energy, rel=0.01)
    with pytest.raises(KeyError, match="no model labelled 'crack band'"):
        table.fit("crack band")


def test_tables_figure_and_report(tmp_path, cohesive_to_gradient, gradient_to_cohesive, comparison):
    """The report module reads the results above (no new runs): tables, figure and one HTML page."""
    from fracid.report.cross_model import (CurvePanel, comparison_rows, cross_rows, curves_figure, markdown_table,
                                           write_cross_model_report)

    crosses = [("(a)", cohesive_to_gradient), ("(b)", gradient_to_cohesive)]
    header, rows = cross_rows(crosses)
    assert len(rows) == 2 and all(len(r) == len(header) for r in rows)
    assert "Gf = " in rows[1][3] and "N/mm" in rows[1][3]  # the cohesive fit, with its units
    text = markdown_table(*comparison_rows(comparison[0]))
    assert text.count("\n") == 3 and text.startswith("| model |")  # header, rule, two models
    fig = curves_figure([CurvePanel.of_cross("(a)", cohesive_to_gradient),
                         CurvePanel.of_comparison("one data set", comparison[0])])
    assert len(fig.axes) == 2 and len(fig.axes[1].lines) == 3  # data and the two fitted runs
    path = write_cross_model_report(tmp_path / "report.html", crosses=crosses,
                                    comparisons=[("one data set", comparison[0])], notes=["a note"])
    html = path.read_text()
    assert html.count("<img") == 1 + 2 * 4  # the curves, then the fit and Kalman figures of four fits
    assert html.count("<details>") == 4 and "a note" in html and "cohesive crack" in html
