"""The inverse methods read and check their own ``[identify.<table>]`` settings (issue 26, item 1): the checkers of
``fracid.settings.checks`` (shared with the configuration's Checker), the methods' ``config_tables``,
``from_config(tables, context)`` and ``config_template``, and ``[identify]`` allowing, checking and warning of the
tables through the registry only."""

from __future__ import annotations

import math
import tomllib
from dataclasses import dataclass
from pathlib import Path
from typing import ClassVar

import numpy as np
import pytest
from hostile import bar_config, synthetic_curve, write_csv

from fracid.config import ConfigError, build_method, load_config
from fracid.inverse.methods.knn_settings import MAX_POPULATION
from fracid.config.checker import Checker
from fracid.settings import checks as settings
from fracid.settings.checks import SettingError, SettingsContext
from fracid.inverse.methods.knn_settings import DEFAULT_SCREENING, KnnSettings, knn_from_table
from fracid.inverse.methods.registry import METHODS, config_tables, known_tables, method_from_tables, table_readers
from fracid.inverse.methods.kalman_settings import KalmanSettings
from fracid.inverse.methods.knn_gauss_newton import KnnGaussNewton
from fracid.inverse.methods.knn_kalman import KnnKalman

CONTEXT = SettingsContext(n_y=12, parameters=("c", "beta"))


# ------------------------------------------------------------------------------------- the checkers

VALUES = [0, 1, 7, -3, 2.5, 3.0, -0.0, math.inf, -math.inf, math.nan, True, False, "3", None, [1], {"a": 1}]


@pytest.mark.parametrize("value", VALUES, ids=repr)
def test_integer_and_number_accept_exactly_the_ints_and_finite_numbers_that_are_not_bools(value):
    is_bool = isinstance(value, bool)
    want_int = isinstance(value, int) and not is_bool
    want_number = isinstance(value, (int, float)) and not is_bool and math.isfinite(value)
    assert settings.is_integer(value) == want_int and settings.is_number(value) == want_number
    for check, wanted in ((settings.integer, want_int), (settings.number, want_number)):
        if wanted:
            assert check("x", value) == value and type(check("x", value)) is (int if check is settings.integer else float)
        else:
            with pytest.raises(SettingError) as info:
                check("knn.x", value, "must be whatever")
            assert (info.value.key, info.value.allowed) == ("knn.x", "must be whatever")
            assert info.value.value is value or (isinstance(value, float) and math.isnan(value))


def test_the_condition_and_the_messages_of_the_checkers():
    assert settings.integer("n", 5, "must be >= 2", lambda v: v >= 2) == 5
    with pytest.raises(SettingError, match=r"^n = 1: must be >= 2$"):
        settings.integer("n", 1, "must be >= 2", lambda v: v >= 2)
    with pytest.raises(SettingError, match=r"^tol = 0: must be > 0$"):
        settings.number("tol", 0, "must be > 0", lambda v: v > 0)
    assert settings.choice("m", "lhs", ("sobol", "lhs")) == "lhs"
    for value in ("grid", 3, None):
        with pytest.raises(SettingError) as info:
            settings.choice("m", value, ("sobol", "lhs"))
        assert str(info.value) == f"m = {value!r}: must be one of 'sobol', 'lhs'"
    assert settings.table("knn", {"n": 3}, ("n", "k")) == {"n": 3}
    with pytest.raises(SettingError) as info:
        settings.table("knn", {"n": 3, "neighbours": 7}, ("n", "k"))
    assert (info.value.key, info.value.value, info.value.allowed) == ("knn.neighbours", 7,
                                                                      "unknown key; allowed keys here: n, k")
    with pytest.raises(SettingError, match=r"^knn = 5: must be a table \(section\) with keys n, k$"):
        settings.table("knn", 5, ("n", "k"))
    with pytest.raises(SettingError) as info:
        settings.table("", {"zz": 1}, ("n",))
    assert info.value.key == "zz"
    assert isinstance(info.value, ValueError)


@pytest.mark.parametrize("value", VALUES, ids=repr)
def test_the_configuration_checker_judges_every_value_as_the_settings_checkers(value, tmp_path):
    """Checker.integer, .number, .choice and .table are the same checks, their SettingError as a ConfigError
    naming the file."""
    ck = Checker(tmp_path / "cfg.toml")
    calls = [("integer", ("k", value, "must be an integer >= 0", lambda v: v >= 0)),
             ("number", ("k", value, "must be a number > 0", lambda v: v > 0)),
             ("choice", ("k", value, ("a", "b"))), ("table", ("k", value, ("a",)))]
    for name, args in calls:
        try:
            expected = getattr(settings, name)(*args)
        except SettingError as err:
            with pytest.raises(ConfigError) as info:
                getattr(ck, name)(*args)
            assert str(info.value) == f"{ck.path}: {err}"
        else:
            assert getattr(ck, name)(*args) == expected


# ------------------------------------------------------------------------------------- the methods' tables


