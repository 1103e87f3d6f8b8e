"""Hostile-input cases: outputs that would replace an input or a file fracid did not write, the
configuration path (a FIFO, a device, standard input, a NUL byte, a link loop, deep nesting, its size),
the run store's SQLite failures by cause, CSV tables with awkward names, ``~`` in --out. Run by
tests/test_hostile_inputs.py."""

from __future__ import annotations

import csv
import os
import sqlite3

from hostile import IDENTIFY, bar_config, case, check, fracid_wrote, simulate_config, write_csv

MEASURED = "u_mm,F_N\n0,0\n0.01,812.5\n"  # a user's measured curve, which nothing may replace


def _unchanged(name, status, words):
    """Check status and words, and that the file ``name`` is byte for byte its copy ``name``.orig."""
    def verify(proc, d):
        check(proc, d, status, words)
        assert (d / name).read_bytes() == (d / f"{name}.orig").read_bytes(), f"{name} was changed"
    return verify


def _keep_copy(path):
    path.with_name(path.name + ".orig").write_bytes(path.read_bytes())


def _measured_curve_beside(d):
    (d / "curve.csv").write_text(MEASURED)
    _keep_copy(d / "curve.csv")


def _data_in_out(d, curve):
    """An earlier identification's directory ``out`` (its manifest lists fit.csv), whose fit.csv the user
    now gives as the data file."""
    (d / "out").mkdir()
    fracid_wrote(d / "out", "fit.csv", "result.json")
    write_csv(d / "out" / "fit.csv", *curve)
    _keep_copy(d / "out" / "fit.csv")


def _link_to_data(d):
    """out/fit.csv, listed as fracid's, is a symbolic link to the data file."""
    (d / "out").mkdir()
    fracid_wrote(d / "out", "fit.csv")
    (d / "out" / "fit.csv").symlink_to(d / "bar.csv")


def _foreign_database(listed):
    def files(d):
        (d / "out").mkdir()
        with sqlite3.connect(d / "out" / "runs.sqlite") as conn:
            conn.execute("CREATE TABLE runs_of_my_lab (id INTEGER, sample TEXT)")
        if listed:
            fracid_wrote(d / "out", "runs.sqlite")
    return files


def _store_is_a_directory(d):
    (d / "out" / "runs.sqlite").mkdir(parents=True)
    fracid_wrote(d / "out", "runs.sqlite")


def _fifo(d):
    (d / "cfg.toml").unlink()
    os.mkfifo(d / "cfg.toml")


def _loop(d):
    (d / "cfg.toml").unlink()
    (d / "cfg.toml").symlink_to("cfg.toml")


def _data_loop(d):
    (d / "bar.csv").unlink()
    (d / "bar.csv").symlink_to("bar.csv")


def _huge_config(d):
    (d / "cfg.toml").write_text(bar_config() + ("#" * 99 + "\n") * 12_000)  # 1.2 MB of comments


def _nested(d):
    (d / "cfg.toml").write_text("a = " + "[" * 5000 + "]" * 5000 + "\n")


NAME = 'beam "A", 2026\nrun 2'  # a comma, quotes and a line break
FORMULA = "=HYPERLINK(\"http://x\",\"y\")"


def _names_read_back(name):
    """fit.csv read back with the csv module: a header of 5 columns, one row per data value (12), every row
    of 5 cells, the block column the name (a formula quoted with ')."""
    def verify(proc, d):
        check(proc, d, 0)
        with open(d / "out" / "fit.csv", newline="", encoding="utf-8") as handle:
            rows = list(csv.reader(handle))
        assert rows[0] == ["control_mm", "measured", "std", "computed", "block"], rows[0]
        assert len(rows) == 1 + 12 and all(len(r) == 5 for r in rows), rows
        expected = "'" + name if name.startswith("=") else name
        assert {r[4] for r in rows[1:]} == {expected}, {r[4] for r in rows[1:]}
    return verify


def _toml_string(text):
    return '"' + text.replace("\\", "\\\\").replace('"', '\\"').replace("\n", "\\n") + '"'


def _tilde(proc, d):
    check(proc, d, 0)
    assert (d / "home" / "res" / "curve.csv").exists(), sorted(p.name for p in d.iterdir())
    assert not (d / "~").exists(), "a directory named ~ was made"


def _rerun(proc, d):
    """The second simulate into the same directory replaces fracid's own files (exit 0)."""
    check(proc, d, 0)
    assert (d / "out" / "curve.csv").read_text() != "an earlier run of fracid\n"


