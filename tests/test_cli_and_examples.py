import runpy
import subprocess
import sys
from pathlib import Path

import pytest

from fracid.cli import main

ROOT = Path(__file__).resolve().parents[1]


def test_demo_prints_the_curve(capsys):
    assert main(["demo", "--elements", "60"]) == 0
    out = capsys.readouterr().out
    rows = [line.split() for line in out.splitlines() if line.strip() and line.split()[0].isdigit()]
    forces = [float(r[2]) for r in rows]
    assert len(rows) > 10 and forces[0] == 0.0
    assert max(forces) > 1.5 and forces[-1] < 0.1 * max(forces)  # peak and softening to 10 %
    assert "peak force" in out


def test_demo_rejects_bad_arguments(capsys):
    with pytest.raises(SystemExit) as info:
        main(["demo", "--elements", "1"])
    assert info.value.code == 2
    assert "--elements" in capsys.readouterr().err


def test_module_entry_point_runs():
    proc = subprocess.run([sys.executable, "-m", "fracid", "demo", "--elements", "40"], capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr
    assert "peak force" in proc.stdout


@pytest.mark.parametrize("example", sorted((ROOT / "examples").glob("*.py")), ids=lambda p: p.name)
def test_example_runs(example, capsys):
    runpy.run_path(str(example), run_name="__main__")
    assert capsys.readouterr().out.strip()
