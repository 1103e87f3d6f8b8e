"""The error terms through the configuration and the command line: ``[identify] discretisation_error`` and
``model_error`` read and checked (a bad value exits 2 naming the key and the value), ``fracid identify`` reporting
them per data block (result.json, the summary, report.html), ``fracid posterior`` marginalising the model error."""

import json

import pytest

from _bar_study import SMALL_POSTERIOR, write_bar_study
from fracid import cli
from fracid.runtime import exits
from fracid.config import load_config
from fracid.inverse.likelihood.settings import DiscretisationError, ModelError

TERMS = 'discretisation_error = "richardson"\nmodel_error = "variance"\n'


def _with_terms(directory, terms=TERMS, n_elements=30):
    config = write_bar_study(directory, n_elements=n_elements)
    config.write_text(config.read_text().replace('parameters = ["c", "beta"]\n', 'parameters = ["c", "beta"]\n' + terms))
    return config


def test_the_keys_are_read_as_words_or_tables(tmp_path):
    cfg = load_config(_with_terms(tmp_path))
    assert cfg.identify.discretisation_error == DiscretisationError() and cfg.identify.model_error == ModelError()
    tables = ('discretisation_error = "off"\n[identify.model_error]\nkind = "bias"\nprior = "log-uniform"\n'
              'correlation_length = 0.5\n[identify.bounds]\n')
    config = _with_terms(tmp_path, "")
    config.write_text(config.read_text().replace("[identify.bounds]\n", tables))
    cfg = load_config(config)
    assert cfg.identify.discretisation_error is None
    assert cfg.identify.model_error == ModelError(kind="bias", prior="log-uniform", correlation_length=0.5)
    assert load_config(write_bar_study(tmp_path)).identify.model_error is None  # off by default


@pytest.mark.parametrize("terms, words", [
    ('discretisation_error = "fine"\n', ["identify.discretisation_error = 'fine'", "'richardson'"]),
    ('model_error = 0.05\n', ["identify.model_error = 0.05", "'variance'"]),
    ('model_error = {kind = "variance", prior = "flat"}\n', ["identify.model_error.prior = 'flat'", "half-cauchy"]),
    ('model_error = {bounds = [0.5, 0.1]}\n', ["identify.model_error.bounds = [0.5, 0.1]", "0 < lower < upper"]),
    ('discretisation_error = {refinement = 1}\n', ["identify.discretisation_error.refinement = 1", "1 < refinement"]),
    ('discretisation_error = {kind = "richardson", sizes = 3}\n', ["identify.discretisation_error.sizes", "unknown key"]),
])
def test_a_bad_value_exits_2_naming_the_key_and_the_value(tmp_path, capsys, terms, words):
    config = _with_terms(tmp_path, terms)
    assert cli.main(["identify", str(config), "--out", str(tmp_path / "out"), "--quiet"]) == exits.INPUT
    err = capsys.readouterr().err
    assert "Traceback" not in err and all(w in err for w in words), err


def test_a_refined_mesh_beyond_the_limits_is_refused(tmp_path, capsys):
    config = _with_terms(tmp_path, 'discretisation_error = "richardson"\n', n_elements=30)
    config.write_text(config.read_text().replace("n_elements = 30", "n_elements = 150000"))
    assert cli.main(["check", str(config), "--no-time"]) == exits.INPUT
    err = capsys.readouterr().err
    assert "identify.discretisation_error = 'richardson'" in err and "2 times finer" in err and "300,000" in err


def test_identify_and_posterior_report_the_terms_per_block(tmp_path, capsys):
    config = _with_terms(tmp_path)
    config.write_text(config.read_text() + SMALL_POSTERIOR)
    out = tmp_path / "out"
    assert cli.main(["posterior", str(config), "--out", str(out), "--workers", "1"]) == 0
    printed = capsys.readouterr().out
    assert "error terms in the data covariance" in printed and "model-error std of global" in printed
    terms = json.loads((out / "result.json").read_text())["error_terms"]
    row = terms["blocks"][0]
    assert row["measurement_std"] == pytest.approx(0.02) and row["discretisation_std"] > 0 and row["model_error_std"] > 0
    assert row["total_std"] ** 2 > row["measurement_std"] ** 2 + row["model_error_std"] ** 2
    assert len(terms["discretisation"]["error"]) == 12 and terms["model_error"]["sigma"][0]["group"] == "global"
    report = (out / "report.html").read_text()
    assert "Error terms: discretisation and model error" in report and "discretisation std" in report
    posterior = json.loads((out / "posterior.json").read_text())
    assert posterior["model_error"][0]["interval_90"][0] < posterior["model_error"][0]["interval_90"][1]
    assert "Model error" in (out / "posterior.html").read_text()
