"""A lab's DIC exports as its software writes them (issue 41): European CSV (semicolons, decimal commas) in the
frame table and the point clouds, a frame table whose file column has another name, and files refused before
they are read (too large, binary)."""

import dataclasses
import shutil
from pathlib import Path

import numpy as np
import pytest

from fracid.data import DataError
from fracid.data.dic import read_dic_frames
from fracid.data.table import check_text_file, read_table

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "dic"


def european(source: Path, target: Path, file_column: str = "cloud") -> Path:
    """The example's frame table and clouds rewritten with ';' separators and decimal commas, the frame table's
    file column renamed; returns the new frame table."""
    target.mkdir()
    for path in source.glob("*.csv"):
        lines = path.read_text().splitlines()
        header = lines[0].replace(",file,", f",{file_column},") if path.name == "frames.csv" else lines[0]
        # decimal commas in the numbers only: the cloud files keep their names
        rows = [";".join(cell if cell.endswith(".csv") else cell.replace(".", ",") for cell in line.split(","))
                for line in lines[1:]]
        (target / path.name).write_text("\n".join([header.replace(",", ";"), *rows]) + "\n")
    return target / "frames.csv"


def test_a_european_export_reads_as_the_original(tmp_path):
    original = read_dic_frames(EXAMPLE / "frames.csv", sigma="sigma", load_columns=["cmod_mm"])
    table = european(EXAMPLE, tmp_path / "eu")
    assert ";" in table.read_text() and "0,02" in table.read_text()
    read = read_dic_frames(table, sigma="sigma", load_columns=["cmod_mm"], delimiter=";", decimal=",",
                           file_column="cloud")
    np.testing.assert_array_equal(read.points, original.points)
    np.testing.assert_array_equal(read.u, original.u)
    np.testing.assert_array_equal(read.std, original.std)
    np.testing.assert_array_equal(read.load["cmod_mm"], original.load["cmod_mm"])


def test_a_european_export_read_with_the_defaults_names_the_keys(tmp_path):
    table = european(EXAMPLE, tmp_path / "eu", file_column="file")
    with pytest.raises(DataError) as err:
        read_dic_frames(table, sigma="sigma", load_columns=["cmod_mm"])
    assert "delimiter = ';'" in str(err.value) and 'decimal = ","' in str(err.value)


def test_the_field_block_takes_delimiter_decimal_and_file_column(tmp_path):
    from fracid.config import ConfigError, load_config

    european(EXAMPLE, tmp_path / "eu")
    text = (EXAMPLE / "identify.toml").read_text().replace('kind = "field"', 'kind = "field"\ndelimiter = ";"\n'
                                                            'decimal = ","\nfile_column = "cloud"')
    shutil.copy(EXAMPLE / "load_cmod.csv", tmp_path / "eu" / "load_cmod.csv")
    (tmp_path / "eu" / "identify.toml").write_text(text)
    config = load_config(tmp_path / "eu" / "identify.toml")
    field = next(exp for exp in config.experiments if exp.kind == "field")
    assert (field.delimiter, field.decimal, field.file_column) == (";", ",", "cloud")
    # the wrong file column is named with its key
    (tmp_path / "eu" / "identify.toml").write_text(text.replace('file_column = "cloud"', 'file_column = "files"'))
    with pytest.raises(ConfigError) as err:
        load_config(tmp_path / "eu" / "identify.toml")
    assert "file_column" in str(err.value) and "files" in str(err.value)


def test_a_file_too_large_is_refused_before_it_is_read(tmp_path):
    path = tmp_path / "cloud.csv"
    path.write_text("X,Y,U,V\n" + "1.0,2.0,0.1,0.2\n" * 1000)
    check_text_file(str(path), limit=path.stat().st_size)  # at the limit: read
    with pytest.raises(DataError) as err:
        check_text_file(str(path), limit=path.stat().st_size - 1)
    assert str(path) in str(err.value) and "MiB" in str(err.value) and "split" in str(err.value)


def test_a_binary_file_is_refused_and_utf16_left_to_the_decoder(tmp_path):
    binary = tmp_path / "cloud.csv"
    binary.write_bytes(b"X,Y,U,V\n1,2,3,4\n\x00\x01\x02")
    with pytest.raises(DataError) as err:
        read_table(str(binary), columns=["X"])
    assert "NUL byte at offset 16" in str(err.value) and "binary" in str(err.value)
    utf16 = tmp_path / "utf16.csv"
    utf16.write_text("X,Y\n1,2\n", encoding="utf-16")
    with pytest.raises(DataError) as err:
        read_table(str(utf16), columns=["X"])
    assert "UTF-16" in str(err.value)
    text = tmp_path / "text.csv"
    text.write_text("X,Y\n1,2\n")
    assert read_table(str(text), columns=["X"]).header == ["X", "Y"]


def test_the_fit_error_is_given_per_block_in_its_own_unit():
    from fracid.inverse.core.method import MethodResult

    # a force curve (peak 1000 N, RMS 10 N) and a displacement field (peak 0.01 mm, RMS 0.0001 mm)
    force = np.linspace(100.0, 1000.0, 10)
    field = np.linspace(-0.01, 0.01, 10)
    result = MethodResult(["c"], np.array([1.0]), np.eye(1), np.r_[force, field],
                          np.r_[force + 10.0, field + 1e-4], np.ones(20), [("global", 0, 10), ("field", 10, 20)])
    result = dataclasses.replace(result, quantities=["force", "u"])
    rows = {row["name"]: row for row in result.block_rms()}
    assert rows["global"]["unit"] == "N" and rows["field"]["unit"] == "mm"
    np.testing.assert_allclose([rows["global"]["rms"], rows["field"]["rms"]], [10.0, 1e-4])
    np.testing.assert_allclose([rows["global"]["percent"], rows["field"]["percent"]], [1.0, 1.0])
    # one RMS over both blocks over the largest value (1000 N) mixes newtons and millimetres: 0.71 %, which the
    # headline no longer shows when there are several blocks
    assert result.rms_percent == pytest.approx(100 * np.sqrt(50.0) / 1000.0)
    text = result.rms_text()
    assert "global 10 N (1 % of its peak)" in text and "field 0.0001 mm (1 % of its peak)" in text


def test_a_block_named_field_is_not_called_field_field():
    from fracid.report.field_figures import field_heading, field_stem

    assert (field_heading("field"), field_stem("field")) == ("Displacement field", "field")
    assert (field_heading("dic"), field_stem("dic")) == ("Displacement field dic", "field_dic")
