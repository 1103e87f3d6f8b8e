"""The inverse method as an argument: a custom method (scipy's least squares) plugged into identify, its
result, warnings, JSON and HTML report; the default method passed explicitly; the study's settings; the misfit
in units of the data's std; the warnings in the study's verdict.txt."""

import json
import re

import numpy as np
import pytest

import fracid
from fracid.inverse.core.forward_operator import ForwardOperator, Observation
from fracid.inverse.core.space import ParameterSpace
from fracid.inverse.core.fit_status import status_action
from fracid.inverse.core.method import POOR_FIT_PERCENT, POOR_FIT_STD, InverseMethod, MethodResult, result_fields
from fracid.inverse.methods.kalman_settings import KalmanSettings
from fracid.inverse.methods.knn_kalman import IdentificationResult, KnnKalman
from fracid.inverse.methods.knn_settings import KnnSettings
from fracid.inverse.methods.registry import DEFAULT_METHOD, METHODS
from fracid.inverse.methods.strategy import identify
from fracid.inverse.studies.study import StudySettings
from fracid.inverse.studies.twin import synthetic_data

optimize = pytest.importorskip("scipy.optimize")

BAR = fracid.BarWithWeakZone(n_elements=40)
POINTS = np.linspace(0.004, 0.03, 12)  # end displacement [mm]: pre-peak, peak and softening
TRUTH = np.array([2.0, 250.0])  # c [mm^2], beta [-]
SPACE = ParameterSpace(("c", "beta"), [0.5, 100.0], [4.0, 500.0])


class LeastSquares:
    """A method the strategy, result and report do not know: scipy's trust-region least squares on the
    whitened residual from the centre of the box, covariance (J^T J)^-1 at the end. One stage."""

    name = "least-squares"

    def __call__(self, operator, y_exp, C_exp, space, *, executor=None, store=None, progress=None,
                 retry_failed=False, blocks=(), notes=()):
        std = np.sqrt(np.diag(C_exp))
        runs = {"least_squares": 0, "least_squares_failed": 0}

        def residual(x):
            runs["least_squares"] += 1
            record = operator(x)
            if not record.ok:
                runs["least_squares_failed"] += 1
                return np.full(y_exp.size, 1e3)
            return (record.y - y_exp) / std

        lower, upper = np.asarray(space.lower, float), np.asarray(space.upper, float)
        fit = optimize.least_squares(residual, 0.5 * (lower + upper), bounds=(lower, upper), x_scale=upper - lower,
                                     diff_step=1e-4, max_nfev=40)
        runs["least_squares_evaluations"] = int(fit.nfev)
        return MethodResult(
            x=fit.x, C=np.linalg.inv(fit.jac.T @ fit.jac), y_fit=y_exp + fit.fun * std, runs=runs,
            converged=bool(fit.success), status="converged" if fit.success else f"not converged: {fit.message}",
            method=self.name, stages={"least_squares": "least squares"},
            records={"least_squares": {"cost": float(fit.cost), "evaluations": int(fit.nfev), "message": fit.message}},
            **result_fields(operator, space, fit.x, y_exp, C_exp, blocks=blocks,
                            notes=[*notes, "least squares from the centre of the box"]))


@pytest.fixture(scope="module")
def problem():
    op = ForwardOperator([Observation(BAR, POINTS)], fracid.DamageParameters(), ("c", "beta"))
    return op, synthetic_data(op, TRUTH, {"global:relative": 0.01}, seed=None)