def _config_as_result_json(d):
    """The configuration saved as result.json in a directory where an earlier run wrote result.json."""
    (d / "result.json").write_text(bar_config())
    fracid_wrote(d, "result.json")


def _home(d):
    (d / "home").mkdir()


def _simulated_before(d):
    (d / "out").mkdir()
    fracid_wrote(d / "out", "curve.csv", "curve.png", "vtk")
    (d / "out" / "curve.csv").write_text("an earlier run of fracid\n")


def _store_message_is_not_move_away(proc, d):
    err = check(proc, d, 4, ["runs.sqlite", "is it a directory"])
    assert "move it away" not in err, err


SIM = ("simulate", "cfg.toml", "--quiet")

CASES = {
    # ---- outputs never replace inputs, nor files fracid did not write
    "out-dot-beside-a-measured-curve-csv": case(
        None, config=simulate_config(), csv=None, files=_measured_curve_beside, args=(*SIM, "--out", "."),
        verify=_unchanged("curve.csv", 2, ["curve.csv", "not written by fracid", "--out"])),
    "identify-data-file-is-out-fit-csv": case(
        None, config=bar_config(file="out/fit.csv"), csv=_data_in_out, args=IDENTIFY,
        verify=_unchanged("out/fit.csv", 2, ["fit.csv", "experiments[0].file", "never overwrites"])),
    "out-fit-csv-links-to-the-data": case(2, ["fit.csv", "experiments[0].file", "never overwrites"], files=_link_to_data,
                                          args=IDENTIFY),
    "config-inside-out-as-result-json": case(
        2, ["result.json", "the configuration", "never overwrites"], args=("identify", "result.json", "--out", "."),
        files=_config_as_result_json),
    "simulate-again-replaces-its-own-files": case(None, config=simulate_config(), csv=None, files=_simulated_before,
                                                  args=(*SIM, "--out", "out"), verify=_rerun),
    "another-programs-runs-sqlite-in-out": case(4, ["runs.sqlite", "another program", "runs_of_my_lab", "--out"],
                                                files=_foreign_database(False), args=IDENTIFY),
    "another-programs-database-listed-as-fracids": case(4, ["another program", "runs_of_my_lab", "--out"],
                                                        files=_foreign_database(True), args=IDENTIFY),
    "out-tilde-expanded": case(None, config=simulate_config(), csv=None, args=(*SIM, "--out=~/res"),
                               files=_home, env={"HOME": "home"}, verify=_tilde),
    # ---- the configuration path is checked like a data file
    "config-is-a-fifo": case(2, ["cfg.toml", "not a regular file"], files=_fifo),
    "config-is-dev-zero": case(2, ["/dev/zero", "not a regular file"], args=("identify", "/dev/zero")),
    "config-on-stdin": case(0, stdin=simulate_config(), args=("simulate", "-", "--out", "out", "--quiet")),
    "config-too-large": case(2, ["too large", "bytes"], files=_huge_config),
    "config-nested-too-deeply": case(2, ["nested too deeply"], files=_nested),
    "config-symlink-loop": case(2, ["cfg.toml", "symbolic link"], files=_loop),
    "data-path-symlink-loop": case(2, ["experiments[0].file", "symbolic link"], files=_data_loop),
    "data-path-with-a-nul-byte": case(2, ["experiments[0].file", "NUL"], config=bar_config(file="bar\\u0000.csv")),
    "output-directory-with-a-nul-byte": case(2, ["output.directory", "NUL"],
                                             config=bar_config(tail='directory = "res\\u0000ults"').replace(
                                                 'directory = "results"\n', "")),
    # ---- the run store: each SQLite failure with its own advice
    "store-is-a-directory": case(None, files=_store_is_a_directory, args=IDENTIFY,
                                 verify=lambda proc, d: _store_message_is_not_move_away(proc, d)),
    # ---- CSV tables with the csv module
    "fit-csv-name-with-comma-quotes-newline": case(None, config=bar_config(experiment=f"name = {_toml_string(NAME)}"),
                                                   args=IDENTIFY, slow=True, verify=_names_read_back(NAME)),
    "fit-csv-name-like-a-formula": case(None, config=bar_config(experiment=f"name = {_toml_string(FORMULA)}"),
                                        args=IDENTIFY, slow=True, verify=_names_read_back(FORMULA)),
}

