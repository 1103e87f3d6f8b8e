"""Hostile but realistic inputs, each run through the real ``fracid`` command (``python -m fracid``) as a
subprocess in its own directory: the exit status of the contract (:mod:`fracid.runtime.exits`: 0 done, 1 a bug,
2 bad input, 3 the computation failed, 4 files and storage, 130/143 interrupted), a few distinctive
words of the message (paths of the case's directory removed first), and no traceback (except with
``--debug``).

Cost: most cases end while the configuration or the data are loaded (about 1.5 s each: the interpreter's
start and the imports). All the cases of :data:`CASES` run in one batch, set up by the first of them,
``FRACID_TEST_JOBS`` subprocesses at a time (default 2), the few that compute first; only the cases
pytest selected run. The cases that compute use a 40-element bar, a KNN population of 8, 2 Kalman
groups, 3 passes and ``--workers 1``. The subprocesses keep their bytecode in a cache under the temporary
directory (``PYTHONPYCACHEPREFIX``), so that fracid is not compiled again in every one of them.
``FRACID_TEST_TIMES=1`` (with ``pytest -s``) prints the wall time of every command.
"""

from __future__ import annotations

import contextlib
import os
import shutil
import signal
import sqlite3
import subprocess
import sys
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import pytest

import hostile_checks
import hostile_compare
import hostile_data
import hostile_dic
import hostile_estimate
import hostile_files
import hostile_fit
import hostile_machine_log
import hostile_mesh
import hostile_paths
import hostile_plausibility
import hostile_screening
import hostile_status
from fracid.runtime.locks import directory_lock
from hostile import (ENV, FRACID, IDENTIFY, IS_ROOT, JOBS, OUT, REACHES_OUTPUT, _cells, _clean, _config_bytes,
                     _corrupt_store, _estimate_near_truth, _out_dir, _out_is_file, _read_only_out, _scaled, _units_row,
                     _unloading, bar_config, case, check, csv_case, run_fracid, sim_case, synthetic_curve, write_csv)


pytestmark = pytest.mark.slow  # the fast loop (-m "not slow") leaves this module out

@pytest.fixture(scope="module")
def curve():
    """Control [mm] and force [N] of the 40-element bar with (c, beta) = TRUTH, the synthetic test."""
    return synthetic_curve()


