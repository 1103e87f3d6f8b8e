"""The fracid command: each subcommand on a small configuration, and configuration errors."""

import json
import runpy
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import fracid
from fracid import cli

ROOT = Path(__file__).resolve().parents[1]
CONFIGS = Path(__file__).with_name("configs")

BAR_IDENTIFY = """
[model.parameters]
c = 1.0
beta = 300.0

[specimen]
type = "bar"
n_elements = 60

[[experiments]]
file = "bar.csv"
control_column = "u_mm"
control_unit = "mm"
force_unit = "N"
kind = "single"
force_columns = ["F_N"]
std = 0.02
n_points = 12
control_range = [0.004, 0.03]

[identify]
parameters = ["c", "beta"]
[identify.bounds]
c = [0.5, 4.0]
beta = [100.0, 500.0]
[identify.knn]
n = 16
k = 4
[identify.kalman]
groups = 3

[output]
directory = "results"
"""


@pytest.fixture()
def bar_study(tmp_path):
    """Synthetic measured curve of the bar with (c, beta) = (2, 250), and the identification config."""
    run = fracid.simulate(fracid.BarWithWeakZone(n_elements=60), fracid.DamageParameters(c=2.0, beta=250.0),
                          target=0.032, stop_force_fraction=None, checkpoints=np.linspace(0.001, 0.032, 40))
    np.savetxt(tmp_path / "bar.csv", np.column_stack([run.control, run.force]), delimiter=",", header="u_mm,F_N",
               comments="")
    (tmp_path / "study.toml").write_text(BAR_IDENTIFY)
    return tmp_path / "study.toml"


def test_simulate_writes_curve_plot_and_vtk(tmp_path):
    pytest.importorskip("meshio")
    assert cli.main(["simulate", str(CONFIGS / "bar_simulate.toml"), "--out", str(tmp_path), "--quiet"]) == 0
    curve = np.loadtxt(tmp_path / "curve.csv", delimiter=",", skiprows=1)
    header = (tmp_path / "curve.csv").read_text().splitlines()[0].split(",")
    force = curve[:, header.index("force_N")]
    assert force.max() > 1.5 and force[-1] < 0.1 * force.max()
    assert (tmp_path / "curve.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert {p.name for p in (tmp_path / "vtk").glob("*.vtu")} >= {"step_0010.vtu", "step_0020.vtu"}


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


@pytest.mark.parametrize("example", sorted((ROOT / "examples").glob("*.py")), ids=lambda p: p.name)
def test_example_runs(example, capsys):
    runpy.run_path(str(example), run_name="__main__")
    assert capsys.readouterr().out.strip()
