"""Paths and the messages about them (issue 38): the run store of ``--store`` checked like the other paths, a store's
failure on a nearly full file system told as a full disk, the option each message names (``--out DIR``,
``--store FILE``, ``-o FILE``), a TOML file given as data, the posterior's floor named by what sets it, and the
templates of ``fracid init`` (unknown types named; no number over a scaling default; a mesh each model's length
needs; every offered pair checked, with at most :data:`MAX_TEMPLATE_UNKNOWNS` unknowns)."""

from __future__ import annotations

import dataclasses
import errno
import re
import sqlite3

import pytest

from fracid import cli
from fracid.cli.common import shared_store
from fracid.cli.init import _resolving, config_text, runnable_pairs, unknown_pair
from fracid.config.checker import looks_like_toml
from fracid.inverse.sampling.posterior import ess_floor, floor_text
from fracid.runtime import exits
from fracid.runtime.exits import NEARLY_FULL, UsageError, describe, store_failure

#: the most unknowns a template of ``fracid init`` may have. Measured on the test machine (2 cores, load average
#: about 10 from other jobs): one forward run of the PF-CZM on the wedge-splitting specimen, 28 995 unknowns,
#: took 197 s (6.8 ms per unknown; the strip's 29 166 unknowns 120 s, 4.1 ms); the damage models' runs take up to
#: 15 ms per unknown (the integral model on the wedge, 7 034 unknowns, 106 s). 30 000 unknowns keep one run of
#: every template under about 200 s on that loaded machine (``fracid check FILE`` times it).
MAX_TEMPLATE_UNKNOWNS = 30_000


# ---------------------------------------------------------------------------------------------- --store


def test_a_store_that_is_an_input_a_device_or_not_sqlite_is_refused(tmp_path):
    data, config = tmp_path / "bar.csv", tmp_path / "cfg.toml"
    data.write_text("u_mm,F_N\n0,0\n")
    config.write_text("[model]\n")
    inputs = [("the configuration", config), ("experiments[0].file", data)]
    for path, words in ((data, "experiments[0].file, an input"), (config, "the configuration, an input"),
                        ("/dev/null", "not a regular file")):
        with pytest.raises(UsageError, match=re.escape(words)) as refused:
            shared_store(path, inputs)
        assert "--store" in str(refused.value)
    (tmp_path / "notes.txt").write_text("not a database\n")
    with pytest.raises(UsageError, match="not a run store"):
        shared_store(tmp_path / "notes.txt", inputs)
    (tmp_path / "link.sqlite").symlink_to(data)  # through a link: still the data file
    with pytest.raises(UsageError, match="an input of this run"):
        shared_store(tmp_path / "link.sqlite", inputs)


def test_a_new_an_empty_or_an_sqlite_store_is_accepted(tmp_path):
    assert shared_store(tmp_path / "new.sqlite") == tmp_path / "new.sqlite"
    (tmp_path / "empty.sqlite").write_bytes(b"")
    assert shared_store(tmp_path / "empty.sqlite") == tmp_path / "empty.sqlite"
    with sqlite3.connect(tmp_path / "db.sqlite") as conn:
        conn.execute("CREATE TABLE runs (key TEXT)")
    assert shared_store(tmp_path / "db.sqlite") == tmp_path / "db.sqlite"


# ---------------------------------------------------------------------------------------------- full disk


@pytest.mark.parametrize("code, free, expected", [
    (4874, 24_576, 13),  # SQLITE_IOERR_SHMSIZE with 24 KiB free: the disk is full
    (778, NEARLY_FULL - 1, 13),  # SQLITE_IOERR_WRITE just below the threshold
    (4874, NEARLY_FULL, 10),  # at the threshold: an input/output error
    (778, 70 * 2**30, 10),  # 70 GiB free: an input/output error
    (10, None, 10),  # free space unknown
    (13, 70 * 2**30, 13),  # SQLITE_FULL stays
    (None, 0, None),
])
def test_a_store_io_error_on_a_nearly_full_file_system_is_a_full_disk(code, free, expected):
    assert store_failure(code, free) == expected


def _io_error(code):
    err = sqlite3.OperationalError("disk I/O error")
    err.sqlite_errorcode = code
    return err


@pytest.mark.parametrize("free, words, absent", [(4096, "is full", "input/output error"),
                                                 (2**36, "input/output error", "is full")])
def test_the_store_message_reads_the_free_space_of_the_stores_file_system(monkeypatch, tmp_path, free, words, absent):
    seen = []
    monkeypatch.setattr(exits, "_free", lambda path: seen.append(str(path)) or free)
    status, text = describe(_io_error(4874), store_path=tmp_path / "s.sqlite", store_option="--store FILE")
    assert status == exits.FILES and words in text and absent not in text and "move it away" not in text, text
    assert seen and all(path.startswith(str(tmp_path / "s.sqlite")) for path in seen), seen


def test_a_full_disk_under_the_store_lock_names_the_stores_file(tmp_path):
    lock = tmp_path / "s.sqlite.fracid.runtime.locks"
    status, text = describe(OSError(errno.ENOSPC, "No space left on device", str(lock)),
                            store_path=tmp_path / "s.sqlite", out=tmp_path / "out", store_option="--store FILE")
    assert status == exits.FILES and f"the disk is full (writing {lock}" in text and "out" not in text.split("(")[0]


# ---------------------------------------------------------------------------------------------- options named


