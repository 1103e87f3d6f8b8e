"""A new inverse method with stages of its own, written in this file only (no package file edited): a grid search
that leaves a population, a Gauss-Newton refinement that leaves a path of estimates and a last check that leaves
a generic record. Registered in ``fracid.inverse.methods.registry.METHODS`` (one line), it is identified by
``fracid identify`` from a configuration, and report.html shows a section for each of its stages, drawn by the
kind of record the stage declares (the report knows no stage by name)."""

from __future__ import annotations

import json
import re
from dataclasses import dataclass
from typing import ClassVar

import numpy as np
import pytest
from hostile import TRUTH, bar_config, synthetic_curve, write_csv

from fracid import cli
from fracid.data.covariance_matrix import as_covariance
from fracid.inverse.core.method import MethodResult, check_problem, identification_bounds, result_fields
from fracid.inverse.core.misfit import objective
from fracid.inverse.core.runs import StoredOperator
from fracid.inverse.core.sensitivity import ForwardRunError, exact_sensitivity
from fracid.inverse.core.stage_records import GENERIC, PATH, POPULATION
from fracid.inverse.methods.registry import METHODS


@dataclass(frozen=True)
class GridThenSteps:
    """A ``points`` x ``points`` grid over the bounds (its ``k`` best points give the prior), then ``steps``
    Gauss-Newton steps on the Bayesian objective from that prior, then a check of the fit's chi^2."""

    points: int = 5
    k: int = 4
    steps: int = 4
    name: ClassVar[str] = "grid-then-steps"
    stages: ClassVar[dict] = {"grid": "Grid scan", "steps": "Step refinement", "check": "Final check"}
    stage_records: ClassVar[dict] = {"grid": POPULATION, "steps": PATH, "check": GENERIC}

    def _grid(self, evaluate, y_exp, C_exp, space) -> dict:
        """The grid's population record: points, objective, statuses, ranking and the prior of its k best."""
        axis = np.linspace(0.0, 1.0, self.points)
        unit = np.array(np.meshgrid(*[axis] * len(space.names), indexing="ij")).reshape(len(space.names), -1).T
        points = space.from_unit(unit)
        records = [evaluate(x) for x in points]
        Y = np.array([r.y if r.ok else np.full(y_exp.size, np.nan) for r in records])
        f = objective(y_exp, C_exp, Y)
        order = np.argsort(f, kind="stable")
        best = points[order[: self.k]]
        C0 = np.cov(best.T) + np.diag((0.05 * (space.upper - space.lower)) ** 2)
        return {"points": points, "f": f, "status": ["ok" if r.ok else "failed" for r in records],
                "errors": [r.error or "" for r in records], "order": order, "k": self.k,
                "x0": best.mean(axis=0), "C0": C0}

    def _steps(self, evaluate, y_exp, C_exp, x0, C0, bounds) -> tuple[list, np.ndarray]:
        """Gauss-Newton steps from the prior (x0, C0) inside ``bounds``: the path and y at its end."""
        evaluate, sensitivity = exact_sensitivity(evaluate)
        lower, upper = bounds
        x, path, y = np.asarray(x0, float), [], np.full(y_exp.size, np.nan)
        for step in range(1, self.steps + 1):
            try:
                y, S, _ = sensitivity(evaluate, x, None, None)
            except ForwardRunError:
                break
            C = np.linalg.inv(S.T @ C_exp.solve(S) + np.linalg.inv(C0))
            x = np.clip(x + C @ (S.T @ C_exp.solve(y_exp - y) - np.linalg.solve(C0, x - x0)), lower, upper)
            path.append({"iteration": step, "step": 1, "x": x.copy(), "C": C})
        y = evaluate(x).y if path else y
        return path, np.asarray(y, float)

    def __call__(self, operator, y_exp, C_exp, space, *, executor=None, store=None, progress=None,
                 retry_failed=False, blocks=(), notes=()):
        y_exp, C_exp = check_problem(operator, y_exp, C_exp, space)
        C_exp = as_covariance(C_exp, name="C_exp")
        evaluate = StoredOperator(operator, store, retry_failed=retry_failed)
        grid = self._grid(evaluate, y_exp, C_exp, space)
        path, y_fit = self._steps(evaluate, y_exp, C_exp, grid["x0"], grid["C0"], identification_bounds(operator, space))
        x, C = (path[-1]["x"], path[-1]["C"]) if path else (grid["x0"], grid["C0"])
        chi2 = float(objective(y_exp, C_exp, y_fit[None, :])[0])
        failed = sum(status != "ok" for status in grid["status"])
        return MethodResult(
            x=x, C=C, y_fit=y_fit, converged=bool(path), status="converged" if path else "stopped: no step",
            method=self.name, stages=dict(self.stages), stage_records=dict(self.stage_records),
            records={"grid": grid, "steps": path, "check": {"chi2": chi2, "points": int(y_exp.size)}},
            runs={"grid": len(grid["points"]), "grid_failed": failed, "steps": 2 * len(path), "steps_iterations": len(path)},
            **result_fields(operator, space, x, y_exp, C_exp, blocks=blocks, notes=notes))