def test_the_methods_declare_their_tables_and_the_registry_knows_them():
    assert KnnKalman.config_tables == ("knn", "kalman") and KnnGaussNewton.config_tables == ("knn", "gauss-newton")
    assert known_tables() == ("knn", "kalman", "gauss-newton")
    assert table_readers("knn") == ("knn-kalman", "knn-gauss-newton") and table_readers("kalman") == ("knn-kalman",)


def test_knn_kalman_from_its_tables():
    method = KnnKalman.from_config({"knn": {"n": 16, "method": "lhs", "k": 4, "seed": 2},
                                    "kalman": {"groups": 3, "max_iterations": 5, "tol": 0.1, "restart": "prior-mean",
                                               "max_starts": 2}}, CONTEXT)
    assert method.knn == KnnSettings(n=16, method="lhs", seed=2, k=4, screening=DEFAULT_SCREENING)
    assert (method.kalman.max_iterations, method.kalman.tol, method.kalman.restart, method.kalman.max_starts) == \
        (5, 0.1, "prior-mean", 2)
    assert [g.tolist() for g in method.kalman.groups] == [[0, 1, 2, 3], [4, 5, 6, 7], [8, 9, 10, 11]]
    default = KnnKalman.from_config({"knn": {}, "kalman": {}}, SettingsContext(n_y=3, parameters=("c",)))
    # the configuration's population runs on a screening mesh by default, the library's (KnnSettings()) does not
    assert default.knn == KnnSettings(screening=DEFAULT_SCREENING)
    assert [g.tolist() for g in default.kalman.groups] == [[0], [1], [2]]
    assert default.kalman.max_starts == KalmanSettings().max_starts


@pytest.mark.parametrize("tables, key, value, words", [
    ({"knn": {"n": 1}}, "knn.n", 1, "must be an integer >= 2"),
    ({"knn": {"n": 8, "k": 9}}, "knn.k", 9, "1 <= k <= the population size 8 (n = 8, method 'sobol')"),
    ({"knn": {"n": 2}}, "knn.k (default)", 5, "population size 2"),
    ({"knn": {"n": 400, "method": "grid"}}, "knn.n", 400, "the population of 160,000 points (n**p = 400**2"),
    ({"kalman": {"groups": 13}}, "kalman.groups", 13, "1 <= groups <= n_y = 12"),
    ({"kalman": {"restart": "again"}}, "kalman.restart", "again", "'linearize', 'prior-mean'"),
    ({"kalman": {"tol": True}}, "kalman.tol", True, "must be a number > 0"),
    ({"kalman": 4}, "kalman", 4, "must be a table (section) with keys groups, max_iterations"),
])
def test_knn_kalman_refuses_a_bad_setting_by_its_key(tables, key, value, words):
    with pytest.raises(SettingError) as info:
        KnnKalman.from_config({"knn": {}, "kalman": {}, **tables}, CONTEXT)
    assert (info.value.key, info.value.value) == (key, value) and words in info.value.allowed


def test_the_population_limit_is_at_the_limit_and_counts_the_memory():
    grid = {"method": "grid", "k": 1}
    assert knn_from_table({"n": 316, **grid}, CONTEXT).population(2) == 99_856 <= MAX_POPULATION
    with pytest.raises(SettingError) as info:
        knn_from_table({"n": 317, **grid}, CONTEXT)
    assert "100,489 points" in info.value.allowed and f"limit of {MAX_POPULATION:,}" in info.value.allowed
    values = 100_489 * (2 + 12)  # p parameters + n_y outputs per point
    assert f"{values:,} x 8 bytes" in info.value.allowed and "10.7 MiB" in info.value.allowed
    assert 8 * values / 2**20 == pytest.approx(10.73, abs=0.01)


def test_knn_gauss_newton_from_its_tables():
    method = KnnGaussNewton.from_config({"knn": {"n": 8, "k": 3}, "gauss-newton": {"max_iterations": 7, "tol": 0.05}},
                                        CONTEXT)
    assert (method.knn.n, method.knn.k, method.max_iterations, method.tol) == (8, 3, 7, 0.05)
    with pytest.raises(SettingError) as info:
        KnnGaussNewton.from_config({"knn": {}, "gauss-newton": {"tol": 0}}, CONTEXT)
    assert (info.value.key, info.value.allowed) == ("gauss-newton.tol", "must be a number > 0 [standard deviations]")


@pytest.mark.parametrize("cls", [KnnKalman, KnnGaussNewton])
def test_the_template_is_toml_that_the_method_reads_back(cls):
    start = {"knn": {"n": 24, "method": "lhs", "k": 3}}
    for tables in ({}, start):
        lines = cls.config_template(tables)
        parsed = tomllib.loads("[identify]\n" + "\n".join(lines))["identify"]
        assert tuple(parsed) == cls.config_tables and all("#" in line for line in lines if "=" in line)
        method = cls.from_config(parsed, CONTEXT)
        assert (method.knn.n, method.knn.method, method.knn.k) == ((24, "lhs", 3) if tables else (32, "sobol", 5))