@pytest.mark.parametrize("options, named, not_named", [
    ({}, "--out DIR", "--store"), ({"store_option": "--store FILE"}, "--store FILE", "--out"),
])
def test_a_read_only_store_names_the_option_that_placed_it(options, named, not_named):
    err = sqlite3.OperationalError("attempt to write a readonly database")
    err.sqlite_errorcode = 8
    _, text = describe(err, store_path="s.sqlite", **options)
    assert named in text and not_named not in text, text


@pytest.mark.parametrize("err", [PermissionError(errno.EACCES, "Permission denied", "ro/x.toml"),
                                 OSError(errno.EROFS, "Read-only file system", "ro/x.toml"),
                                 NotADirectoryError(errno.ENOTDIR, "Not a directory", "taken/x.toml")])
def test_init_failures_name_its_o_option(err):
    status, text = describe(err, out_option="-o FILE")
    assert status == exits.FILES and "-o FILE" in text and "--out" not in text, text


def test_the_command_line_passes_the_options_to_the_message(tmp_path, capsys):
    (tmp_path / "taken").write_text("a file\n")
    assert cli.main(["init", "-o", str(tmp_path / "taken" / "x.toml")]) == exits.INPUT  # -o in a missing directory
    assert "-o " in capsys.readouterr().err


# ---------------------------------------------------------------------------------------------- TOML as data


def test_toml_is_told_from_a_data_table(tmp_path):
    cases = {"a.toml": "u_mm,F_N\n0,0\n", "b.txt": "# fracid\n\n[model]\ntype = \"pf-czm\"\n",
             "c.csv": "[mm],[N]\n0,0\n", "d.csv": "u_mm,F_N\n0,0\n", "e.txt": "[mm]\n0\n1\n"}
    found = {}
    for name, text in cases.items():
        (tmp_path / name).write_text(text)
        found[name] = looks_like_toml(tmp_path / name)
    assert found == {"a.toml": True, "b.txt": True, "c.csv": False, "d.csv": False, "e.txt": False}


# ---------------------------------------------------------------------------------------------- the floor


@pytest.mark.parametrize("target, words", [(500.0, "the least effective sample size"),
                                           (4000.0, "5% of target_ess = 4000"),
                                           (30.0, "target_ess = 30 itself")])
def test_the_floor_is_named_by_the_term_that_sets_it(target, words):
    assert words in floor_text(target)
    assert (ess_floor(target) == 30.0) == ("itself" in floor_text(target))


# ---------------------------------------------------------------------------------------------- fracid init


@pytest.mark.parametrize("specimen, model, words", [
    ("beam", "gradient-damage", ["--specimen 'beam'", "unknown specimen type", "notched-beam", "did you mean "
                                 "notched-beam"]),
    ("bar", "gradient", ["--model 'gradient'", "unknown model type", "crack-band", "did you mean gradient-damage"]),
    ("bar", "cohesive-crack", ["does not run", "--model gradient-damage", "pf-czm"]),
    ("mesh", "gradient-damage", ["--specimen mesh", "mesh file"]),
])
def test_init_names_the_unknown_type_and_the_known_ones(specimen, model, words):
    text = unknown_pair(specimen, model, runnable_pairs())
    assert all(word in text for word in words), text
    assert "no configuration for this pair" not in text


def test_the_mesh_resolves_the_length_the_model_declares():
    from fracid.specimens import SPECIMENS

    assert _resolving("pf-czm", SPECIMENS["notched-beam"], {"h_fine": 2.0}, {})[0] == {"h_fine": 0.5}
    assert _resolving("pf-czm", SPECIMENS["notched-beam"], {"h_fine": 2.0}, {"l": 10.0}) is None  # h <= l / 5
    count = _resolving("pf-czm", SPECIMENS["strip"], {}, {})[0]["n_elements"]
    assert count % 2 == 1 and 100.0 / count <= 0.5 < 100.0 / (count - 2)  # odd, the fewest that resolve l / 5
    assert _resolving("pf-czm", SPECIMENS["bar"], {}, {}) is None  # 0.5 mm already
    assert _resolving("cohesive-crack", SPECIMENS["notched-beam"], {}, {}) is None  # no length declared


@pytest.mark.parametrize("specimen, model", runnable_pairs())
def test_templates_write_no_number_over_a_scaling_default_nor_an_installed_path(specimen, model):
    from fracid.specimens import SPECIMENS

    for beside in (False, True):
        text = config_text(specimen, model, beside)
        for field in dataclasses.fields(SPECIMENS[specimen]):
            if field.default is None:
                assert not re.search(rf"^{field.name} = ", text, re.M), (field.name, specimen, model)
        assert not re.search(r'^#? ?file = "/', text, re.M) and "site-packages" not in text


@pytest.mark.slow
def test_every_offered_pair_is_checked_with_a_mesh_of_reasonable_size(tmp_path, capsys):
    """``fracid check`` accepts every pair of ``fracid init --list`` as written, each with at most
    :data:`MAX_TEMPLATE_UNKNOWNS` unknowns (their count stands for the run's time: see there)."""
    sizes = {}
    for specimen, model in runnable_pairs():
        path = tmp_path / f"{specimen}-{model}.toml"
        assert cli.main(["init", "--specimen", specimen, "--model", model, "-o", str(path)]) == 0
        capsys.readouterr()
        assert cli.main(["check", str(path), "--no-time"]) == 0, capsys.readouterr().err
        sizes[specimen, model] = int(re.search(r"([\d,]+) unknowns", capsys.readouterr().out).group(1).replace(",", ""))
    assert max(sizes.values()) <= MAX_TEMPLATE_UNKNOWNS, sizes
