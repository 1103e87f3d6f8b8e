"""``--store FILE``: a run store shared between commands, so that identifications of the same model, specimen and
measured controls reuse each other's forward runs; bad paths and a store in use are refused with a message."""

import json
import sqlite3

import pytest

from _bar_study import stored_rows, write_bar_study
from fracid import cli
from fracid.runtime.exits import FILES, INPUT
from fracid.runtime.locks import store_lock


def identify(config, out, store, *extra):
    return cli.main(["identify", str(config), "--out", str(out), "--store", str(store), "--workers", "1", "--quiet",
                     *extra])


def test_a_shared_store_lets_a_second_identification_reuse_every_run(tmp_path):
    config = write_bar_study(tmp_path)
    store = tmp_path / "shared.sqlite"
    assert identify(config, tmp_path / "first", store) == 0
    first = json.loads((tmp_path / "first" / "result.json").read_text())
    assert first["runs"]["knn_computed"] == first["runs"]["knn"] > 0
    assert not (tmp_path / "first" / "runs.sqlite").exists()  # the runs went to the shared store
    rows = stored_rows(store)
    assert rows >= first["runs"]["knn"] + first["runs"]["kalman"]

    assert identify(config, tmp_path / "second", store) == 0
    second = json.loads((tmp_path / "second" / "result.json").read_text())
    assert second["runs"]["knn_computed"] == 0 and second["runs"]["knn_reused"] == first["runs"]["knn"]
    assert second["runs"]["kalman_computed"] == 0
    assert second["x"] == first["x"]
    assert stored_rows(store) == rows


def test_bad_store_paths_are_named(tmp_path, capsys):
    config = write_bar_study(tmp_path)
    assert identify(config, tmp_path / "out", tmp_path / "missing" / "runs.sqlite") == INPUT
    err = capsys.readouterr().err
    assert "--store" in err and "does not exist" in err


def test_a_directory_as_store_is_refused(tmp_path, capsys):
    config = write_bar_study(tmp_path)
    assert identify(config, tmp_path / "out", tmp_path) == INPUT
    err = capsys.readouterr().err
    assert "--store" in err and "is a directory" in err and "Traceback" not in err


def test_another_programs_database_is_not_written(tmp_path, capsys):
    config = write_bar_study(tmp_path)
    foreign = tmp_path / "other.sqlite"
    with sqlite3.connect(foreign) as conn:
        conn.execute("CREATE TABLE parts (name TEXT)")
    before = foreign.read_bytes()
    assert identify(config, tmp_path / "out", foreign) == FILES
    err = capsys.readouterr().err
    assert "another program" in err and "--store FILE" in err
    assert foreign.read_bytes() == before


def test_a_store_in_use_is_refused(tmp_path, capsys):
    config = write_bar_study(tmp_path)
    store = tmp_path / "shared.sqlite"
    with store_lock(store):
        assert identify(config, tmp_path / "out", store) == FILES
    err = capsys.readouterr().err
    assert f"is using the run store {store}" in err and "--store FILE" in err


@pytest.mark.parametrize("command", ["simulate", "sensitivity", "size-effect"])
def test_commands_without_a_store_do_not_take_the_option(tmp_path, capsys, command):
    with pytest.raises(SystemExit) as exit_:
        cli.main([command, str(tmp_path / "c.toml"), "--store", str(tmp_path / "s.sqlite")])
    assert exit_.value.code == INPUT and "unrecognized arguments: --store" in capsys.readouterr().err


def test_other_data_at_the_same_controls_reuse_the_population(tmp_path):
    """Another test of the series (the forces 3 % higher, the same control values): its identification through the
    same store computes no population run."""
    import numpy as np

    config = write_bar_study(tmp_path)
    store = tmp_path / "shared.sqlite"
    assert identify(config, tmp_path / "first", store) == 0
    data = np.loadtxt(tmp_path / "bar.csv", delimiter=",", skiprows=1)
    other = tmp_path / "other"
    other.mkdir()
    np.savetxt(other / "bar.csv", np.column_stack([data[:, 0], 1.03 * data[:, 1]]), delimiter=",", header="u_mm,F_N",
               comments="")
    (other / "study.toml").write_text(config.read_text())
    assert identify(other / "study.toml", tmp_path / "second", store) == 0
    first = json.loads((tmp_path / "first" / "result.json").read_text())
    second = json.loads((tmp_path / "second" / "result.json").read_text())
    assert second["runs"]["knn_computed"] == 0 and second["runs"]["knn_reused"] == second["runs"]["knn"]
    assert second["runs"]["kalman_computed"] > 0  # the filter goes elsewhere with other data
    assert second["x"] != first["x"]