# ------------------------------------------------------------------------------------- through the configuration


@dataclass(frozen=True)
class Simplex:
    """A method without ``config_tables``: it reads the table of its name."""

    steps: int = 10
    name: ClassVar[str] = "simplex"
    stages: ClassVar[dict] = {"simplex": "Simplex"}

    @classmethod
    def from_config(cls, tables, context):
        own = settings.table(cls.name, tables[cls.name], ("steps",))
        return cls(steps=settings.integer("simplex.steps", own.get("steps", 10), "must be an integer >= 1 (steps)",
                                          lambda v: v >= 1))


@dataclass(frozen=True)
class Fixed:
    """A method without ``from_config``: built with its defaults, it takes no settings."""

    name: ClassVar[str] = "fixed"
    stages: ClassVar[dict] = {}


def _config(tmp_path: Path, **changes) -> Path:
    write_csv(tmp_path / "bar.csv", *synthetic_curve())
    (tmp_path / "cfg.toml").write_text(bar_config(**changes), encoding="utf-8")
    return tmp_path / "cfg.toml"


def test_a_method_without_config_tables_reads_the_table_of_its_name(tmp_path, monkeypatch):
    monkeypatch.setitem(METHODS, Simplex.name, Simplex)
    assert config_tables(Simplex) == ("simplex",) and "simplex" in known_tables()
    cfg = load_config(_config(tmp_path, identify='method = "simplex"', tail="[identify.simplex]\nsteps = 4"))
    assert build_method(cfg) == Simplex(steps=4) and cfg.identify.tables["simplex"] == {"steps": 4}
    # the built-in tables it does not read are warned of, naming the methods that read them
    assert ("[identify.knn] is given but identify.method = 'simplex': its settings are not used (set method = "
            '"knn-kalman" or "knn-gauss-newton" to use them)') in cfg.warnings
    with pytest.raises(ConfigError, match=r"cfg\.toml: identify\.simplex\.steps = 0: must be an integer >= 1 \(steps\)$"):
        load_config(_config(tmp_path, identify='method = "simplex"', tail="[identify.simplex]\nsteps = 0"))
    # a table of the chosen default method's: read; the simplex's: warned of, still checked
    cfg = load_config(_config(tmp_path, tail="[identify.simplex]\nsteps = 4"))
    assert any(w.startswith("[identify.simplex] is given but identify.method = 'knn-kalman'") and
               '(set method = "simplex" to use them)' in w for w in cfg.warnings)
    with pytest.raises(ConfigError, match=r"identify\.simplex\.steps = 0"):
        load_config(_config(tmp_path, tail="[identify.simplex]\nsteps = 0"))


def test_a_table_no_registered_method_reads_is_an_unknown_key(tmp_path):
    with pytest.raises(ConfigError, match=r"identify\.simplex = a table \{steps\}: unknown key; allowed keys here: "
                                          r"parameters, method, bounds, discretisation_error, model_error, knn, kalman, "
                                          r"gauss-newton$"):
        load_config(_config(tmp_path, tail="[identify.simplex]\nsteps = 4"))


def test_a_method_without_from_config_takes_no_settings(tmp_path, monkeypatch):
    monkeypatch.setitem(METHODS, Fixed.name, Fixed)
    assert method_from_tables(Fixed, {}, CONTEXT) == Fixed()
    cfg = load_config(_config(tmp_path, identify='method = "fixed"'))
    assert build_method(cfg) == Fixed()
    with pytest.raises(ConfigError, match=r"identify\.fixed = a table \{x\}: the method 'fixed' takes no settings"):
        load_config(_config(tmp_path, identify='method = "fixed"', tail="[identify.fixed]\nx = 1"))


def test_the_configuration_keeps_the_tables_and_the_method_is_built_from_them(tmp_path):
    cfg = load_config(_config(tmp_path, identify='method = "knn-gauss-newton"', k="2",
                              tail="[identify.gauss-newton]\nmax_iterations = 7"))
    assert cfg.identify.tables == {"knn": {"n": 8, "k": 2}, "kalman": {"groups": 2, "max_iterations": 3},
                                   "gauss-newton": {"max_iterations": 7}}
    assert build_method(cfg) == KnnGaussNewton(KnnSettings(n=8, k=2, screening=DEFAULT_SCREENING), max_iterations=7)
    assert ("[identify.kalman] is given but identify.method = 'knn-gauss-newton': its settings are not used (set "
            'method = "knn-kalman" to use them)') in cfg.warnings
    # an unread table is checked too (by a method that reads it)
    with pytest.raises(ConfigError, match=r"identify\.kalman\.groups = 13: .*n_y = 12"):
        load_config(_config(tmp_path, identify='method = "knn-gauss-newton"', groups="13"))
    method = build_method(load_config(_config(tmp_path)))
    assert isinstance(method, KnnKalman) and np.concatenate(method.kalman.groups).tolist() == list(range(12))