def test_a_custom_method_plugs_into_identify_result_and_report(problem, tmp_path):
    pytest.importorskip("matplotlib")
    from fracid.report import write_report

    op, data = problem
    method = LeastSquares()
    assert isinstance(method, InverseMethod) and isinstance(KnnKalman(), InverseMethod)
    result = identify(op, data.y, data.covariance, SPACE, method=method, blocks=list(data.blocks))
    assert type(result) is MethodResult and result.method == "least-squares"
    np.testing.assert_allclose(result.x, TRUTH, rtol=0.02)
    # c and beta of the bar trade off (r > 0.99): the one warning names them and points to the study
    assert result.converged and result.rms_percent < 0.5
    assert [w for w in result.warnings() if "c and beta" not in w or "fracid study" not in w] == []
    assert result.forward_runs == result.runs["least_squares"] > 0 and result.runs["wall_seconds"] > 0
    assert result.stage_runs()["least_squares"]["evaluations"] == result.records["least_squares"]["evaluations"]
    assert "least squares: converged" in result.summary() and "mm^2" in result.summary()

    saved = json.loads(result.save(tmp_path / "result.json").read_text())
    assert saved["method"] == "least-squares" and saved["stages"] == {"least_squares": "least squares"}
    assert saved["records"]["least_squares"]["evaluations"] == result.runs["least_squares_evaluations"]

    text = write_report(tmp_path / "report.html", result, control=data.control).read_text(encoding="utf-8")
    headings = re.findall(r"<h2>(.*?)</h2>", text)
    assert headings == ["Identified parameters", "Correlation", "Fit", "least squares", "Run statistics", "Notes"]
    assert "least squares: converged (what to do: the estimate and its std can be used, except the parameters" in text
    assert "<td class=\"text\">least squares forward runs</td>" in text
    assert "<td class=\"text\">least squares evaluations</td>" in text
    assert "<td class=\"text\">least squares converged</td><td>yes</td>" in text
    assert "<td class=\"text\">message</td>" in text and "least squares from the centre of the box" in text
    assert len(re.findall(r"<img ", text)) == 2  # correlation and fit: no KNN or Kalman figures


def test_default_method_settings_belong_to_the_default_method(problem):
    op, data = problem
    with pytest.raises(TypeError, match="unknown setting.s. groups, n: the method 'least-squares' has no settings"):
        identify(op, data.y, data.covariance, SPACE, method=LeastSquares(), n=8, groups="all")
    with pytest.raises(TypeError, match="unknown setting.s. population of the method 'knn-gauss-newton'; known: k, "
                                        "knn, max_iterations, n, screening, seed, start, tol"):
        identify(op, data.y, data.covariance, SPACE, method="knn-gauss-newton", population=8)
    with pytest.raises(ValueError, match="method = 'simplex': not a registered inverse method"):
        identify(op, data.y, data.covariance, SPACE, method="simplex")


def test_default_method_passed_explicitly(problem):
    op, data = problem
    method = KnnKalman(KnnSettings(n=8, k=3), KalmanSettings(groups="all", max_iterations=3))
    result = identify(op, data.y, data.covariance, SPACE, method=method)
    assert isinstance(result, IdentificationResult) and result.method == "knn-kalman"
    assert list(result.stages) == ["knn", "kalman"] and result.status_label == "Kalman filter"
    assert result.runs["knn"] == 8 and result.runs["kalman"] > 0
    assert result.forward_runs == result.runs["knn"] + result.runs["kalman"]
    assert len(result.history) == result.runs["kalman_iterations"]  # groups "all": one step per pass


def test_failed_runs_and_status_of_a_stage_named_by_the_method():
    result = MethodResult(names=["c"], x=np.array([2.0]), C=np.array([[0.01]]), y_exp=np.array([1.0, 2.0]),
                          y_fit=np.array([1.0, 2.0]), std_exp=np.array([0.1, 0.1]), status="stopped: no step",
                          runs={"grid": 9, "grid_failed": 2, "wall_seconds": 1.0}, stages={"grid": "grid search"})
    assert result.warnings() == ["grid search stopped: no step. What to do: " + status_action("not converged"),
                                 "failed forward runs: 2 of 9 in the grid search stage (each with its reason, in "
                                 "the result)"]
    assert result.stage_runs() == {"grid": {"runs": 9, "failed": 2}} and result.forward_runs == 9


