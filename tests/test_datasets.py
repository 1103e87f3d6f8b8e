"""Data sets by name (issue 28, item 4): :mod:`fracid.datasets`, ``fracid datasets`` and ``fracid init --dataset``.

Every data set loads with the stated units and counts, its README names its source (repository and commit),
licence and citation, the command line lists and writes them (never over a file it did not write; an unknown
name is exit 2 without a traceback), and each is identified on a coarse mesh with a small population: the
fit's RMS error stays below a stated fraction of the measured peak and every estimate inside its bounds.
"""

import json
import re
import subprocess
import sys
import tomllib
from pathlib import Path

import numpy as np
import pytest

from fracid import cli, datasets
from fracid.config import build_data, load_config
from fracid.data import DataError

#: per data set: (points, peak force [N], first and last control value [mm]) of its configuration's data
EXPECTED = {"gregoire2013-beam4": (24, 978.6, (0.004, 0.2)),
            "tinloi-que-wst": (32, 2845.6, (0.025, 1.008))}
#: per data set: the configuration's keys made small for a fast identification (a coarse mesh, a population of
#: 8, fewer points), and the largest RMS error of the fit [% of the measured peak] (measured: 4.8 and 3.7 %)
SMALL = {"gregoire2013-beam4": ({"h_fine": 5.0, "h_coarse": 10.0, "n": 8, "n_points": 12}, 6.0),
         "tinloi-que-wst": ({"h_fine": 10.0, "n": 8}, 5.0)}


def fracid_command(*args, cwd=None):
    """``python -m fracid ARGS`` in a child process: (exit status, stdout, stderr)."""
    proc = subprocess.run([sys.executable, "-m", "fracid", *map(str, args)], capture_output=True, text=True, cwd=cwd)
    return proc.returncode, proc.stdout, proc.stderr


def test_every_data_set_is_expected_here():
    assert datasets.names() == list(EXPECTED) == list(datasets.DATASETS)


@pytest.mark.parametrize("name", list(EXPECTED))
def test_data_set_loads_with_its_units_and_counts(name):
    data = datasets.load(name)
    points, peak, (first, last) = EXPECTED[name]
    assert data.y.shape == data.control.shape == (points,)
    assert np.all(np.isfinite(data.y)) and np.all(np.isfinite(data.control)) and np.all(data.std > 0)
    assert data.y.max() == pytest.approx(peak, abs=0.1)  # N, not kN
    assert data.control[0] == pytest.approx(first) and data.control[-1] == pytest.approx(last)  # mm
    assert np.all(np.diff(data.control) > 0)
    assert datasets.path(name).is_file() and datasets.path(name).suffix == ".csv"


@pytest.mark.parametrize("name", list(EXPECTED))
def test_readme_names_source_licence_citation_units_and_scatter(name):
    ds = datasets.get(name)
    readme = ds.readme_path.read_text(encoding="utf-8")
    repository = re.search(r"\((\S+/\S+)\)", ds.licence).group(1)
    assert f"github.com/{repository}" in readme and re.search(r"commit\s+`[0-9a-f]{40}`", readme)
    assert "Licence: MIT" in readme and ds.licence_path.name in readme
    assert "Permission is hereby granted, free of charge" in ds.licence_path.read_text(encoding="utf-8")
    assert "Citation:" in readme and "## Units and scatter" in readme and "## Geometry" in readme
    for file in ds.file_paths:
        assert file.name in readme


@pytest.mark.parametrize("name", list(EXPECTED))
def test_configuration_matches_the_registry(name):
    ds = datasets.get(name)
    with open(ds.config_path, "rb") as f:
        raw = tomllib.load(f)
    assert (raw["specimen"]["type"], raw["model"]["type"]) == (ds.specimen, ds.model)
    # the data files by their names alone: `fracid init --dataset` copies them beside the configuration
    assert [block["file"] for block in raw["experiments"]] == [file.name for file in ds.file_paths]
    assert all(file.parent == ds.config_path.parent for file in ds.file_paths)


def test_unknown_name_lists_the_known_ones():
    with pytest.raises(DataError, match="unknown data set 'nope'") as err:
        datasets.load("nope")
    assert all(name in str(err.value) for name in EXPECTED)


def test_wedge_splitting_csv_holds_the_numbers_of_the_shipped_file():
    folder = datasets.get("tinloi-que-wst").config_path.parent
    text = (folder / "tinquesw2.dat").read_text(encoding="utf-8")
    tables = [re.findall(r"s\d+\s+([0-9.]+)", re.search(rf"parameter {name}\s*/(.*?)/", text, re.S).group(1))
              for name in (r"q\(s\)", r"Qm\(s\)")]
    rows = (folder / "load_opening.csv").read_text(encoding="utf-8").splitlines()
    assert rows[0] == "opening_mm,splitting_force_N"
    assert rows[1:] == [f"{q},{force}" for q, force in zip(*tables)] and len(rows) == 33