CASES = {
    # ---- the configuration file itself
    "config-missing-file": case(2, ["configuration file not found"], args=("identify", "nope.toml")),
    "config-is-a-directory": case(2, ["is a directory"], args=("identify", ".")),
    "config-is-the-data-csv": case(2, ["not valid TOML"], args=("identify", "bar.csv")),
    "config-utf8-bom-from-notepad": case(2, [("specimen.colour", "BOM", "byte order mark")], files=_config_bytes(
        b"\xef\xbb\xbf" + b'[specimen]\ntype = "bar"\ncolour = "red"\n')),
    "unknown-top-key": case(2, ["colour", "unknown key"], config={"top": 'colour = "red"'}),
    # ---- keys and values
    "unknown-nested-key-typo": case(2, ["experiments[0].force_colums", "unknown key"],
                                    config={"experiment": 'force_colums = ["F_N"]'}),
    "string-for-number": case(2, ["model.parameters.c", "must be a number"], config={"c": '"2.0"'}),
    "negative-std": case(2, ["experiments[0].std", "> 0"], config={"std": "std = -0.02"}),
    "nan-parameter": case(2, ["model.parameters.beta", "nan"], config={"beta": "nan"}),
    "inf-target": sim_case(2, ["simulate.target", "inf"], simulate="target = inf"),
    "missing-control_unit": case(2, ["experiments[0].control_unit is missing"], config={"drop": ("control_unit",)}),
    "unknown-model-type": case(2, ["model.type", "'gradient'"], config={"model": "gradient"}),
    "unknown-specimen-type": case(2, ["specimen.type", "'beam'"], config=bar_config().replace('"bar"', '"beam"')),
    "unknown-control": case(2, ["specimen.control", "'cmod'"], config={"specimen": 'control = "cmod"'}),
    # ---- [identify]
    "bound-outside-valid-range": case(2, ["identify.bounds.beta", "valid range"],
                                      config={"bounds": "c = [0.5, 4.0]\nbeta = [-10.0, 500.0]"}),
    "lower-not-below-upper": case(2, ["identify.bounds.c", "below"],
                                  config={"bounds": "c = [4.0, 0.5]\nbeta = [100.0, 500.0]"}),
    "log-bound-zero": case(2, ["identify.bounds.log", "lower bound > 0"],
                           config={"bounds": 'c = [0.5, 4.0]\nbeta = [0.0, 500.0]\nlog = ["beta"]'}),
    "identify-unknown-parameter": case(2, ["identify.parameters", "'gamma'"], config={"parameters": '["c", "gamma"]'}),
    # ---- limits: refused when the configuration is loaded
    "knn-n-1e9": case(2, ["identify.knn.n", "limit", "GiB"], config={"n": "1_000_000_000"}),
    "bar-n_elements-1e8": case(2, ["specimen.n_elements", "memory", "200,000"], config={"n_elements": "100_000_000"}),
    "beam-h_fine-0.001": case(2, ["specimen.h_fine", "unknowns", "memory"], csv=None, args=("simulate", "cfg.toml"),
                              config='[specimen]\ntype = "notched-beam"\nh_fine = 0.001\n'),
    "groups-above-n_y": case(2, ["identify.kalman.groups", "n_y = 12"], config={"groups": "13"}),
    "k-above-n": case(2, ["identify.knn.k", "population size 8"], config={"k": "9"}),
    # ---- the data file
    "data-missing-csv": case(2, ["experiments[0].file", "file not found"], csv=None),
    "data-empty-csv": case(2, ["experiments[0].file", "empty"], csv=lambda d, c: (d / "bar.csv").write_text("")),
    "data-header-only": case(2, ["0 data rows"], csv=lambda d, c: (d / "bar.csv").write_text("u_mm,F_N\n"), args=IDENTIFY),
    "data-missing-column": csv_case(2, ["experiments[0].force_columns", "'F_N'", "'Force'"],
                                    rows=lambda c: [["u_mm", "Force"], *_cells(c)[1:]]),
    "data-units-row-below-header": csv_case(2, ["row 2", "'mm' is not a number"], rows=_units_row, args=IDENTIFY),
    "data-nan-cell": csv_case(2, ["missing value", "'NaN'"], lambda i, row: [row[0], "NaN"] if i == 30 else row,
                              args=IDENTIFY),
    "data-semicolon-without-delimiter": case(2, ["delimiter", '";"'],
                                             csv=lambda d, c: write_csv(d / "bar.csv", *c, sep=";", decimal=",")),
    "data-decimal-comma-without-decimal": case(2, ["decimal", 'decimal = ","'], config={"experiment": 'delimiter = ";"'},
                                               csv=lambda d, c: write_csv(d / "bar.csv", *c, sep=";", decimal=",")),
    "data-negated-forces": case(2, ["negative", "negate"], csv=lambda d, c: write_csv(d / "bar.csv", c[0], -c[1]),
                                args=IDENTIFY),
    "data-all-zero-forces": case(2, ["all forces are zero"], csv=lambda d, c: write_csv(d / "bar.csv", c[0], 0 * c[1]),
                                 args=IDENTIFY),
    "data-unloading-loop": csv_case(2, ["goes backwards", "backtrack_tolerance"], _unloading, args=IDENTIFY),
    "data-control_range-beyond-data": case(2, ["never extrapolated"], config={"control_range": "[0.004, 0.05]"},
                                           args=IDENTIFY),
    # ---- files that must be read: the data are built, then the output path (a file) ends the command
    "reads-tab-separated": case(4, ["taken is a file"], csv=lambda d, c: write_csv(d / "bar.csv", *c, sep="\t"),
                                config={"experiment": 'delimiter = "tab"'}, files=_out_is_file,
                                args=("identify", "cfg.toml", *REACHES_OUTPUT)),
    "reads-utf8-bom-header": case(4, ["taken is a file"], csv=lambda d, c: write_csv(d / "bar.csv", *c, bom=True),
                                  files=_out_is_file, args=("identify", "cfg.toml", *REACHES_OUTPUT)),
    # ---- output directory and run store
    "demo-out-is-an-existing-file": case(4, ["taken is a file", "--out"], files=_out_is_file,
                                         args=("demo", "--out", "taken", "--quiet")),
    "out-read-only": case(4, ["permission denied", "--out"], files=_read_only_out, args=IDENTIFY, needs_user=True),
    "store-corrupt": case(4, ["runs.sqlite", "move it away"], files=_corrupt_store, args=IDENTIFY),
    "store-corrupt-debug-shows-traceback": case(4, ["runs.sqlite"], files=_corrupt_store, args=(*IDENTIFY, "--debug"),
                                                traceback=True),
    "out-locked-by-another-fracid": case(4, ["another fracid process", f"pid {os.getpid()}"], files=_out_dir,
                                         args=IDENTIFY, lock="out"),
    # ---- command line
    "workers-zero": case(2, ["--workers = 0"], args=("identify", "cfg.toml", "--workers", "0")),
    "unknown-subcommand": case(2, ["invalid choice", "'identfy'"], args=("identfy", "cfg.toml")),
    "scheduler-not-an-address": case(2, ["--scheduler", "not-an-address"],
                                     args=("identify", "cfg.toml", "--scheduler", "not-an-address", "--quiet")),
    "scheduler-and-workers": case(2, ["--scheduler", "--workers"], args=(
        "identify", "cfg.toml", "--workers", "1", "--scheduler", "tcp://127.0.0.1:9", "--quiet")),
    "size-effect-negative-size": case(2, ["--sizes", "-100"], args=("size-effect", "cfg.toml", "--sizes", "-100",
                                                                     "--out", "out", "--quiet")),
    # ---- the computation fails
    "simulate-snap-back-end-displacement": sim_case(3, ["did not converge", "weak_zone_elongation"],
                                                    params="beta = 1000.0", specimen="length = 400.0"),
    "simulate-c-1e12": sim_case(2, ["model.parameters.c = 1e+12", "cannot form", "lower c below 253"], params="c = 1e12"),
    "simulate-cohesive-crack-on-bar": case(2, ["cohesive", "bar"], csv=None, args=("simulate", "cfg.toml"), config=(
        '[model]\ntype = "cohesive-crack"\n[specimen]\ntype = "bar"\nn_elements = 40\n')),
    "identify-every-knn-run-fails": case(3, ["0 of 8 forward runs", "no convergence", "--retry-failed"], args=IDENTIFY,
                                         config={"bounds": "c = [0.5, 1.0]\nbeta = [2000.0, 5000.0]"}, slow=True),
    # ---- cases that compute and succeed
    "semicolon-decimal-comma-identifies": case(
        0, csv=lambda d, c: write_csv(d / "bar.csv", *c, sep=";", decimal=","), args=IDENTIFY, slow=True,
        config={"experiment": 'delimiter = ";"\ndecimal = ","'}, verify=_estimate_near_truth),
    "relative_std-5-warns": case(0, ["fracid: warning", "if you meant 5 %", "0.05"], config={"std": "relative_std = 5"},
                                 args=("sensitivity", "cfg.toml", *OUT), slow=True),
    "units-forces-in-kN-declared-N": _scaled(1.0, 1e-3),
    "units-control-in-um-declared-mm": _scaled(1e3, 1.0),
    "units-control-in-m-declared-mm": _scaled(1e-3, 1.0),
}

