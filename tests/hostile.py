"""What the hostile-input cases are made of (tests/test_hostile_inputs.py and the hostile_*.py case
modules): data and configuration files as a user writes them, the ``fracid`` command as a subprocess, the
check of its exit status and message, and :class:`Case`."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

import numpy as np

import fracid

FRACID = [sys.executable, "-m", "fracid"]
JOBS = max(1, int(os.environ.get("FRACID_TEST_JOBS", "2")))
IS_ROOT = hasattr(os, "geteuid") and os.geteuid() == 0
_PYCACHE = Path(tempfile.gettempdir()) / f"fracid-test-pycache-{os.getuid() if hasattr(os, 'getuid') else 0}"
#: one BLAS thread per forward run (the runs are tiny), and a shared bytecode cache outside the source tree
ENV = {**{k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"},
       "OMP_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1", "MKL_NUM_THREADS": "1",
       "PYTHONPYCACHEPREFIX": os.environ.get("PYTHONPYCACHEPREFIX", str(_PYCACHE))}
TRUTH = (2.0, 250.0)  # (c, beta) of the synthetic measured curve


# ------------------------------------------------------------------------------------ files


def synthetic_curve():
    """Control [mm] and force [N] of the 40-element bar with (c, beta) = TRUTH, the synthetic test."""
    run = fracid.simulate(fracid.BarWithWeakZone(n_elements=40), fracid.DamageParameters(c=TRUTH[0], beta=TRUTH[1]),
                          target=0.032, stop_force_fraction=None, checkpoints=np.linspace(0.001, 0.032, 40))
    return np.asarray(run.control, dtype=float), np.asarray(run.force, dtype=float)


def _number(value: float, decimal: str) -> str:
    text = f"{value:.9g}"
    return text.replace(".", decimal) if decimal != "." else text


def write_csv(path: Path, control, force, *, sep=",", decimal=".", bom=False) -> Path:
    """The two-column data file "u_mm", "F_N" as a lab's software may write it (separator, decimal mark, BOM)."""
    lines = [sep.join(("u_mm", "F_N"))]
    lines += [sep.join((_number(c, decimal), _number(f, decimal))) for c, f in zip(control, force)]
    path.write_text(("\ufeff" if bom else "") + "\n".join(lines) + "\n", encoding="utf-8")
    return path


def write_rows(path: Path, rows) -> Path:
    """A comma-separated data file from rows of cells (strings), the first row the header."""
    path.write_text("\n".join(",".join(str(cell) for cell in row) for row in rows) + "\n", encoding="utf-8")
    return path


def _cells(curve, edit=None):
    """Header and rows of the standard file as strings; ``edit(i, [c, f])`` may change row i."""
    rows = [["u_mm", "F_N"]]
    for i, (c, f) in enumerate(zip(*curve)):
        row = [f"{c:.9g}", f"{f:.9g}"]
        rows.append(edit(i, row) if edit else row)
    return rows


BAR = """\
{top}
[model]
type = "{model}"
[model.parameters]
c = {c}
beta = {beta}
{params}

[specimen]
type = "bar"
n_elements = {n_elements}
{specimen}

[[experiments]]
file = "{file}"
control_column = "u_mm"
control_unit = "{control_unit}"
force_unit = "{force_unit}"
kind = "single"
force_columns = ["F_N"]
{std}
n_points = {n_points}
control_range = {control_range}
{experiment}

[identify]
parameters = {parameters}
{identify}
[identify.bounds]
{bounds}
[identify.knn]
n = {n}
k = {k}
{knn}
[identify.kalman]
groups = {groups}
max_iterations = 3
{kalman}

[output]
directory = "results"
{tail}
"""

