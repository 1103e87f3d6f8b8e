"""Hostile-input cases of issue 38 (paths): ``--store`` checked like the other paths (an input of the run, a device,
a file that is not a run store, a directory that refuses writing), ``fracid init``'s unknown types and ``-o`` in a
missing or read-only directory, the configuration as ``/dev/stdin``, the configuration given as its own data file,
a 200 000-character column name, ``fracid check`` refusing what the run would refuse. Run by
tests/test_hostile_inputs.py."""

from __future__ import annotations

import re

from hostile import OUT, bar_config, case, check, run_fracid

LONG = "X" * 200_000  # a column name pasted from a whole line of a file


def _unchanged_and_no_lock(name, status, words):
    """Check status and words, that ``name`` is byte for byte as written and that no lock file was put beside it."""
    def verify(proc, d):
        check(proc, d, status, words)
        assert (d / name).read_text() == _ORIGINAL[name], f"{name} was changed"
        assert not list(d.glob(f"{name}*.locks")), sorted(p.name for p in d.iterdir())
    return verify


_ORIGINAL = {"cfg.toml": bar_config(), "notes.txt": "the lab's notes, not a run store\n"}


def _notes(d):
    (d / "notes.txt").write_text(_ORIGINAL["notes.txt"])


def _store_is_the_data(proc, d):
    check(proc, d, 2, ["--store bar.csv", "experiments[0].file", "an input of this run", "never writes"])
    assert not list(d.glob("bar.csv*.locks")) and not (d / "out").exists(), sorted(p.name for p in d.iterdir())


def _read_only(name):
    def files(d):
        (d / name).mkdir()
        (d / name).chmod(0o555)
    return files


def _config_as_data(d):
    """A data file named .txt that holds a configuration (TOML), as a user may save one by mistake."""
    (d / "curve.txt").write_text(bar_config())


def _long_name_once(proc, d):
    """The 200 000-character name cut (200 characters with its quotes), said once, the columns listed."""
    err = check(proc, d, 2, ["experiments[0].control_column", "not a column", "available columns: 'u_mm', 'F_N'"])
    runs = re.findall(r"X{50,}", err)
    assert len(runs) == 1 and len(runs[0]) < 200, [len(r) for r in runs]
    assert len(err) < 2000, len(err)


def _demo_written_beside(proc, d):
    """``fracid init -o`` writes the demo's data file beside the configuration and names it there, no path into
    the installed package, the mesh's scaling defaults left to scale; ``fracid check`` accepts it as written."""
    check(proc, d, 0, ["load_cmod.csv", "fracid check"])
    text = (d / "sub" / "mine.toml").read_text()
    assert re.search(r'^file = "load_cmod.csv"', text, re.M) and "site-packages" not in text and "/fracid/" not in text
    assert re.search(r"^# h_coarse = ", text, re.M) and not re.search(r"^h_coarse = ", text, re.M)
    assert (d / "sub" / "load_cmod.csv").is_file()
    checked = run_fracid(["check", "sub/mine.toml", "--no-time"], d)
    assert checked.returncode == 0 and "valid (for fracid identify" in checked.stdout, checked.stderr


def _sub(d):
    (d / "sub").mkdir()


def _valid_from_stdin(proc, d):
    check(proc, d, 0)
    assert "<stdin>: valid" in proc.stdout, proc.stdout


def _user_file_in_out(d):
    (d / "fit.csv").write_text("the lab's own fit\n")


STORE = ("identify", "cfg.toml", *OUT, "--store")

CASES = {
    # ---- --store: checked like the other paths, never written into an input or a file fracid did not make
    "store-is-the-data-csv": case(None, args=(*STORE, "bar.csv"), verify=_store_is_the_data),
    "store-is-the-configuration": case(None, args=(*STORE, "cfg.toml"), verify=_unchanged_and_no_lock(
        "cfg.toml", 2, ["--store cfg.toml", "is the configuration", "an input of this run"])),
    "store-is-dev-null": case(2, ["--store /dev/null", "not a regular file", "--store runs.sqlite"],
                              args=(*STORE, "/dev/null")),
    "store-is-a-text-file": case(None, files=_notes, args=(*STORE, "notes.txt"), verify=_unchanged_and_no_lock(
        "notes.txt", 2, ["--store notes.txt", "not a run store", "SQLite"])),
    "store-in-a-read-only-directory": case(4, ["permission denied", "ro/s.sqlite", "--store FILE"],
                                           files=_read_only("ro"), args=(*STORE, "ro/s.sqlite"), needs_user=True),
    # ---- fracid init: the unknown type named with the known ones; -o checked
    "init-unknown-specimen-beam": case(2, ["--specimen 'beam'", "unknown specimen type", "notched-beam, dogbone",
                                           "did you mean notched-beam"], args=("init", "--specimen", "beam")),
    "init-unknown-model-gradient": case(2, ["--model 'gradient'", "unknown model type", "pf-czm",
                                            "did you mean gradient-damage"], args=("init", "--model", "gradient")),
    "init-model-that-does-not-run-there": case(2, ["--specimen bar --model cohesive-crack", "does not run",
                                                   "gradient-damage", "pf-czm"],
                                               args=("init", "--specimen", "bar", "--model", "cohesive-crack")),
    "init-o-in-a-missing-directory": case(2, ["-o missing/x.toml", "missing does not exist"],
                                          args=("init", "-o", "missing/x.toml")),
    "init-dataset-o-in-a-missing-directory": case(2, ["-o missing/x.toml", "missing does not exist"],
                                                  args=("init", "--dataset", "gregoire2013-beam4", "-o",
                                                        "missing/x.toml")),
    "init-o-in-a-read-only-directory": case(4, ["permission denied", "-o FILE"], files=_read_only("ro"),
                                            args=("init", "-o", "ro/x.toml"), needs_user=True),
    "init-demo-data-copied-beside": case(None, files=_sub, args=("init", "-o", "sub/mine.toml"),
                                         verify=_demo_written_beside),
    # ---- the configuration's path and the data files it names
    "config-as-dev-stdin-from-a-pipe": case(None, stdin=bar_config(), args=("check", "/dev/stdin", "--no-time"),
                                            verify=_valid_from_stdin),
    "config-is-its-own-data-file": case(2, ["experiments[0].file = 'cfg.toml'", "the configuration itself",
                                            "TOML file"], config=bar_config(file="cfg.toml")),
    "data-file-holds-a-configuration": case(2, ["experiments[0].file = 'curve.txt'", "a TOML file"],
                                            config=bar_config(file="curve.txt"), files=_config_as_data),
    "column-name-of-200000-characters": case(None, config=bar_config().replace('control_column = "u_mm"',
                                                                                f'control_column = "{LONG}"'),
                                             verify=_long_name_once),
    # ---- fracid check refuses what the run would refuse
    "check-out-is-a-file": case(4, ["taken is a file", "--out DIR"], args=("check", "cfg.toml", "--out", "taken",
                                                                            "--no-time"),
                                files=lambda d: (d / "taken").write_text("a file\n")),
    "check-out-holds-a-users-fit-csv": case(2, ["fit.csv", "not written by fracid", "--out"], files=_user_file_in_out,
                                            args=("check", "cfg.toml", "--out", ".", "--no-time")),
}

