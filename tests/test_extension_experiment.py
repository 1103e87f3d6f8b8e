"""A new experiment kind, written in this file only (no package file edited): ``kind = "scaled-force"``, a force
curve recorded in the machine's own unit (a load-cell reading in mV, say) with the scale to N given, and a relative
std. It declares its keys, reads and checks its own table with the checker the configuration passes in, builds its
data and its observation; registered by one line (``EXPERIMENTS[kind.name] = kind``), it is read from a
configuration, passes ``fracid check``, is identified by ``fracid identify`` and is shown in report.html."""

from __future__ import annotations

import json
import re
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np
import pytest
from hostile import TRUTH, bar_config, synthetic_curve

from fracid import cli
from fracid.config import build_data, build_operator, load_config
from fracid.data.curves import read_curve_csv
from fracid.data.experimental import with_std
from fracid.inverse.core.observations import Observation
from fracid.inverse.experiments.registry import EXPERIMENTS
from fracid.report.block_view import BlockView
from fracid.report.views import VIEWS, View
from fracid.settings.checks import SettingError

#: N per unit of the recorded force column
SCALE = 250.0


@dataclass(frozen=True)
class ScaledForceConfig:
    """One validated block of the kind; the members the configuration asks of every block, then its own."""

    index: int
    file: Path
    n_points: int
    scale: float
    relative_std: float
    control_range: tuple | None
    name: str = "scaled"
    role: str = "calibration"
    weight: float = 1.0
    kind: str = "scaled-force"
    specimen: tuple = ()
    quantity: str = "force"
    measures_force = True


@dataclass(frozen=True)
class ScaledForce:
    """The kind: columns "u_mm" (control [mm]) and "reading" (force / ``scale``)."""

    name: str = "scaled-force"
    keys: tuple = ("kind", "file", "scale", "relative_std", "n_points", "control_range", "name", "role", "weight")
    column_keys: tuple = ()
    source: str | None = None
    view: str | None = None  # a curve: the report's fit figure and table draw it

    def read(self, ck, index, raw, context):
        prefix = f"experiments[{index}]"
        ck.table(prefix, raw, self.keys)
        for key in ("file", "scale", "n_points"):
            if key not in raw:
                ck.missing(f"{prefix}.{key}", "required by kind 'scaled-force'")
        file = ck.file(f"{prefix}.file", raw["file"], context.base)
        scale = ck.number(f"{prefix}.scale", raw["scale"], "must be a number > 0 [N per unit]", lambda v: v > 0)
        std = ck.number(f"{prefix}.relative_std", raw.get("relative_std", 0.01), "must be a number > 0",
                        lambda v: v > 0)
        n_points = ck.integer(f"{prefix}.n_points", raw["n_points"], "must be an integer >= 3", lambda v: v >= 3)
        span = ck.pair(f"{prefix}.control_range", raw["control_range"], "must be [start, stop] [mm]") \
            if "control_range" in raw else None
        return ScaledForceConfig(index, file, n_points, scale, std, span,
                                 name=ck.string(f"{prefix}.name", raw.get("name", "scaled")),
                                 role=ck.choice(f"{prefix}.role", raw.get("role", "calibration"),
                                                ("calibration", "prediction"))), None

    def data(self, exp, context):
        (curve,) = read_curve_csv(exp.file, control_column="u_mm", force_columns=["reading"],
                                  force_unit_scale=exp.scale)
        return with_std(curve, exp.relative_std, exp.n_points, exp.control_range, name=exp.name, relative=True)

    def observation(self, exp, context, name, control):
        try:
            return Observation(context.specimen, control, control=context.control, name=name)
        except ValueError as err:
            raise SettingError("control_range", exp.control_range, str(err)) from None


KIND = ScaledForce()


@pytest.fixture
def registered(monkeypatch):
    """The kind registered for one test (the registry as before afterwards)."""
    monkeypatch.setitem(EXPERIMENTS, KIND.name, KIND)
    return KIND


def _configured(tmp_path: Path, block: str) -> Path:
    control, force = synthetic_curve()
    rows = ["u_mm,reading"] + [f"{c:.9g},{f / SCALE:.9g}" for c, f in zip(control, force)]
    (tmp_path / "machine.csv").write_text("\n".join(rows) + "\n", encoding="utf-8")
    text = bar_config()
    start, stop = text.index("[[experiments]]"), text.index("[identify]")
    path = tmp_path / "cfg.toml"
    path.write_text(text[:start] + f"[[experiments]]\n{block}\n\n" + text[stop:], encoding="utf-8")
    return path