BAR_DEFAULTS = dict(top="", model="gradient-damage", c="1.0", beta="300.0", params="", n_elements="40", specimen="",
                    file="bar.csv", control_unit="mm", force_unit="N", std="std = 0.02", n_points="12",
                    control_range="[0.004, 0.03]", experiment="", parameters='["c", "beta"]', identify="",
                    bounds="c = [0.5, 4.0]\nbeta = [100.0, 500.0]", n="8", k="3", knn="", groups="2", kalman="",
                    tail="")


def bar_config(*, drop=(), **changes) -> str:
    """The tiny bar identification config, with template fields changed and lines whose key is in ``drop`` removed."""
    unknown = set(changes) - set(BAR_DEFAULTS)
    assert not unknown, unknown
    text = BAR.format(**{**BAR_DEFAULTS, **changes})
    return "\n".join(line for line in text.splitlines() if line.split("=")[0].strip() not in drop) + "\n"


SIMULATE = """\
[model.parameters]
{params}

[specimen]
type = "bar"
n_elements = 40
{specimen}

[simulate]
{simulate}
"""


def simulate_config(params="", specimen="", simulate="") -> str:
    return SIMULATE.format(params=params, specimen=specimen, simulate=simulate)


# ------------------------------------------------------------------------------------ running


def run_fracid(args, cwd, timeout=240, *, stdin=None, env=None) -> subprocess.CompletedProcess:
    """``python -m fracid ARGS`` in ``cwd`` (``stdin``: text on its standard input; ``env``: variables
    added to :data:`ENV`)."""
    start = time.perf_counter()
    proc = subprocess.run([*FRACID, *map(str, args)], cwd=cwd, capture_output=True, text=True, timeout=timeout,
                          env={**ENV, **(env or {})}, input=stdin, stdin=None if stdin is not None else subprocess.DEVNULL)
    proc.seconds = time.perf_counter() - start
    if os.environ.get("FRACID_TEST_TIMES"):
        print(f"TIME {proc.seconds:6.2f} s  {' '.join(map(str, args))}  ({cwd})", file=sys.__stderr__, flush=True)
    return proc


def _clean(text: str, directory: Path) -> str:
    """Output with the case's directory written <dir>, so that words are never found in a path."""
    for form in {str(directory.resolve()), str(directory)}:
        text = text.replace(form, "<dir>")
    return text


def check(proc, directory: Path, status: int, words=(), *, traceback=False) -> str:
    """Assert the exit status, the words of stderr (a tuple: any of them) and the absence (presence with
    --debug) of a traceback; returns the cleaned stderr."""
    out, err = _clean(proc.stdout, directory), _clean(proc.stderr, directory)
    shown = f"exit status {proc.returncode}\n--- stdout:\n{out[-2500:]}\n--- stderr:\n{err[-4000:]}"
    assert proc.returncode == status, shown
    assert "Traceback" not in out, shown
    assert ("Traceback" in err) == traceback, shown
    for word in words:
        alternatives = word if isinstance(word, tuple) else (word,)
        assert any(w in err for w in alternatives), f"none of {alternatives} in stderr\n{shown}"
    return err


# ------------------------------------------------------------------------------------ cases


@dataclass(frozen=True)
class Case:
    """``prepare(directory, curve)`` writes the files and returns the arguments after ``fracid``;
    ``verify(proc, directory)``, when given, replaces the check of status and words."""

    prepare: Callable
    status: int | None
    words: tuple = ()
    lock: str | None = None  # hold the lock of this directory (relative) while the command runs
    traceback: bool = False  # --debug: a traceback is expected
    needs_user: bool = False  # file permissions do not bind root
    slow: bool = False  # computes for a few seconds: started first
    verify: Callable | None = None
    stdin: str | None = None  # the command's standard input
    env: dict | None = None  # environment variables for the command


def _standard_csv(d, curve):
    write_csv(d / "bar.csv", *curve)


