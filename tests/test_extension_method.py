"""A new inverse method, written in this file only (no package file edited): KNN over a small population,
then Nelder-Mead (scipy) on the Bayesian objective, with the covariance of the linearised problem at the end.
Registered in ``fracid.inverse.methods.registry.METHODS``, it runs through ``identify``, ``run_study`` and a
configuration file (``[identify] method`` with its own ``[identify.<name>]`` table) by ``fracid identify``
and ``fracid study``."""

from __future__ import annotations

import json
import re
from dataclasses import dataclass
from typing import ClassVar

import numpy as np
import pytest
from hostile import TRUTH, bar_config, synthetic_curve, write_csv

import fracid
from fracid import cli
from fracid.inverse.core.forward_operator import ForwardOperator, Observation
from fracid.settings import checks as settings
from fracid.inverse.methods.knn_settings import KnnSettings
from fracid.inverse.methods.knn_started import population_search
from fracid.inverse.methods.knn_settings import knn_from_table
from fracid.inverse.core.method import MethodResult, identification_bounds, result_fields
from fracid.inverse.methods.registry import METHODS, StudyMethod
from fracid.inverse.core.runs import StoredOperator
from fracid.inverse.core.sensitivity import ForwardRunError, exact_sensitivity
from fracid.inverse.core.space import ParameterSpace
from fracid.inverse.methods.strategy import identify
from fracid.inverse.studies.study import StudySettings, run_study
from fracid.inverse.studies.twin import synthetic_data

optimize = pytest.importorskip("scipy.optimize")
pytestmark = pytest.mark.slow

SPACE = ParameterSpace(("c", "beta"), [0.5, 100.0], [4.0, 500.0])


def _solve(C, b):
    """C^-1 b for a dense covariance or any covariance object with ``solve``."""
    return C.solve(b) if hasattr(C, "solve") else np.linalg.solve(np.asarray(C, float), b)


@dataclass
class _Fit:
    x: np.ndarray
    C: np.ndarray
    y: np.ndarray
    evaluations: int
    failed: bool = False
    status: str = "converged"
    converged: bool = True

    @property
    def std(self):
        return np.sqrt(np.diag(self.C))


@dataclass(frozen=True)
class KnnNelderMead:
    """KNN population (prior), then Nelder-Mead on (y - h(x))^T C^-1 (y - h(x)) + (x - x0)^T C0^-1 (x - x0) inside the
    bounds; covariance (S^T C^-1 S + C0^-1)^-1 with the sensitivities S at the end."""

    n: int = 8
    k: int = 3
    max_evaluations: int = 80
    name: ClassVar[str] = "knn-nelder-mead"
    stages: ClassVar[dict] = {"knn": "KNN", "nelder_mead": "Nelder-Mead"}

    #: the tables of [identify] it reads: the shared [identify.knn] and its own [identify.knn-nelder-mead]
    config_tables: ClassVar[tuple] = ("knn", "knn-nelder-mead")

    @classmethod
    def from_config(cls, tables, context):
        """Population from [identify.knn] (the built-in methods' checks); ``max_evaluations`` from this method's
        own [identify.knn-nelder-mead], checked with the configuration's checkers."""
        knn = knn_from_table(tables["knn"], context)
        own = settings.table(cls.name, tables[cls.name], ("max_evaluations",))
        value = settings.integer(f"{cls.name}.max_evaluations", own.get("max_evaluations", cls.max_evaluations),
                                 "must be an integer >= 10", lambda v: v >= 10)
        return cls(n=knn.n, k=knn.k, max_evaluations=value)

    def search(self, operator, y_exp, C_exp, space, **options):
        return population_search(KnnSettings(n=self.n, k=self.k), operator, y_exp, C_exp, space, **options)

    def fit_from(self, evaluate, y_exp, C_exp, x0, C0, *, bounds=None, executor=None, blocks=()):
        scale = np.sqrt(np.diag(C0))
        lower, upper = bounds if bounds is not None else (np.full(x0.size, -np.inf), np.full(x0.size, np.inf))

        def objective(z):
            x = np.clip(x0 + z * scale, lower, upper)
            record = evaluate(x)
            if not record.ok:
                return 1e12
            r = y_exp - record.y
            return float(r @ _solve(C_exp, r) + (x - x0) @ np.linalg.solve(C0, x - x0))

        fit = optimize.minimize(objective, np.zeros(x0.size), method="Nelder-Mead",
                                options={"maxfev": self.max_evaluations, "xatol": 1e-3, "fatol": 1e-3})
        x = np.clip(x0 + fit.x * scale, lower, upper)
        evaluate, sensitivity = exact_sensitivity(evaluate)
        try:
            y, S, _ = sensitivity(evaluate, x, None, executor)
        except ForwardRunError as err:
            return _Fit(x, C0, np.full(y_exp.size, np.nan), fit.nfev, failed=True, status=f"failed: {err}",
                        converged=False)
        information = S.T @ _solve(C_exp, S) + np.linalg.inv(C0)
        status = "converged" if fit.success else f"not converged: {fit.message}"
        return _Fit(x, np.linalg.inv(information), np.asarray(y, float), int(fit.nfev), status=status,
                    converged=bool(fit.success))

    def refine(self, operator, y_exp, C_exp, overview, *, C0=None, executor=None, blocks=(), notes=(), progress=None,
               started=None):
        bounds = identification_bounds(operator, overview.space)
        fit = self.fit_from(operator, y_exp, C_exp, overview.x0, overview.C0 if C0 is None else C0, bounds=bounds,
                            executor=executor)
        return MethodResult(
            x=fit.x, C=fit.C, y_fit=fit.y, converged=fit.converged, status=fit.status, method=self.name,
            stages=dict(self.stages), runs={"knn": len(overview.points), "knn_failed": overview.n_failed,
                                            "nelder_mead": fit.evaluations},
            records={"nelder_mead": {"evaluations": fit.evaluations}},
            **result_fields(operator, overview.space, fit.x, y_exp, C_exp, blocks=blocks, notes=notes))

    def __call__(self, operator, y_exp, C_exp, space, *, executor=None, store=None, progress=None,
                 retry_failed=False, blocks=(), notes=()):
        overview = self.search(operator, y_exp, C_exp, space, executor=executor, store=store, progress=progress,
                               retry_failed=retry_failed)
        return self.refine(StoredOperator(operator, store, retry_failed=retry_failed), y_exp, C_exp, overview,
                           executor=executor, blocks=blocks, notes=notes)