def test_datasets_command_lists_name_specimen_model_licence_citation():
    status, out, err = fracid_command("datasets")
    assert status == 0 and "Traceback" not in err
    for ds in datasets.DATASETS.values():
        row = next(line for line in out.splitlines() if line.startswith(ds.name + " "))
        for text in (ds.specimen, ds.model, ds.licence, ds.citation):
            assert text in row


@pytest.mark.parametrize("name", list(EXPECTED))
def test_init_dataset_writes_a_configuration_that_reads_the_copied_data(tmp_path, name):
    ds = datasets.get(name)
    status, _, err = fracid_command("init", "--dataset", name, "--out", "run.toml", cwd=tmp_path)
    assert status == 0, err
    for file in (*ds.file_paths, ds.licence_path):
        assert (tmp_path / file.name).read_bytes() == file.read_bytes()
    text = (tmp_path / "run.toml").read_text(encoding="utf-8")
    assert ds.citation in text and str(ds.readme_path) in text
    cfg = load_config(tmp_path / "run.toml", purpose="identify")
    assert [Path(exp.file).resolve() for exp in cfg.experiments] == [(tmp_path / f.name).resolve() for f in ds.file_paths]
    assert np.array_equal(build_data(cfg).y, datasets.load(name).y)


def test_init_dataset_without_out_names_the_installed_data():
    status, out, err = fracid_command("init", "--dataset", "tinloi-que-wst")
    assert status == 0, err
    assert f'file = "{datasets.path("tinloi-que-wst")}"' in out


def test_init_unknown_dataset_exits_2_naming_the_known_ones(tmp_path):
    status, out, err = fracid_command("init", "--dataset", "nope", "--out", "x.toml", cwd=tmp_path)
    assert status == 2 and "Traceback" not in err and len(err.strip().splitlines()) == 1
    assert "nope" in err and all(name in err for name in EXPECTED)
    assert not any(tmp_path.iterdir())


def test_init_dataset_refuses_to_overwrite(tmp_path):
    (tmp_path / "wst.toml").write_text("# mine\n")
    status, _, err = fracid_command("init", "--dataset", "tinloi-que-wst", "--out", "wst.toml", cwd=tmp_path)
    assert status == 2 and "does not overwrite" in err and "Traceback" not in err
    assert (tmp_path / "wst.toml").read_text() == "# mine\n" and not (tmp_path / "load_opening.csv").exists()
    # a measured file of the data file's name is never replaced, not even with --force
    (tmp_path / "load_opening.csv").write_text("opening_mm,splitting_force_N\n0.1,1.0\n")
    status, _, err = fracid_command("init", "--dataset", "tinloi-que-wst", "--out", "wst.toml", "--force",
                                    cwd=tmp_path)
    assert status == 2 and "load_opening.csv" in err and "Traceback" not in err
    assert (tmp_path / "load_opening.csv").read_text().endswith("0.1,1.0\n")
    assert (tmp_path / "wst.toml").read_text() == "# mine\n"
    # the same bytes are no conflict: --force replaces the configuration
    (tmp_path / "load_opening.csv").unlink()
    status, _, err = fracid_command("init", "--dataset", "tinloi-que-wst", "--out", "wst.toml", "--force",
                                    cwd=tmp_path)
    assert status == 0, err
    assert fracid_command("init", "--dataset", "tinloi-que-wst", "--out", "wst.toml", "--force", cwd=tmp_path)[0] == 0


def small_configuration(tmp_path, name) -> tuple:
    """The data set's configuration as ``fracid init --dataset`` writes it, with the keys of :data:`SMALL`."""
    assert cli.main(["init", "--dataset", name, "-o", str(tmp_path / "run.toml")]) == 0
    text = (tmp_path / "run.toml").read_text(encoding="utf-8")
    keys, rms_limit = SMALL[name]
    for key, value in keys.items():
        text, count = re.subn(rf"^{key} = \S+", f"{key} = {value}", text, flags=re.M)
        assert count == 1, key
    (tmp_path / "run.toml").write_text(text, encoding="utf-8")
    return tmp_path / "run.toml", rms_limit


@pytest.mark.slow
@pytest.mark.parametrize("name", list(EXPECTED))
def test_data_set_is_identified_on_a_coarse_mesh(tmp_path, name):
    config, rms_limit = small_configuration(tmp_path, name)
    assert cli.main(["identify", str(config), "--quiet", "--out", str(tmp_path / "out")]) == 0
    result = json.loads((tmp_path / "out" / "result.json").read_text())
    fit = np.genfromtxt(tmp_path / "out" / "fit.csv", delimiter=",", names=True, dtype=None, encoding="utf-8")
    rms = np.sqrt(np.mean((fit["computed"] - fit["measured"]) ** 2))
    assert rms < rms_limit / 100 * fit["measured"].max(), (rms, fit["measured"].max())
    lower, upper = np.array(result["bounds"])
    margin = 0.01 * (upper - lower)  # inside, not at a bound
    assert np.all(lower + margin < result["x"]) and np.all(np.array(result["x"]) < upper - margin), result["x"]
    assert not result["at_bound"]