def _sections(html: str) -> dict:
    """Every ``<h2>`` section of the report: heading -> its HTML up to the next heading."""
    parts = re.split(r"<h2>(.*?)</h2>", html)
    return dict(zip(parts[1::2], parts[2::2]))


@pytest.fixture()
def identified(tmp_path, monkeypatch):
    monkeypatch.setitem(METHODS, GridThenSteps.name, GridThenSteps)
    write_csv(tmp_path / "bar.csv", *synthetic_curve())
    config = tmp_path / "cfg.toml"
    config.write_text(bar_config(identify=f'method = "{GridThenSteps.name}"'), encoding="utf-8")
    out = tmp_path / "id"
    assert cli.main(["identify", str(config), "--out", str(out), "--workers", "1", "--quiet"]) == 0
    return out


def test_fracid_identify_runs_the_new_methods_stages(identified):
    result = json.loads((identified / "result.json").read_text())
    assert result["method"] == GridThenSteps.name and list(result["stages"]) == ["grid", "steps", "check"]
    assert result["stage_records"] == {"grid": "population", "steps": "path", "check": "generic"}
    assert result["runs"]["grid"] == 25 and len(result["records"]["steps"]) == GridThenSteps.steps
    # noise-free data of the same bar: the steps end at the truth within its uncertainty
    assert np.all(np.abs(np.array(result["x"]) - TRUTH) <= 3 * np.array(result["std"]) + 1e-3 * np.array(TRUTH))


def test_the_report_shows_a_section_per_stage_by_its_kind_of_record(identified):
    sections = _sections((identified / "report.html").read_text(encoding="utf-8"))
    population = sections["Grid scan population"]
    assert 'alt="Grid scan objective"' in population and 'alt="Grid scan map"' in population
    assert "The 10 best population points" in population and "Prior of the Step refinement (mean of the 4 nearest)" in population
    assert 'alt="Step refinement history"' in sections["Step refinement"]
    check = sections["Final check"]
    assert re.search(r"<td[^>]*>chi2</td>\s*<td[^>]*>[0-9.e+-]+</td>", check) and "No record" not in check
    runs = sections["Run statistics"]
    for label in ("Grid scan forward runs (population)", "Grid scan failed runs", "Step refinement forward runs",
                  "Step refinement iterations"):
        assert label in runs, label
    # the stages appear from the one that gave the estimate back to the first
    order = [name for name in sections if name in ("Final check", "Step refinement", "Grid scan population")]
    assert order == ["Final check", "Step refinement", "Grid scan population"]
    figures = {p.name for p in (identified / "figures").glob("*.png")}
    assert {"grid_objective.png", "grid_map.png", "steps.png"} <= figures and "check.png" not in figures


def test_every_registered_method_declares_a_known_kind_of_record_for_each_stage():
    from fracid.inverse.core.stage_records import RECORD_KINDS

    for name, cls in {**METHODS, GridThenSteps.name: GridThenSteps}.items():
        assert list(cls.stage_records) == list(cls.stages), name
        assert set(cls.stage_records.values()) <= set(RECORD_KINDS), name