def test_study_settings_group_the_options_and_replace_by_name():
    settings = StudySettings().replace(n=16, k=3, groups="all", max_iterations=8, starts=0, prior="bounds")
    method = settings.method
    assert method.knn == KnnSettings(n=16, k=3) and method.kalman == KalmanSettings(groups="all", max_iterations=8)
    assert (settings.starts, settings.replicates, settings.prior) == (0, 5, "bounds")
    assert settings.identification == KnnKalman(method.knn, method.kalman)
    assert StudySettings().replace(knn=KnnSettings(n=8), k=2).method.knn == KnnSettings(n=8, k=2)
    assert StudySettings().prior == "search" and isinstance(StudySettings().method, METHODS[DEFAULT_METHOD])
    with pytest.raises(TypeError, match="unknown setting.s. population .*or a study setting: error_terms, method, noise_seed"):
        StudySettings().replace(population=16)
    with pytest.raises(ValueError, match="choose 'search' or 'bounds'"):
        StudySettings(prior="flat")
    with pytest.raises(ValueError, match="prior = 'knn' is now called 'search'"):
        StudySettings(prior="knn")


def _fit(y_fit, std=0.001, x=2.0):
    """A one-parameter result on 10 values from 1 to 2 with the fit ``y_fit(y)`` and the data's std ``std``."""
    y = np.linspace(1.0, 2.0, 10)
    return MethodResult(names=["c"], x=np.array([x]), C=np.eye(1) * 0.01, y_exp=y, y_fit=y_fit(y), std_exp=np.full(10, std),
                        converged=True, status="converged", units={"c": "mm^2"}, bounds=([0.5], [4.0]),
                        at_bound=["c"] if x in (0.5, 4.0) else [])


def test_a_misfit_of_tens_of_std_is_flagged_in_units_of_the_std():
    """4 % above the data: a fine fit in % of the peak, but 60 std off: the warning says so and what it means."""
    result = _fit(lambda y: 1.04 * y)
    assert result.rms_percent < POOR_FIT_PERCENT and result.misfit_std > POOR_FIT_STD
    texts = result.warnings()
    assert not any("fit is poor" in text for text in texts)
    (misfit,) = [text for text in texts if "misfit" in text]
    expected = f"the misfit is {result.misfit_std:.3g} times the data's std"
    for words in (expected, "units", "geometry", "std is too small"):
        assert words in misfit, (words, misfit)


def test_a_fit_within_the_scatter_is_not_flagged():
    result = _fit(lambda y: y + 0.001)
    assert result.misfit_std == pytest.approx(1.0) and result.warnings() == []


def test_verdict_txt_carries_the_warnings_of_the_identification(tmp_path):
    """The study's summary (verdict.txt) gives the warnings stderr and report.html give: misfit, bound."""
    from fracid.inverse.studies.study import StudyResult

    class Verdict:
        measure = "Gaussian (linearised) std"

        def text(self, units):
            return "c: identified"

    ident = _fit(lambda y: 1.04 * y, x=4.0)
    study = StudyResult(ident, None, [], np.zeros(1), None, None, [], Verdict())
    assert study.summary().splitlines()[:2] == ["Verdict:", "c: identified"]
    lines = [f"Warning: {text}" for text in ident.warnings()]
    assert len(lines) == 2 and all(line in study.summary().splitlines() for line in lines)
    assert any("estimate at a bound" in line for line in lines) and any("misfit" in line for line in lines)


def test_the_configurations_study_prior_reads_search_bounds_and_the_former_knn(tmp_path):
    from fracid.config.checker import Checker
    from fracid.config.sections import read_study

    ck = Checker(tmp_path / "cfg.toml")
    assert [read_study(ck, raw).prior for raw in (None, {"prior": "search"}, {"prior": "bounds"}, {"prior": "knn"})] == \
        ["search", "search", "bounds", "search"]
    with pytest.raises(Exception, match=r"study.prior = 'flat'.*'search', 'bounds'"):
        read_study(ck, {"prior": "flat"})