#: the other cases, one module per class of defect (files and signals, data files, meshes, plausibility and API)
for _module in (hostile_files, hostile_data, hostile_mesh, hostile_checks, hostile_plausibility, hostile_fit,
                hostile_dic, hostile_paths, hostile_compare, hostile_estimate, hostile_status, hostile_screening,
                hostile_machine_log):
    assert not set(_module.CASES) & set(CASES), set(_module.CASES) & set(CASES)
    CASES.update(_module.CASES)

#: the cases whose output directory another test uses
_SOURCE_OF = {"test_truncated_run_store": "semicolon-decimal-comma-identifies",
              "test_undecodable_records_in_the_run_store": "semicolon-decimal-comma-identifies"}


def _selected_cases(session) -> list[str]:
    names = []
    for item in session.items:
        if getattr(item, "module", None) is None or item.module.__name__ != __name__:
            continue
        if item.originalname == "test_hostile_input":
            names.append(item.callspec.params["name"])
        elif item.originalname in _SOURCE_OF:
            names.append(_SOURCE_OF[item.originalname])
    names = [n for n in dict.fromkeys(names) if not (CASES[n].needs_user and IS_ROOT)]
    return sorted(names, key=lambda n: not CASES[n].slow)


@pytest.fixture(scope="module")
def batch(request, curve, tmp_path_factory):
    """Run every selected case, FRACID_TEST_JOBS at a time: name -> (completed process, or the exception
    of its preparation, and the case's directory)."""
    names = _selected_cases(request.session)
    directories = {name: tmp_path_factory.mktemp("case") for name in names}  # here: mktemp is not thread-safe

    def one(name):
        spec, d = CASES[name], directories[name]
        try:
            args = spec.prepare(d, curve)
            options = dict(stdin=spec.stdin, env=spec.env)
            if spec.lock is None:
                return run_fracid(args, d, **options), d
            with directory_lock(d / spec.lock):
                return run_fracid(args, d, **options), d
        except Exception as err:  # noqa: BLE001 -- raised by the case's test
            return err, d

    with ThreadPoolExecutor(JOBS) as pool:
        return dict(zip(names, pool.map(one, names)))


