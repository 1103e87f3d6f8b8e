"""The registry of inverse methods (fracid.inverse.methods.registry.METHODS) and ``[identify] method``: chosen in
the configuration, validated, and run by ``fracid identify``."""

from __future__ import annotations

import json

import numpy as np
import pytest
from hostile import TRUTH, bar_config, check, run_fracid, synthetic_curve, write_csv

from fracid.config import ConfigError, build_method, load_config
from fracid.inverse.methods.registry import METHODS
from fracid.inverse.methods.knn_gauss_newton import KnnGaussNewton
from fracid.inverse.methods.knn_kalman import KnnKalman

OUT = ("--out", "out", "--workers", "1", "--quiet")


@pytest.fixture(scope="module")
def curve():
    return synthetic_curve()


def _case(tmp_path, curve, **changes):
    write_csv(tmp_path / "bar.csv", *curve)
    (tmp_path / "cfg.toml").write_text(bar_config(**changes), encoding="utf-8")
    return tmp_path / "cfg.toml"


def test_the_registry_lists_both_methods_by_their_names():
    assert METHODS == {"knn-kalman": KnnKalman, "knn-gauss-newton": KnnGaussNewton}
    assert next(iter(METHODS)) == "knn-kalman"  # the default first
    assert all(cls.name == name for name, cls in METHODS.items())


def test_the_configured_method_is_built_with_its_settings(tmp_path, curve):
    path = _case(tmp_path, curve, identify='method = "knn-gauss-newton"',
                 tail="[identify.gauss-newton]\nmax_iterations = 7\ntol = 0.05")
    method = build_method(load_config(path))
    assert isinstance(method, KnnGaussNewton)
    assert (method.max_iterations, method.tol, method.knn.n, method.knn.k) == (7, 0.05, 8, 3)
    default = build_method(load_config(_case(tmp_path, curve)))
    assert isinstance(default, KnnKalman) and default.kalman.max_iterations == 3 and len(default.kalman.groups) == 2


def test_an_unknown_key_of_the_gauss_newton_section_is_refused_by_name(tmp_path, curve):
    path = _case(tmp_path, curve, identify='method = "knn-gauss-newton"', tail="[identify.gauss-newton]\nsteps = 3")
    with pytest.raises(ConfigError, match=r"identify\.gauss-newton\.steps = 3: unknown key; allowed keys here: "
                                          r"max_iterations, tol"):
        load_config(path)
    path = _case(tmp_path, curve, identify='method = "knn-gauss-newton"', tail="[identify.gauss-newton]\ntol = 0")
    with pytest.raises(ConfigError, match=r"identify\.gauss-newton\.tol = 0"):
        load_config(path)


def test_a_bad_method_name_exits_2_naming_the_key_and_the_allowed_values(tmp_path, curve):
    _case(tmp_path, curve, identify='method = "simplex"')
    proc = run_fracid(["identify", "cfg.toml", *OUT], tmp_path)
    check(proc, tmp_path, 2, ("identify.method", "'simplex'", "'knn-kalman'", "'knn-gauss-newton'"))
    assert not (tmp_path / "out" / "result.json").exists()


def test_knn_gauss_newton_identifies_the_tiny_bar_twin_through_the_cli(tmp_path, curve):
    _case(tmp_path, curve, identify='method = "knn-gauss-newton"', tail="[identify.gauss-newton]\nmax_iterations = 10")
    proc = run_fracid(["identify", "cfg.toml", *OUT], tmp_path)
    check(proc, tmp_path, 0)
    result = json.loads((tmp_path / "out" / "result.json").read_text())
    assert result["method"] == "knn-gauss-newton"
    x, std = np.array(result["x"]), np.array(result["std"])
    assert np.all(np.abs(x - TRUTH) <= np.maximum(3 * std, 0.1 * np.array(TRUTH))), (x, std)


def test_the_default_method_is_still_knn_kalman(tmp_path, curve):
    _case(tmp_path, curve)
    assert load_config(tmp_path / "cfg.toml").identify.method == "knn-kalman"
    proc = run_fracid(["identify", "cfg.toml", *OUT], tmp_path)
    check(proc, tmp_path, 0)
    assert json.loads((tmp_path / "out" / "result.json").read_text())["method"] == "knn-kalman"


@pytest.mark.slow
def test_fracid_study_runs_knn_gauss_newton_and_gives_a_verdict(tmp_path, curve):
    _case(tmp_path, curve, identify='method = "knn-gauss-newton"',
          tail="[identify.gauss-newton]\nmax_iterations = 10\n[study]\nstarts = 2\nreplicates = 2")
    proc = run_fracid(["study", "cfg.toml", *OUT], tmp_path)
    check(proc, tmp_path, 0)
    study = json.loads((tmp_path / "out" / "study.json").read_text())
    assert study["identification"]["method"] == "knn-gauss-newton"
    assert set(study["runs"]) >= {"KNN", "Gauss-Newton", "multi-start", "stability"}
    assert {v["name"] for v in study["verdict"]["parameters"]} == {"c", "beta"}
    assert len(study["stability"]["estimates"]) == 2 and len(study["multi_start"]["ends"]) == 2
    verdict = (tmp_path / "out" / "verdict.txt").read_text()
    assert "Gauss-Newton: converged" in verdict
    assert "<h2>Gauss-Newton</h2>" in (tmp_path / "out" / "report.html").read_text(encoding="utf-8")