BLOCK = ('kind = "scaled-force"\nfile = "machine.csv"\nscale = 250.0\nrelative_std = 0.01\nn_points = 12\n'
         'control_range = [0.004, 0.03]\nname = "machine"')


def test_the_new_kind_is_read_and_builds_its_data_and_observation(tmp_path, registered):
    cfg = load_config(_configured(tmp_path, BLOCK))
    (exp,) = cfg.experiments
    assert (exp.kind, exp.scale, exp.n_points, exp.name) == ("scaled-force", 250.0, 12, "machine")
    data = build_data(cfg)
    control, force = synthetic_curve()
    assert [b[0] for b in data.blocks] == ["machine"] and data.n_y == cfg.n_y == 12
    np.testing.assert_allclose(data.y, np.interp(data.control, control, force), rtol=1e-6)  # scaled back to N
    (observation,) = build_operator(cfg, data).observations
    assert isinstance(observation, Observation) and observation.name == "machine"


def test_the_kinds_own_checks_name_the_key_and_value(tmp_path, registered, capsys):
    path = _configured(tmp_path, BLOCK.replace("scale = 250.0", "scale = -2.0"))
    assert cli.main(["check", str(path)]) == 2
    err = capsys.readouterr().err
    assert "experiments[0].scale = -2.0: must be a number > 0 [N per unit]" in err and "Traceback" not in err


def test_without_the_registration_the_kind_is_unknown(tmp_path, capsys):
    assert "scaled-force" not in EXPERIMENTS  # the fixture's registration is gone after its test
    assert cli.main(["check", str(_configured(tmp_path, BLOCK.replace("scale = 250.0\n", "")
                                              .replace("relative_std = 0.01\n", "")))]) == 2
    assert "experiments[0].kind = 'scaled-force': must be one of 'repeats'" in capsys.readouterr().err


@pytest.mark.slow
def test_fracid_check_and_identify_take_the_new_kind_and_the_report_shows_it(tmp_path, registered, capsys):
    path = _configured(tmp_path, BLOCK)
    assert cli.main(["check", str(path)]) == 0
    out = tmp_path / "id"
    assert cli.main(["identify", str(path), "--out", str(out), "--workers", "1", "--quiet"]) == 0
    result = json.loads((out / "result.json").read_text())
    assert result["blocks"][0][0] == "machine" and result["quantities"] == ["force"]
    assert np.all(np.abs(np.array(result["x"]) - TRUTH) <= 3 * np.array(result["std"]))
    report = (out / "report.html").read_text(encoding="utf-8")
    fit = report[report.index("<h2>Fit</h2>"):]
    assert re.search(r'<td class="text">machine</td><td class="text">N</td><td>12</td>', fit)  # its row, in N
    diagnostics = fit[fit.index("<h3>Fit diagnostics</h3>"):]
    assert '<td class="text">machine</td>' in diagnostics  # a force: its slope and peak diagnosed
    assert (out / "figures" / "fit.png").is_file()


def readings_view(name, coordinates, measured, computed, std, control_label):
    """A view of its own: a table of the block's values instead of a curve panel."""
    rows = [[f"{c:.4g}", f"{m:.4g}", f"{f:.4g}"] for c, m, f in zip(coordinates["control"], measured, computed)]
    return BlockView(name, f"Machine readings {name}", f"{len(rows)} readings, {control_label}",
                     ["control [mm]", "measured [N]", "computed [N]"], rows)


@pytest.mark.slow
def test_a_kind_naming_a_view_of_its_own_gets_its_section_in_the_report(tmp_path, monkeypatch):
    monkeypatch.setitem(EXPERIMENTS, KIND.name, replace(KIND, view="readings"))  # the kind names its view
    monkeypatch.setitem(VIEWS, "readings", View(readings_view))  # the report's view of that name
    out = tmp_path / "id"
    assert cli.main(["identify", str(_configured(tmp_path, BLOCK)), "--out", str(out), "--workers", "1",
                     "--quiet"]) == 0
    report = (out / "report.html").read_text(encoding="utf-8")
    assert "<h2>Machine readings machine</h2>" in report and "<th>computed [N]</th>" in report
    assert report.count("<tr><td>") >= 12  # a row per reading
