"""Provenance (fracid.store.provenance): collected, saved in result.json and loaded back, shown in the report,
recorded in the run store; an old result.json without it and an old store without its table still open."""

import dataclasses
import hashlib
import json
import sqlite3
from pathlib import Path

import numpy as np
import pytest

import fracid
from fracid.inverse.core.space import ParameterSpace
from fracid.inverse.core.method import MethodResult
from fracid.inverse.methods.knn_kalman import IdentificationResult
from fracid.store.provenance import collect, json_safe
from fracid.store.runs import RunStore

BAR = fracid.BarWithWeakZone(n_elements=10)


@dataclasses.dataclass(frozen=True)
class FakeConfig:
    """Stands for fracid.config.Config: frozen dataclasses, paths, tuples, None."""

    path: Path
    parameters: tuple = (("c", 2.0),)
    target: float | None = None
    upper: float = float("inf")


@pytest.fixture
def provenance(tmp_path):
    data = tmp_path / "curve.csv"
    data.write_text("cmod_mm,force_N\n0.0,0.0\n0.01,1.5\n")
    return data, collect(argv=["fracid", "identify", "my config.toml"], config=FakeConfig(tmp_path / "c.toml"),
                         data_files=[data], specimen=BAR, parameters=fracid.DamageParameters(),
                         bounds=ParameterSpace(("c", "beta"), [0.5, 100.0], [4.0, 500.0]))


def test_collect_records_the_run(provenance, tmp_path):
    data, p = provenance
    assert json.loads(json.dumps(p, allow_nan=False)) == p  # plain JSON, no NaN or infinity
    assert p["command"] == "fracid identify 'my config.toml'" and p["date"].endswith("+00:00")
    assert p["fracid"] == fracid.__version__ and p["machine"]["numpy"] == np.__version__
    assert p["machine"]["cpu_count"] >= 1
    entry, = p["data_files"]
    assert entry["sha256"] == hashlib.sha256(data.read_bytes()).hexdigest() and entry["bytes"] == data.stat().st_size
    assert p["config"] == {"path": str(tmp_path / "c.toml"), "parameters": [["c", 2.0]], "target": None,
                           "upper": "inf"}
    assert p["specimen"]["type"] == "BarWithWeakZone" and p["specimen"]["geometry"]["length"] == BAR.length
    mesh = p["specimen"]["mesh"]
    assert mesh["elements"] == 10 and mesh["nodes"] == 21 and mesh["unknowns"] == 21 + 11  # u + ebar at vertices
    assert p["parameters"]["c"] == fracid.DamageParameters().c
    assert p["bounds"] == {"c": [0.5, 4.0], "beta": [100.0, 500.0]}
    missing = collect(argv=[], data_files=[tmp_path / "gone.csv"])["data_files"][0]
    assert "error" in missing and "sha256" not in missing


def test_json_safe_converts_what_a_configuration_holds():
    assert json_safe({"a": (1, np.float64(2.5)), "b": np.arange(2), "c": float("nan")}) == \
        {"a": [1, 2.5], "b": [0, 1], "c": "nan"}


def result_with(provenance=None):
    extra = {"provenance": provenance} if provenance else {}
    return IdentificationResult(names=["c"], x=np.array([2.0]), C=np.array([[0.04]]), y_exp=np.array([1.0, 2.0, 1.5]),
                                y_fit=np.array([1.0, 2.0, 1.4]), std_exp=np.full(3, 0.1), blocks=[("global", 0, 3)],
                                units={"c": "mm^2"}, converged=True, status="converged", bounds=([0.5], [4.0]),
                                knn={"points": np.array([[1.0], [3.0]]), "f": np.array([1.0, np.inf]), "k": 1},
                                control=np.array([0.0, 0.01, 0.02]), **extra)


def test_provenance_is_saved_in_result_json_and_loaded_back(provenance, tmp_path):
    data, p = provenance
    path = result_with(p).save(tmp_path / "result.json")
    saved = json.loads(path.read_text())
    assert saved["provenance"]["data_files"][0]["sha256"] == hashlib.sha256(data.read_bytes()).hexdigest()
    loaded = IdentificationResult.load(path)
    assert loaded.provenance == p and type(loaded) is IdentificationResult
    np.testing.assert_allclose(loaded.x, [2.0])
    np.testing.assert_allclose(loaded.control, [0.0, 0.01, 0.02])
    assert loaded.blocks == [("global", 0, 3)] and loaded.knn["f"] == [1.0, None]  # inf saved as null
    assert loaded.summary() == result_with(p).summary()


def test_an_old_result_json_without_provenance_still_loads(tmp_path):
    old = result_with().to_dict()
    for key in ("provenance", "control", "control_names", "quantities", "diagnostics"):
        old.pop(key)
    (tmp_path / "result.json").write_text(json.dumps(old))
    loaded = MethodResult.load(tmp_path / "result.json")
    assert loaded.provenance == {} and loaded.control is None and loaded.warnings() == []
    assert "fit diagnostics" in loaded.summary()  # by point index


def test_the_report_has_a_collapsed_section_how_this_was_run(provenance, tmp_path):
    pytest.importorskip("matplotlib")
    from fracid.report import write_report

    data, p = provenance
    text = write_report(tmp_path / "report.html", result_with(p)).read_text(encoding="utf-8")
    section = text[text.index('<details class="provenance">'):text.index("</details>")]
    assert "<summary>How this was run</summary>" in section
    assert hashlib.sha256(data.read_bytes()).hexdigest() in section and "fracid identify" in section
    assert "BarWithWeakZone" in section and "Configuration (as read, defaults filled)" in section
    plain = write_report(tmp_path / "plain.html", result_with()).read_text(encoding="utf-8")
    assert "How this was run" not in plain


def test_the_run_store_records_the_provenance_and_old_stores_open(provenance, tmp_path):
    _, p = provenance
    with sqlite3.connect(tmp_path / "old.sqlite") as conn:  # a store as fracid wrote it before the meta table
        conn.execute("CREATE TABLE runs (key TEXT PRIMARY KEY, study TEXT, created REAL, status TEXT, seconds REAL, "
                     "record BLOB)")
    conn.close()
    with RunStore(tmp_path / "old.sqlite", readonly=True) as store:
        assert store.get_meta("provenance:identify") is None and len(store) == 0
    with RunStore(tmp_path / "old.sqlite") as store:
        assert store.get_meta("provenance:identify") is None
        store.put_meta("provenance:identify", p)
        store.put_meta("provenance:identify", {**p, "command": "fracid identify again"})
        assert len(store) == 0  # not a run
    with RunStore(tmp_path / "old.sqlite", readonly=True) as store:
        assert store.get_meta("provenance:identify") == {**p, "command": "fracid identify again"}
