"""``fracid posterior`` on the small bar study ((c, beta) = (2, 250)): the identification, then the
posterior by importance sampling on the exact model; its files, the truth inside its intervals, a rerun
from the run store, and the ``[posterior]`` section's validation."""

import dataclasses
import importlib.util
import json
import shutil
import sys

import numpy as np
import pytest

from _bar_study import SCREENED_POSTERIOR, run_bar_command, write_bar_study
from fracid import cli
from fracid.runtime import exits
from fracid.inverse.sampling.mixture import weighted_quantile
from fracid.inverse.sampling.posterior import PosteriorSettings

PNG = b"\x89PNG\r\n\x1a\n"


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    """The bar study with a small [posterior] section (two levels), run once: (config, output directory)."""
    return run_bar_command(tmp_path_factory.mktemp("posterior"), "posterior", SCREENED_POSTERIOR)


def _draws(out):
    header = (out / "posterior.csv").read_text().splitlines()[0].split(",")
    return header, np.loadtxt(out / "posterior.csv", delimiter=",", skiprows=1)


def test_posterior_writes_draws_json_figures_and_page(run):
    config, out = run
    header, table = _draws(out)
    assert header == ["c", "beta", "weight", "log_likelihood"]
    assert table.shape[0] >= 40 and np.isclose(table[:, 2].sum(), 1.0, atol=1e-6)
    info = json.loads((out / "posterior.json").read_text())
    assert info["ess"] >= 30 and info["status"] == "converged"
    levels = info["screening"]  # two levels: coarse draws corrected by fewer fine runs (or the fallback, said)
    assert (levels is not None and levels["fine_runs"] < levels["coarse_draws"]) or info["notes"], info["notes"]
    assert np.shape(info["interval_90"]) == (2, 2) and np.shape(info["gaussian"]["interval_90"]) == (2, 2)
    c = info["parameters"]["c"]
    assert c["unit"] == "mm^2" and set(c) == {"unit", "gaussian", "posterior"}
    kf = c["gaussian"]
    assert np.allclose(kf["interval_90"], [kf["estimate"] - 1.645 * kf["std"], kf["estimate"] + 1.645 * kf["std"]],
                       rtol=1e-3)
    for name in ("corner", "posterior_predictive"):
        assert (out / "figures" / f"{name}.png").read_bytes()[:8] == PNG
    page = (out / "posterior.html").read_text()
    assert "Identification and posterior" in page and "importance sampling" in page and "90 % credible interval" in page
    assert page.count("data:image/png;base64,") == 2
    for written in ("result.json", "fit.csv", "report.html", "runs.sqlite"):  # what identify writes
        assert (out / written).exists()
    assert (out / "posterior.nc").exists() == (importlib.util.find_spec("arviz") is not None)


def test_truth_lies_inside_the_99_percent_intervals(run):
    _, table = _draws(run[1])
    for j, truth in enumerate([2.0, 250.0]):
        lower, upper = weighted_quantile(table[:, j], table[:, 2], [0.005, 0.995])
        assert lower < truth < upper


def test_rerun_reuses_every_stored_run_and_skips_netcdf_without_arviz(run, capsys, monkeypatch):
    config, out = run
    monkeypatch.setitem(sys.modules, "arviz", None)  # import arviz fails
    (out / "posterior.nc").unlink(missing_ok=True)
    assert cli.main(["posterior", str(config), "--out", str(out), "--workers", "1"]) == 0
    text = capsys.readouterr().out
    assert "posterior forward runs:" in text and "(0 computed" in text
    assert "posterior.nc skipped" in text and not (out / "posterior.nc").exists()


def test_no_finite_kalman_covariance_exits_3(run, tmp_path, monkeypatch, capsys):
    from fracid.inverse.methods import strategy

    config, out = run
    (tmp_path / "out").mkdir()
    shutil.copy(out / "runs.sqlite", tmp_path / "out" / "runs.sqlite")
    real = strategy.identify_data

    def no_covariance(*args, **kwargs):
        result = real(*args, **kwargs)
        result.C = np.full_like(result.C, np.nan)
        return result

    monkeypatch.setattr(strategy, "identify_data", no_covariance)
    status = cli.main(["posterior", str(config), "--out", str(tmp_path / "out"), "--workers", "1", "--quiet"])
    assert status == exits.FAILED
    assert "no finite estimate and covariance" in capsys.readouterr().err
    assert not (tmp_path / "out" / "posterior.csv").exists()


@pytest.mark.parametrize("line, words", [("defensive = 1.5", ["posterior.defensive", "1.5", "0 <= d < 1"]),
                                         ("samples_per_round = 1", ["posterior.samples_per_round", ">= 2"]),
                                         ("target_ess = true", ["posterior.target_ess", "> 1"]),
                                         ("chains = 4", ["posterior.chains", "unknown key", "samples_per_round"])])
def test_bad_posterior_value_exits_2_naming_the_key(tmp_path, capsys, line, words):
    config = write_bar_study(tmp_path)
    config.write_text(config.read_text() + f"\n[posterior]\n{line}\n")
    assert cli.main(["posterior", str(config), "--out", str(tmp_path / "out"), "--quiet"]) == exits.INPUT
    err = capsys.readouterr().err
    assert str(config.resolve()) in err and len(err.strip().splitlines()) == 1
    for word in words:
        assert word in err


def test_defaults_are_those_of_posterior_settings(tmp_path):
    from fracid.config import PosteriorConfig, load_config, posterior_settings

    assert dataclasses.asdict(PosteriorConfig()) == dataclasses.asdict(PosteriorSettings())
    config = write_bar_study(tmp_path)
    assert posterior_settings(load_config(config)) == PosteriorSettings()
    config.write_text(config.read_text() + "\n[posterior]\nseed = 7\ninflation = 3\n")
    assert posterior_settings(load_config(config)) == PosteriorSettings(seed=7, inflation=3.0)
    config.write_text(config.read_text() + "max_rounds = 2\nsamples_per_round = 10\n")
    assert any("posterior.target_ess" in w for w in load_config(config).warnings)


def test_all_runs_failed_is_a_computation_failure():
    """Every forward run of the sampler fails: a ForwardRunError, exit status 3 with the message."""
    from types import SimpleNamespace

    from fracid.inverse.core.forward_operator import RunRecord
    from fracid.inverse.core.space import ParameterSpace
    from fracid.inverse.core.sensitivity import ForwardRunError
    from fracid.inverse.sampling.sample import sample_posterior

    def failing(x, needed=None):
        return RunRecord(np.asarray(x), np.full(2, np.nan), status="failed", error="diverged")

    data = SimpleNamespace(y=np.zeros(2), covariance=np.eye(2))
    identification = SimpleNamespace(x=np.ones(1), C=np.eye(1), units={})
    space = ParameterSpace(("k",), (0.0,), (2.0,))
    with pytest.raises(ForwardRunError) as caught:
        sample_posterior(failing, data, space, identification, PosteriorSettings(samples_per_round=2, max_rounds=2),
                         progress=False)
    status, text = exits.describe(caught.value)
    assert status == exits.FAILED and "all 2 forward runs failed" in text and "--retry-failed" in text