def case(status, words=(), *, config=None, csv=_standard_csv, args=("identify", "cfg.toml", "--quiet"), files=None,
         **options) -> Case:
    """A case on the tiny bar config (``config``: a text, or the template's changes as a dict) and a data file
    (``csv(directory, curve)``); ``files(directory)`` adds or overwrites files."""
    def prepare(d, curve):
        if csv is not None:
            csv(d, curve)
        (d / "cfg.toml").write_text(config if isinstance(config, str) else bar_config(**(config or {})))
        if files is not None:
            files(d)
        return list(args)

    return Case(prepare, status, tuple(words), **options)


def csv_case(status, words, edit=None, *, rows=None, **options) -> Case:
    """A case whose data file is the standard one with rows edited (``edit(i, [control, force])``), or ``rows``."""
    def csv(d, curve):
        write_rows(d / "bar.csv", rows(curve) if rows else _cells(curve, edit))

    return case(status, words, csv=csv, **options)


def sim_case(status, words, **sections) -> Case:
    """``fracid simulate`` of the 40-element bar with extra lines in [model.parameters], [specimen], [simulate]."""
    return case(status, words, config=simulate_config(**sections), csv=None, args=("simulate", "cfg.toml", "--quiet"))


def _config_bytes(data: bytes):
    def files(d):
        (d / "cfg.toml").write_bytes(data)
    return files


def _unloading(i, row):
    """An unloading-reloading loop on the softening branch: the control goes back by 40 % of its range."""
    return [f"{float(row[0]) - 0.013:.9g}", row[1]] if 60 <= i < 64 else row


def _units_row(curve):
    rows = _cells(curve)
    return [rows[0], ["mm", "N"], *rows[1:]]


def _out_is_file(d):
    (d / "taken").write_text("a file where the output directory should be\n")


def fracid_wrote(directory: Path, *names) -> None:
    """Record ``names`` in ``directory``'s manifest as written by fracid (as an earlier run would have)."""
    (directory / ".fracid-written").write_text(json.dumps(list(names)))


def _corrupt_store(d):
    (d / "out").mkdir()
    (d / "out" / "runs.sqlite").write_bytes(b"\x00\x17garbage, not an SQLite database\xff" * 200)
    fracid_wrote(d / "out", "runs.sqlite")


def _read_only_out(d):
    (d / "out").mkdir()
    (d / "out").chmod(0o555)


def _out_dir(d):
    (d / "out").mkdir()


def _estimate_near_truth(proc, d):
    check(proc, d, 0)
    result = json.loads((d / "out" / "result.json").read_text())
    x, std = np.array(result["x"]), np.array(result["std"])
    assert np.all(np.abs(x - TRUTH) <= np.maximum(3 * std, 0.1 * np.array(TRUTH))), (x, std)


def _scaled(control_factor, force_factor):
    """The synthetic mm / N data scaled as if recorded in other units, still declared mm and N."""
    def csv(d, curve):
        write_csv(d / "bar.csv", curve[0] * control_factor, curve[1] * force_factor)
    return case(None, csv=csv, args=IDENTIFY, slow=True, verify=_unit_contract)


def _unit_contract(proc, d):
    """Exit 0 with a "fit is poor" warning and an estimate inside the bounds, or exit 2 naming the likely
    unit problem; never a traceback, never an internal error."""
    err = _clean(proc.stderr, d)
    assert proc.returncode in (0, 2), f"exit status {proc.returncode}\n{err}"
    check(proc, d, proc.returncode)
    if proc.returncode == 0:
        assert "fit is poor" in err, err
        x = np.array(json.loads((d / "out" / "result.json").read_text())["x"])
        assert np.all((x >= [0.5, 100.0]) & (x <= [4.0, 500.0])), x
    else:
        assert "unit" in err.lower(), f"exit 2 without naming the units (control_unit, force_unit):\n{err}"


OUT = ("--out", "out", "--workers", "1", "--quiet")
IDENTIFY = ("identify", "cfg.toml", *OUT)
REACHES_OUTPUT = ("--out", "taken", "--workers", "1", "--quiet")  # the data are built, then the output path fails

