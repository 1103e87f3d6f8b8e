"""The fracid command: each subcommand on a small configuration, and configuration errors."""

import json
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import fracid
from _bar_study import write_bar_study
from fracid import cli

ROOT = Path(__file__).resolve().parents[1]
CONFIGS = Path(__file__).with_name("configs")


@pytest.fixture()
def bar_study(tmp_path):
    """Synthetic measured curve of the bar with (c, beta) = (2, 250), and the identification config."""
    return write_bar_study(tmp_path)


def test_simulate_writes_curve_plot_and_vtk(tmp_path):
    assert cli.main(["simulate", str(CONFIGS / "bar_simulate.toml"), "--out", str(tmp_path), "--quiet"]) == 0
    curve = np.loadtxt(tmp_path / "curve.csv", delimiter=",", skiprows=1)
    header = (tmp_path / "curve.csv").read_text().splitlines()[0].split(",")
    force = curve[:, header.index("force_N")]
    assert force.max() > 1.5 and force[-1] < 0.1 * force.max()
    assert (tmp_path / "curve.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert {p.name for p in (tmp_path / "vtk").glob("*.vtu")} >= {"step_0010.vtu", "step_0020.vtu"}


@pytest.mark.parametrize("vtk_steps, skipped", [("[]", False), ("[10]", True)])
def test_vtk_skipped_is_said_only_when_vtk_was_asked_for(tmp_path, capsys, monkeypatch, vtk_steps, skipped):
    import fracid.report.vtk

    def no_meshio(*args, **kwargs):
        raise ImportError("writing VTK files needs meshio")

    monkeypatch.setattr(fracid.report.vtk, "write_result_vtk", no_meshio)
    text = (CONFIGS / "bar_simulate.toml").read_text()
    text = re.sub(r"^vtk_steps = .*$", f"vtk_steps = {vtk_steps}", text, flags=re.M)
    assert f"vtk_steps = {vtk_steps}" in text
    (tmp_path / "cfg.toml").write_text(text)
    assert cli.main(["simulate", str(tmp_path / "cfg.toml"), "--out", str(tmp_path / "out")]) == 0
    out, err = capsys.readouterr()
    assert ("VTK output skipped" in err) is skipped and "VTK" not in out
    assert "wrote in" in out and "curve.csv, curve.png" in out


@pytest.mark.parametrize("count, text", [(1, "1 run"), (2, "2 runs"), (0, "0 runs")])
def test_plural(count, text):
    from fracid.inverse.core.plans import plural

    assert plural(count, "run") == text


def test_identify_writes_result_fit_figures_and_report(bar_study, tmp_path):
    out = tmp_path / "out"
    assert cli.main(["identify", str(bar_study), "--out", str(out), "--workers", "1", "--quiet"]) == 0
    result = json.loads((out / "result.json").read_text())
    assert np.all(np.abs(np.array(result["x"]) - [2.0, 250.0]) <= 2 * np.array(result["std"]))
    fit = np.genfromtxt(out / "fit.csv", delimiter=",", skip_header=1, usecols=(0, 1, 2, 3))
    assert fit.shape == (12, 4)
    html = (out / "report.html").read_text()
    assert html.count("data:image/png;base64,") >= 4
    assert {p.name for p in (out / "figures").glob("*.png")} >= {"fit.png", "kalman.png", "correlation.png"}
    assert (out / "runs.sqlite").exists()


def test_demo_runs_its_bundled_config(bar_study, tmp_path, monkeypatch):
    """The demo path end to end, on the small bar study instead of the beam (minutes) for speed."""
    monkeypatch.setattr(cli, "demo_config_path", lambda: bar_study)
    assert cli.main(["demo", "--out", str(tmp_path / "demo"), "--workers", "1", "--quiet"]) == 0
    assert (tmp_path / "demo" / "report.html").exists()


def test_bundled_demo_config_is_valid():
    from fracid.config import build_data, build_operator, build_space, load_config

    cfg = load_config(cli.demo_config_path())
    data = build_data(cfg)
    assert build_operator(cfg, data).n_outputs == data.y.size
    assert build_space(cfg).names == ("kappa_i", "beta", "c")


@pytest.mark.parametrize(
    "text, words",
    [
        ("[specimen]\ntype = 'beam'\n", ["specimen.type", "'beam'"]),
        ("[model.parameters]\nc = -2.0\n[specimen]\ntype = 'bar'\n", ["model.parameters.c", "-2"]),
        ("[specimen]\ntype = 'bar'\ncolour = 'red'\n", ["specimen.colour", "unknown key"]),
    ],
)
def test_bad_config_exits_2_with_one_paragraph_and_no_traceback(tmp_path, text, words):
    path = tmp_path / "bad.toml"
    path.write_text(text)
    proc = subprocess.run([sys.executable, "-m", "fracid", "simulate", str(path), "--quiet"], capture_output=True, text=True)
    assert proc.returncode == 2
    assert "Traceback" not in proc.stderr and len(proc.stderr.strip().splitlines()) == 1
    for word in words:
        assert word in proc.stderr


def test_bad_workers_option(capsys):
    assert cli.main(["simulate", str(CONFIGS / "bar_simulate.toml"), "--workers", "0"]) == 2
    assert "--workers" in capsys.readouterr().err


BAR_SERIES = """
[model.parameters]
c = 1.0
beta = 300.0

[specimen]
type = "bar"
n_elements = 60
{experiments}
[identify]
parameters = ["c", "beta"]
[identify.bounds]
c = [0.5, 4.0]
beta = [100.0, 500.0]
[identify.knn]
n = 16
k = 4
[identify.kalman]
groups = 2

[study]
starts = 2
replicates = 2
"""

EXPERIMENT = """
[[experiments]]
file = "bar{L}.csv"
control_column = "u_mm"
control_unit = "mm"
force_unit = "N"
kind = "single"
force_columns = ["F_N"]
std = 0.02
n_points = 10
control_range = [{start}, {stop}]
name = "L{L}"
specimen = {{ length = {L}.0 }}
role = "{role}"
"""


@pytest.fixture()
def bar_series(tmp_path):
    """Bars of three lengths with (c, beta) = (2, 250): two for calibration, one held out."""
    blocks = []
    for L, role in ((60, "calibration"), (100, "calibration"), (160, "prediction")):
        bar = fracid.BarWithWeakZone(length=float(L), n_elements=60)
        stop = 0.03 * L / 100 + 0.01
        run = fracid.simulate(bar, fracid.DamageParameters(c=2.0, beta=250.0), target=stop, stop_force_fraction=None,
                              checkpoints=np.linspace(0.001, stop, 40))
        np.savetxt(tmp_path / f"bar{L}.csv", np.column_stack([run.control, run.force]), delimiter=",",
                   header="u_mm,F_N", comments="")
        blocks.append(EXPERIMENT.format(L=L, start=0.002, stop=round(stop, 4), role=role))
    (tmp_path / "series.toml").write_text(BAR_SERIES.format(experiments="".join(blocks)))
    return tmp_path / "series.toml"


@pytest.mark.slow
def test_study_writes_verdict_figures_predictions_and_size_effect(bar_series, tmp_path):
    out = tmp_path / "out"
    assert cli.main(["study", str(bar_series), "--out", str(out), "--workers", "2", "--quiet"]) == 0
    study = json.loads((out / "study.json").read_text())
    verdicts = {v["name"]: v for v in study["verdict"]["parameters"]}
    assert set(verdicts) == {"c", "beta"} and all(v["status"] in ("identified", "correlated") for v in verdicts.values())
    assert len(study["multi_start"]["ends"]) == 2 and len(study["stability"]["estimates"]) == 2
    [prediction] = study["predictions"]
    assert prediction["name"] == "L160" and prediction["relative_rms"] < 0.02  # noise-free data, a model that holds
    assert {p.name for p in (out / "figures").glob("*.png")} >= {"sensitivity.png", "valley.png", "stability.png",
                                                                 "predictions.png", "size_effect.png"}
    sizes = np.loadtxt(out / "size_effect.csv", delimiter=",", skiprows=1)
    np.testing.assert_allclose(sizes[:, 0], [60, 100, 160])
    html = (out / "report.html").read_text()
    assert "Verdict" in html and "Multi-start check" in html
    assert (out / "verdict.txt").read_text().startswith("Verdict:")


def test_sensitivity_and_size_effect_commands(bar_series, tmp_path):
    out = tmp_path / "s"
    assert cli.main(["sensitivity", str(bar_series), "--out", str(out), "--workers", "1", "--quiet"]) == 0
    table = np.loadtxt(out / "sensitivity.csv", delimiter=",", skiprows=1)
    assert table.shape == (20, 2 + 2 * 2) and np.all(np.diff(table[:, -1]) >= -1e-9)  # information only grows
    assert cli.main(["size-effect", str(bar_series), "--out", str(out), "--sizes", "240", "--quiet"]) == 0
    sizes = np.loadtxt(out / "size_effect.csv", delimiter=",", skiprows=1)
    np.testing.assert_allclose(sizes[:, 0], [60, 100, 160, 240])
    assert (out / "size_effect.png").exists()


@pytest.mark.slow
def test_uniqueness_command_runs_only_its_stages(bar_series, tmp_path):
    out = tmp_path / "u"
    assert cli.main(["uniqueness", str(bar_series), "--out", str(out), "--workers", "1", "--quiet"]) == 0
    study = json.loads((out / "study.json").read_text())
    assert "multi_start" in study and "stability" not in study and study["predictions"] == []