@pytest.fixture(scope="module")
def problem():
    op = ForwardOperator([Observation(fracid.BarWithWeakZone(n_elements=40), np.linspace(0.004, 0.03, 12))],
                         fracid.DamageParameters(), ("c", "beta"))
    return op, synthetic_data(op, TRUTH, {"global:relative": 0.01}, seed=None)


def test_the_new_method_meets_both_contracts_and_identifies_the_bar(problem):
    op, data = problem
    method = KnnNelderMead()
    assert isinstance(method, StudyMethod)
    result = identify(op, data.y, data.covariance, SPACE, method=method, blocks=list(data.blocks))
    assert result.method == "knn-nelder-mead" and list(result.stages) == ["knn", "nelder_mead"]
    assert result.converged and np.all(result.std > 0) and result.rms_percent < 1.0
    assert np.all(np.abs(result.x - TRUTH) <= 2 * result.std), (result.x, result.std)


def test_the_study_runs_the_new_methods_stages(problem):
    op, data = problem
    settings = StudySettings(method=KnnNelderMead(max_evaluations=30), starts=2, replicates=2)
    assert settings.replace(max_evaluations=20).method.max_evaluations == 20  # the method's own settings by name
    study = run_study(op, data, SPACE, settings)
    assert study.identification.method == "knn-nelder-mead"
    assert set(study.runs) >= {"KNN", "Nelder-Mead", "multi-start", "stability"}
    assert study.multi_start is not None and study.multi_start.ends.shape[1] == 2
    assert study.stability.estimates.shape == (2, 2) and not any(study.stability.errors)
    assert [v.name for v in study.verdict.parameters] == ["c", "beta"]


def _configured(tmp_path, table="max_evaluations = 60"):
    write_csv(tmp_path / "bar.csv", *synthetic_curve())
    text = bar_config(identify='method = "knn-nelder-mead"', tail=f"[identify.knn-nelder-mead]\n{table}\n"
                      "[study]\nstarts = 2\nreplicates = 2\n")
    (tmp_path / "cfg.toml").write_text(text, encoding="utf-8")
    return tmp_path / "cfg.toml"


def test_fracid_identify_and_study_run_the_registered_method_from_its_configuration(tmp_path, monkeypatch):
    monkeypatch.setitem(METHODS, KnnNelderMead.name, KnnNelderMead)
    config = _configured(tmp_path)
    assert cli.main(["identify", str(config), "--out", str(tmp_path / "id"), "--workers", "1", "--quiet"]) == 0
    result = json.loads((tmp_path / "id" / "result.json").read_text())
    assert result["method"] == "knn-nelder-mead" and result["runs"]["nelder_mead"] <= 60
    assert np.all(np.abs(np.array(result["x"]) - TRUTH) <= 2 * np.array(result["std"]))
    report = (tmp_path / "id" / "report.html").read_text(encoding="utf-8")
    assert "Nelder-Mead" in re.findall(r"<h2>(.*?)</h2>", report)
    assert cli.main(["study", str(config), "--out", str(tmp_path / "study"), "--workers", "1", "--quiet"]) == 0
    verdict = (tmp_path / "study" / "verdict.txt").read_text()
    assert "Verdict:" in verdict and "Nelder-Mead" in verdict


def test_a_bad_key_of_the_methods_own_table_is_named(tmp_path, monkeypatch, capsys):
    monkeypatch.setitem(METHODS, KnnNelderMead.name, KnnNelderMead)
    config = _configured(tmp_path, table="max_evaluations = 3")
    assert cli.main(["identify", str(config), "--out", str(tmp_path / "id"), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert "identify.knn-nelder-mead.max_evaluations = 3: must be an integer >= 10" in err and "Traceback" not in err
