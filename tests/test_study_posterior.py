"""``fracid study`` with ``[study] posterior = true`` on the small bar study ((c, beta) = (2, 250)): the
posterior sampled after the checks, its files and report section, and a verdict that names the measure it
used; then the verdict rules on hand-made posteriors (a skewed one, one cut by a bound, a correlated one)."""

import json
import shutil

import numpy as np
import pytest

from _bar_study import SMALL_POSTERIOR, run_bar_command, write_bar_study
from fracid import cli
from fracid.runtime import exits
from fracid.inverse.sampling.posterior_result import PosteriorResult
from fracid.inverse.studies.verdict import GAUSSIAN_MEASURE, POSTERIOR_MEASURE, Z_90, DataDescription, parameter_verdicts

STUDY = "\n[study]\nstarts = 2\nreplicates = 2\nposterior = true\n"
PNG = b"\x89PNG\r\n\x1a\n"


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    """The bar study with the posterior asked for, run once: (config, output directory)."""
    return run_bar_command(tmp_path_factory.mktemp("study_posterior"), "study", STUDY + SMALL_POSTERIOR, workers="2")


@pytest.mark.slow
def test_study_samples_the_posterior_and_its_verdict_names_the_measure(run):
    _, out = run
    study = json.loads((out / "study.json").read_text())
    post = study["posterior"]
    assert post["names"] == ["c", "beta"] and post["draws"] >= 40 and post["ess"] > 0 and post["status"]
    assert np.shape(post["interval_90"]) == (2, 2) and "credible interval" in post["interval_90_label"]
    assert study["runs"]["posterior"]["runs"] == post["draws"]
    assert study["verdict"]["measure"] == POSTERIOR_MEASURE
    for verdict, mean, interval in zip(study["verdict"]["parameters"], post["mean"], post["interval_90"]):
        assert verdict["measure"] == "posterior 90 % credible interval"
        assert verdict["value"] == pytest.approx(mean) and verdict["interval"] == pytest.approx(interval)
        assert verdict["std"] == pytest.approx((interval[1] - interval[0]) / (2 * 1.6448536), rel=1e-6)
        assert any(r.startswith("Gaussian (linearised) std: ") for r in verdict["remarks"])
    text = (out / "verdict.txt").read_text()
    assert text.count("[measure: posterior 90 % credible interval [") == 2
    assert "Verdict measure: posterior 90 % credible interval" in text and "Posterior: " in text
    for name in ("posterior.csv", "posterior.json", "posterior.html"):
        assert (out / name).stat().st_size > 0
    for name in ("corner", "posterior_predictive"):
        assert (out / "figures" / f"{name}.png").read_bytes()[:8] == PNG
    html = (out / "report.html").read_text()
    assert "<h2>Posterior</h2>" in html and "Gaussian 90 % interval" in html
    assert "effective sample size (ESS)" in html and 'href="posterior.html"' in html
    assert 'alt="corner plot"' in html and 'alt="posterior predictive"' in html
    assert html.index("<h2>Verdict</h2>") < html.index("<h2>Posterior</h2>")


@pytest.mark.slow
def test_uniqueness_does_not_sample_and_keeps_the_gaussian_verdict(run, tmp_path, capsys):
    config, out = run
    (tmp_path / "out").mkdir()
    shutil.copy(out / "runs.sqlite", tmp_path / "out" / "runs.sqlite")  # the stored runs: nothing to compute
    assert cli.main(["uniqueness", str(config), "--out", str(tmp_path / "out"), "--workers", "1"]) == 0
    assert "posterior: skipped" in capsys.readouterr().out
    study = json.loads((tmp_path / "out" / "study.json").read_text())
    assert "posterior" not in study and "posterior" not in study["runs"]
    assert {v["measure"] for v in study["verdict"]["parameters"]} == {GAUSSIAN_MEASURE}
    assert not (tmp_path / "out" / "posterior.csv").exists()
    assert "<h2>Posterior</h2>" not in (tmp_path / "out" / "report.html").read_text()


@pytest.mark.parametrize("value", ['"yes"', "1"])
def test_a_non_boolean_study_posterior_exits_2_naming_the_key(tmp_path, capsys, value):
    config = write_bar_study(tmp_path)
    config.write_text(config.read_text() + f"\n[study]\nposterior = {value}\n")
    assert cli.main(["study", str(config), "--out", str(tmp_path / "out"), "--quiet"]) == exits.INPUT
    err = capsys.readouterr().err
    assert "study.posterior" in err and "must be true" in err and "or false" in err