@pytest.mark.parametrize("name", [pytest.param(n, id=n, marks=pytest.mark.skipif(
    CASES[n].needs_user and IS_ROOT, reason="root ignores file permissions")) for n in CASES])
def test_hostile_input(name, batch):
    proc, d = batch[name]
    if isinstance(proc, BaseException):
        raise proc
    spec = CASES[name]
    if spec.verify is not None:
        spec.verify(proc, d)
    else:
        check(proc, d, spec.status, spec.words, traceback=spec.traceback)


def test_truncated_run_store(batch, tmp_path):
    """A real store (of the semicolon case) truncated to half its size, then the same command again."""
    _, source = batch["semicolon-decimal-comma-identifies"]
    work = tmp_path / "w"
    shutil.copytree(source, work)
    store = work / "out" / "runs.sqlite"
    with open(store, "r+b") as handle:
        handle.truncate(store.stat().st_size // 2)
    check(run_fracid(IDENTIFY, work), work, 4, ["runs.sqlite", "move it away"])


def _stored_runs(store: Path) -> int:
    """Runs in a store another process is writing (0 while it is not readable yet)."""
    try:
        with contextlib.closing(sqlite3.connect(f"file:{store}?mode=ro", uri=True, timeout=1)) as conn:
            return conn.execute("SELECT COUNT(*) FROM runs").fetchone()[0]
    except sqlite3.Error:
        return 0


INTERRUPTED = ["interrupted", "run the same command again"]


def _as_in_a_terminal():
    """In the child: SIGINT handled as in a terminal's foreground job. A test run started in the background by a
    shell without job control (``pytest ... &`` in a script) ignores SIGINT, its children inherit that, and
    Python then leaves SIGINT ignored: Ctrl-C could not be tested."""
    signal.signal(signal.SIGINT, signal.SIG_DFL)


@pytest.mark.parametrize("sig, status, words, workers, group, when, times", [
    pytest.param(signal.SIGINT, 130, INTERRUPTED, "1", False, "stored", 1, id="sigint"),
    pytest.param(signal.SIGTERM, 143, ["terminated (SIGTERM)", "run the same command again"], "1", False, "stored",
                 1, id="sigterm"),
    pytest.param(signal.SIGTERM, 143, ["terminated (SIGTERM)", "run the same command again"], "1", False, "stored",
                 2, id="sigterm-twice-as-gnu-timeout"),
    pytest.param(signal.SIGHUP, 129, ["hang-up", "run the same command again"], "1", False, "stored", 1,
                 id="sighup-terminal-closed"),
])
def test_signal_during_identify(sig, status, words, workers, group, when, times, curve, tmp_path):
    """Ctrl-C, SIGTERM or SIGHUP during the KNN stage (a population of 1000 runs, longer than the wait), once a
    few runs are stored, or (``when = "starting"``) just after the run store is opened, while the workers start.
    ``group``: the signal goes to the whole process group, workers included, as Ctrl-C in a terminal does;
    ``times``: sent that often, 20 ms apart (GNU timeout signals twice)."""
    write_csv(tmp_path / "bar.csv", *curve)
    # 1000 runs: the forward runs got 3x faster, and 200 of them could end before the signal on a busy machine
    (tmp_path / "cfg.toml").write_text(bar_config(n="1000"))
    proc = subprocess.Popen([*FRACID, "identify", "cfg.toml", "--out", "out", "--workers", workers, "--quiet"],
                            cwd=tmp_path, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=ENV,
                            start_new_session=group, preexec_fn=_as_in_a_terminal)
    try:
        store, start = tmp_path / "out" / "runs.sqlite", time.monotonic()
        while time.monotonic() - start < 60 and proc.poll() is None:
            if store.exists() and (when == "starting" or _stored_runs(store) >= 3):
                break
            time.sleep(0.05)
        time.sleep(0.3)
        assert proc.poll() is None, f"ended before the signal: {proc.returncode}\n{proc.communicate()}"
        sent = time.monotonic()
        for _ in range(times):
            if group:
                os.killpg(proc.pid, sig)
            else:
                proc.send_signal(sig)
            time.sleep(0.02)
        out, err = proc.communicate(timeout=15)
        elapsed = time.monotonic() - sent
    finally:
        if proc.poll() is None:
            if group:
                os.killpg(proc.pid, signal.SIGKILL)
            else:
                proc.kill()
            proc.communicate()
    check(subprocess.CompletedProcess(proc.args, proc.returncode, out, err), tmp_path, status, words)
    assert elapsed < 15


@pytest.mark.parametrize("sig, status", [(signal.SIGINT, 130), (signal.SIGTERM, 143)], ids=["sigint", "sigterm"])
@pytest.mark.parametrize("delay", [0.3, 0.6])
def test_double_signal_during_start_up(sig, status, delay, curve, tmp_path):
    """The signal twice, 10 ms apart, while the command imports and loads (the first raises, the second is
    ignored): the exit status of the signal, a message, no traceback, within 5 s. (Not earlier than 0.3 s:
    within the interpreter's own first ~20 ms, before fracid's first line, Python itself answers; a busy
    machine stretches that.)"""
    write_csv(tmp_path / "bar.csv", *curve)
    (tmp_path / "cfg.toml").write_text(bar_config(n="1000"))
    proc = subprocess.Popen([*FRACID, "identify", "cfg.toml", "--out", "out", "--workers", "1", "--quiet"],
                            cwd=tmp_path, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=ENV,
                            preexec_fn=_as_in_a_terminal)
    try:
        time.sleep(delay)
        proc.send_signal(sig)
        time.sleep(0.01)
        with contextlib.suppress(ProcessLookupError):
            proc.send_signal(sig)
        out, err = proc.communicate(timeout=5)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.communicate()
    check(subprocess.CompletedProcess(proc.args, proc.returncode, out, err), tmp_path, status,
          [("interrupted", "terminated", "nothing was computed")])


def _private_mounts() -> bool:
    """Whether this machine lets a process mount a tmpfs in a mount namespace of its own (unshare -Urm)."""
    if shutil.which("unshare") is None:
        return False
    probe = subprocess.run(["unshare", "-Urm", "sh", "-c", "mount -t tmpfs -o size=64k tmpfs /mnt"],
                           capture_output=True, timeout=20)
    return probe.returncode == 0


FULL_DISK = """\
set -u
mount -t tmpfs -o size=160k tmpfs disk
"$@" --quiet; echo "first exit $?" >&2
"$PYTHON" -c "import sqlite3; print('stored before', sqlite3.connect('file:disk/out/runs.sqlite?mode=ro', uri=True).execute('SELECT COUNT(*) FROM runs').fetchone()[0])"
mount -o remount,size=16m disk
"$@"; echo "second exit $?" >&2
"""


@pytest.mark.skipif(not _private_mounts(), reason="no private tmpfs mounts (unshare -Urm) on this machine")
def test_full_disk_while_storing(curve, tmp_path):
    """The output directory on a 160 KiB file system (a tmpfs in a private mount namespace), the KNN population
    of 64 runs larger than it: the command ends with exit 4, naming the full disk; the runs stored before are
    intact and, once the file system is grown (space freed), the same command reuses them all."""
    write_csv(tmp_path / "bar.csv", *curve)
    (tmp_path / "cfg.toml").write_text(bar_config(n="64"))
    (tmp_path / "disk").mkdir()
    (tmp_path / "full.sh").write_text(FULL_DISK)
    proc = subprocess.run(["unshare", "-Urm", "bash", "full.sh", *FRACID, "identify", "cfg.toml", "--out", "disk/out",
                           "--workers", "1"], cwd=tmp_path, capture_output=True, text=True, timeout=240,
                          env={**ENV, "PYTHON": sys.executable})
    err = _clean(proc.stderr, tmp_path)
    assert "first exit 4" in err and "second exit 0" in err, err
    first = err[:err.index("first exit")]
    assert "Traceback" not in err and "disk" in first and "is full" in first and "move it away" not in first, err
    stored = int(proc.stdout.split("stored before ")[1].split()[0])
    computed = int(proc.stdout.split("64 KNN (0 failed, ")[1].split()[0])
    assert 0 < stored < 64 and computed == 64 - stored, proc.stdout


def test_undecodable_records_in_the_run_store(batch, tmp_path):
    """A real store (of the semicolon case) whose records another program overwrote with bytes that are not
    JSON: exit 4, the store named as damaged, no traceback (not an internal error)."""
    _, source = batch["semicolon-decimal-comma-identifies"]
    work = tmp_path / "w"
    shutil.copytree(source, work)
    with contextlib.closing(sqlite3.connect(work / "out" / "runs.sqlite")) as conn, conn:
        conn.execute("UPDATE runs SET record = x'00ff7b'")
    check(run_fracid(IDENTIFY, work), work, 4, ["runs.sqlite", "cannot be decoded", "move it away"])


READ_ONLY = """\
set -u
mount -t tmpfs -o size=16m tmpfs disk
"$@" 2>/dev/null; echo "first exit $?" >&2
mount -o remount,ro disk
"$@"; echo "second exit $?" >&2
"""


@pytest.mark.skipif(not _private_mounts(), reason="no private tmpfs mounts (unshare -Urm) on this machine")
def test_read_only_file_system(curve, tmp_path):
    """An output directory whose file system became read-only (a full identification done there before): exit 4
    naming the read-only file system, not a permission to fix, not a store to move away."""
    write_csv(tmp_path / "bar.csv", *curve)
    (tmp_path / "cfg.toml").write_text(bar_config())
    (tmp_path / "disk").mkdir()
    (tmp_path / "ro.sh").write_text(READ_ONLY)
    proc = subprocess.run(["unshare", "-Urm", "bash", "ro.sh", *FRACID, *IDENTIFY[:2], "--out", "disk/out",
                           "--workers", "1", "--quiet"], cwd=tmp_path, capture_output=True, text=True, timeout=240,
                          env=ENV)
    err = _clean(proc.stderr, tmp_path)
    assert "first exit 0" in err and "second exit 4" in err, err
    assert "read-only" in err and "Traceback" not in err and "move it away" not in err, err