def _posterior(x, names, estimate, estimate_cov, weights=None) -> PosteriorResult:
    """A PosteriorResult of the draws ``x`` (equal weights unless given), without outputs."""
    n = len(x)
    w = np.full(n, 1.0 / n) if weights is None else np.asarray(weights, float) / np.sum(weights)
    return PosteriorResult(list(names), np.asarray(x, float), w, np.zeros(n), np.zeros((n, 0)), np.zeros(0),
                           np.zeros(0), float(1.0 / np.sum(w**2)), 1, 0, np.asarray(estimate, float),
                           np.asarray(estimate_cov, float), (x.min(axis=0), x.max(axis=0)), status="converged")


def test_verdict_reads_the_credible_interval_not_the_gaussian_std():
    """A: the Gaussian says 5 %, but the posterior is skewed against the lower bound 0.9 with a long tail (a
    90 % interval of about [0.91, 1.35]): not identified. B: the Gaussian says 16 %, but the bounds
    [245, 300] cut the posterior: identified."""
    rng = np.random.default_rng(1)
    n = 20000
    a = 0.9 + rng.exponential(0.15, n)
    b = rng.normal(250.0, 40.0, 4 * n)
    b = b[(b > 245.0) & (b < 300.0)][:n]
    x, C = np.array([1.0, 250.0]), np.diag([0.05, 40.0]) ** 2
    C_prior = np.diag([(3.0 - 0.9) ** 2 / 12, 55.0**2 / 12])
    post = _posterior(np.column_stack([a, b]), ["a", "b"], x, C)

    gaussian = parameter_verdicts(["a", "b"], x, C, C_prior, data=DataDescription(sizes=2, local=True))
    assert (gaussian["a"].status, gaussian["b"].status) == ("identified", "not identifiable")
    assert gaussian.measure == GAUSSIAN_MEASURE and gaussian["a"].measure == GAUSSIAN_MEASURE
    assert gaussian["a"].interval == () and "[measure: Gaussian (linearised) std]" in gaussian.text()

    verdict = parameter_verdicts(["a", "b"], x, C, C_prior, data=DataDescription(sizes=2, local=True),
                                 posterior=post)
    assert verdict.measure == POSTERIOR_MEASURE
    assert verdict["a"].status == "not identifiable" and verdict["b"].status == "identified"
    intervals = post.credible_intervals(0.9)
    for j, name in enumerate(["a", "b"]):
        v = verdict[name]
        assert v.measure == POSTERIOR_MEASURE and v.interval == pytest.approx(intervals[j])
        assert v.value == pytest.approx(post.mean[j])
        assert v.std == pytest.approx((intervals[j, 1] - intervals[j, 0]) / (2 * Z_90))
    assert 0.1 < verdict["a"].relative_std < 0.2 and verdict["b"].relative_std < 0.08
    assert "by it alone the parameter would be identified" in verdict["a"].remarks[-1]
    assert "by it alone the parameter would not be identified" in verdict["b"].remarks[-1]
    text = verdict.text()
    assert "a: not identifiable" in text and "b: identified" in text
    assert text.count("[measure: posterior 90 % credible interval [") == 2
    json.dumps(verdict.as_dict())  # study.json takes it as it is


def test_correlation_and_conditional_std_come_from_the_weighted_draws():
    """A valley c ~ beta in the (weighted) draws: 20 % marginals, 2 % along the valley: correlated, with
    the posterior's r; the Gaussian given (uncorrelated, 20 %) would call both not identifiable."""
    rng = np.random.default_rng(2)
    u = rng.normal(size=(40000, 2))
    c = 2.0 * (1 + 0.2 * u[:, 0])
    beta = 250.0 * (1 + 0.2 * u[:, 0] + 0.02 * u[:, 1])
    draws = np.column_stack([c, beta])
    weights = np.exp(-0.5 * u[:, 1] ** 2 / 4.0)  # importance-like weights, not all equal
    x, C = np.array([2.0, 250.0]), np.diag([0.4, 50.0]) ** 2
    post = _posterior(draws, ["c", "beta"], x, C, weights)
    gaussian = parameter_verdicts(["c", "beta"], x, C, np.diag([1.0, 1e4]))
    assert {v.status for v in gaussian.parameters} == {"not identifiable"}
    verdict = parameter_verdicts(["c", "beta"], x, C, np.diag([1.0, 1e4]), posterior=post)
    r = post.cov[0, 1] / np.sqrt(post.cov[0, 0] * post.cov[1, 1])
    assert verdict["c"].status == "correlated" and verdict["c"].partner == "beta"
    assert verdict["c"].correlation == pytest.approx(r) and r > 0.99
    assert verdict["c"].conditional_std < 0.1 * verdict["c"].std
