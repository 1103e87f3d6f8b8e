"""Experimental data: reading curves (every bad-file case names file, row, column) and building y_exp, C_exp."""

import numpy as np
import pytest

from fracid import datasets
from fracid.data import (
    Curve,
    DataError,
    DataTypeError,
    ExperimentalData,
    curve_from_arrays,
    from_envelope,
    from_repeats,
    local_block,
    read_curve_csv,
    require_positive_force,
    sample_points,
    stack,
    with_std,
)


def write_csv(tmp_path, rows, header="cmod,F", name="curve.csv"):
    """A CSV file with the given header and data rows (lists of cells, or raw strings)."""
    lines = [header] + [row if isinstance(row, str) else ",".join(str(v) for v in row) for row in rows]
    path = tmp_path / name
    path.write_text("\n".join(lines) + "\n")
    return path


def good_rows(n=12):
    return [[0.01 * k, 100.0 * k] for k in range(n)]


def read(path, **options):
    options.setdefault("control_column", "cmod")
    options.setdefault("force_columns", "F")
    return read_curve_csv(path, **options)


def read_error(path, **options):
    """The message of the DataError that reading ``path`` raises."""
    with pytest.raises(DataError) as info:
        read(path, **options)
    return str(info.value)


# ------------------------------------------------------------------------------------ bad files


def test_empty_file_is_named(tmp_path):
    path = tmp_path / "empty.csv"
    path.write_text("\n \n")
    message = read_error(path)
    assert "empty.csv" in message and "the file is empty" in message


def test_missing_column_lists_the_available_ones(tmp_path):
    path = write_csv(tmp_path, good_rows())
    message = read_error(path, force_columns=["F", "load_kN"])
    assert "curve.csv" in message and "'load_kN'" in message
    assert "available columns: 'cmod', 'F'" in message


def test_header_row_is_required(tmp_path):
    path = tmp_path / "noheader.csv"
    path.write_text("\n".join(f"{0.01 * k},{k}" for k in range(12)) + "\n")
    with pytest.raises(DataError, match="header row"):
        read(path)


def test_text_in_a_number_cell_names_row_and_column(tmp_path):
    rows = good_rows()
    rows[4][1] = "abc"  # data row 5 = file row 6
    path = write_csv(tmp_path, rows)
    message = read_error(path)
    assert "curve.csv" in message and "row 6" in message and "'F'" in message and "'abc' is not a number" in message


@pytest.mark.parametrize("cell, word", [("", "empty cell"), ("nan", "missing value"), ("NaN", "missing value")])
def test_empty_or_nan_cell_names_row_and_column(tmp_path, cell, word):
    rows = good_rows()
    rows[2][0] = cell  # file row 4, control column
    path = write_csv(tmp_path, rows)
    message = read_error(path)
    assert "curve.csv" in message and "row 4" in message and "'cmod'" in message and word in message


def test_control_going_backwards_beyond_noise_names_the_row(tmp_path):
    rows = good_rows()
    rows[7][0] = 0.03  # file row 9: 0.03 after 0.06, range 0.11 -> tolerance 0.0011 mm
    path = write_csv(tmp_path, rows)
    message = read_error(path)
    assert "curve.csv" in message and "backwards at row 9" in message and "row 8" in message
    assert "backtrack_tolerance: the key of [[experiments]] in a configuration" in message


def test_fewer_points_than_requested(tmp_path):
    path = write_csv(tmp_path, good_rows(5))
    message = read_error(path)
    assert "curve.csv" in message and "5 data rows" in message and "fewer than the 10 a curve needs" in message
    assert len(read(path, min_points=5)[0].control) == 5


def test_row_with_missing_cells(tmp_path):
    rows = good_rows()
    rows[3] = "0.03"
    path = write_csv(tmp_path, rows)
    with pytest.raises(DataError, match="row 5 has 1 cells but the header has 2"):
        read(path)


# ------------------------------------------------------------------------- separators and decimals


def write_text(tmp_path, text, name="curve.csv"):
    path = tmp_path / name
    path.write_text(text)
    return path


def test_semicolon_and_decimal_comma_are_read(tmp_path):
    path = write_text(tmp_path, "cmod_mm;F_N\n0,001;12,5\n0,002;-13,25\n0,5e-2;1,5E2\n")
    (curve,) = read_curve_csv(path, control_column="cmod_mm", force_columns="F_N", delimiter=";", decimal=",",
                              min_points=3)
    np.testing.assert_allclose(curve.control, [0.001, 0.002, 0.005])
    np.testing.assert_allclose(curve.force, [12.5, -13.25, 150.0])


@pytest.mark.parametrize("delimiter, text", [
    ("\t", "cmod\tF\n" + "".join(f"{0.01 * k}\t{100.0 * k}\n" for k in range(12))),
    (" ", "  cmod   F \n" + "".join(f" {0.01 * k} \t {100.0 * k}\n" for k in range(12))),  # any run of whitespace
])
def test_tab_and_whitespace_separated_files(tmp_path, delimiter, text):
    (curve,) = read(write_text(tmp_path, text), delimiter=delimiter)
    np.testing.assert_allclose(curve.force, 100.0 * np.arange(12))


@pytest.mark.parametrize("header, separator", [("cmod;F", ";"), ("cmod\tF", "\t"), ("cmod   F", " ")])
def test_a_one_cell_header_names_the_separator_it_holds(tmp_path, header, separator):
    path = write_text(tmp_path, header + "\n" + "".join(f"{0.01 * k}{separator}{k}\n" for k in range(12)))
    message = read_error(path)
    assert "curve.csv" in message and f"the header is one cell {header!r}" in message
    assert f"seems to be separated by {separator!r}" in message and "no column" not in message


def test_decimal_commas_read_with_a_decimal_point_are_named(tmp_path):
    path = write_text(tmp_path, "cmod;F\n" + "".join(f"0,0{k};{k},5\n" for k in range(1, 13)))
    message = read_error(path, delimiter=";")
    assert "row 2" in message and "'0,01' is not a number" in message and 'set decimal = ","' in message
    # a comma-separated file cannot hold decimal commas: the rows split into too many cells
    path = write_text(tmp_path, "cmod,F\n" + "".join(f"0,0{k},{k},5\n" for k in range(1, 13)), name="comma.csv")
    message = read_error(path)
    assert "row 2 has 4 cells but the header has 2" in message and "decimal commas" in message
    assert 'delimiter = ";" and decimal = ","' in message


def test_decimal_comma_refuses_a_point_and_the_comma_delimiter(tmp_path):
    path = write_text(tmp_path, "cmod;F\n" + "".join(f"0,0{k};1.00{k},5\n" for k in range(1, 13)))
    with pytest.raises(DataError, match=r"row 2, column 'F': '1.001,5' is not a number; with decimal = \",\" a \"\.\""):
        read(path, delimiter=";", decimal=",")
    with pytest.raises(DataError, match="a comma cannot both separate the cells and mark the decimals"):
        read(path, delimiter=",", decimal=",")
    with pytest.raises(DataError, match="decimal = ';'"):
        read(path, delimiter=",", decimal=";")


# ------------------------------------------------------------------------------------ force sign


def test_negative_or_zero_forces_are_refused_naming_file_and_column(tmp_path):
    rows = [[0.01 * k, -100.0 * k, 0.0, 100.0 * k - 50.0] for k in range(12)]
    path = write_csv(tmp_path, rows, header="cmod,F_neg,F_zero,F_ok")
    negative, zero, mixed = read(path, force_columns=["F_neg", "F_zero", "F_ok"])
    require_positive_force([mixed])  # a few values below 0 (offset, noise) are fine
    with pytest.raises(DataError) as info:
        require_positive_force([mixed, negative])
    message = str(info.value)
    assert "curve.csv" in message and "'F_neg'" in message and "the forces are all negative" in message
    assert "from -1100 to 0 N" in message and "negate the column" in message
    with pytest.raises(DataError, match=r"curve.csv, column 'F_zero'.*all forces are zero"):
        require_positive_force([zero])


# ----------------------------------------------------------- direction of the control (before the order)


def signed_rows(control_sign, force_sign, n=12):
    return [[control_sign * 0.01 * k, force_sign * 100.0 * k * (n - k)] for k in range(n)]


def test_a_negative_control_is_named_before_the_order_of_the_rows(tmp_path):
    path = write_csv(tmp_path, signed_rows(-1, -1))
    message = read_error(path)
    assert "curve.csv" in message and "the control column 'cmod' is negative" in message
    assert "from 0 mm at row 2 to -0.11 mm at row 13" in message and "multiply it by -1" in message
    assert "control_unit_scale=-1" in message and "the force column 'F' is negative too" in message
    assert "backtrack_tolerance" not in message
    (curve,) = read(path, control_unit_scale=-1.0, force_unit_scale=-1.0)  # the documented fix
    np.testing.assert_allclose(curve.control, 0.01 * np.arange(12))
    assert np.all(curve.force >= 0.0) and any("multiplied by -1" in note for note in curve.notes)


def test_a_negative_control_with_positive_forces_names_the_control_alone(tmp_path):
    message = read_error(write_csv(tmp_path, signed_rows(-1, 1)))
    assert "'cmod' is negative" in message and "negative too" not in message
    with pytest.raises(DataError, match="'control' is negative"):
        curve_from_arrays(-0.01 * np.arange(12), np.arange(12.0))


def test_rows_in_reverse_order_are_named(tmp_path):
    path = write_csv(tmp_path, good_rows()[::-1])
    message = read_error(path)
    assert "decreases throughout, from 0.11 mm at row 2 to 0 mm at row 13" in message
    assert "reverse order" in message and "backtrack_tolerance" not in message


def test_swapped_columns_are_named(tmp_path):
    rows = signed_rows(1, 1)  # cmod increasing, F rising to a peak and falling back to 0
    path = write_csv(tmp_path, [[force, cmod] for cmod, force in rows])
    message = read_error(path)
    assert "the columns look swapped" in message and "control_column = 'F'" in message
    assert "'cmod' rises to 3600 at row 8" in message


def test_an_unloading_loop_is_not_taken_for_swapped_columns(tmp_path):
    rows = good_rows()
    rows[7][0] = 0.03  # a backtrack in an increasing control, the force increasing: not swapped
    message = read_error(write_csv(tmp_path, rows))
    assert "goes backwards" in message and "swapped" not in message


# ------------------------------------------------------------------- files as spreadsheets write them


@pytest.mark.parametrize("cell, delimiter, decimal, words", [
    ('"1,234.5"', ",", ".", ["'1,234.5' is not a number", "thousands separator", "(',';"]),
    ("1,234.5", ",", ".", ["row 6 has 3 cells", "'1,234.5'", "thousands separator ','"]),
    ("1 234,5", ";", ",", ["'1 234,5' is not a number", "thousands separator", "(spaces;"]),
    ("1\u00a0234,5", ";", ",", ["thousands separator", "non-breaking spaces"]),
    ("1.234,5", ";", ",", ["'1.234,5' is not a number", "thousands separator", "('.';"]),
    ("1.234,5", ";", ".", ["thousands separator", "set decimal = ','"]),
])
def test_thousands_separators_name_row_cell_and_fix(tmp_path, cell, delimiter, decimal, words):
    rows = [delimiter.join((f"{0.01 * k}".replace(".", decimal), "5")) for k in range(12)]
    rows[4] = delimiter.join(("0" + decimal + "04", cell))  # file row 6
    path = write_text(tmp_path, delimiter.join(("cmod", "F")) + "\n" + "\n".join(rows) + "\n")
    message = read_error(path, delimiter=delimiter, decimal=decimal)
    assert "curve.csv" in message and "row 6" in message
    for word in words:
        assert word in message, message


GOOD = "cmod,F\n" + "".join(f"{0.01 * k},{100.0 * k}\n" for k in range(12))


@pytest.mark.parametrize("above, skipped", [
    ("sep=,\n", "line 1 above the header (line 2)"),
    ('"sep=,"\n', "line 1 above"),
    ("# exported by Instron Bluehill 3\n", "line 1 above the header (line 2)"),
    ("Test 1, 2026-01-01\nSpecimen,B4\n\n", "lines 1, 2 above the header (line 4)"),
    ("# ", None),  # numpy.savetxt's header "# cmod,F"
])
def test_lines_above_the_header_are_skipped_and_noted(tmp_path, above, skipped):
    (curve,) = read(write_text(tmp_path, above + GOOD))
    np.testing.assert_allclose(curve.force, 100.0 * np.arange(12))
    assert any(skipped in note for note in curve.notes) if skipped else not curve.notes, curve.notes


def test_a_sep_line_must_agree_with_the_delimiter(tmp_path):
    path = write_text(tmp_path, "sep=;\n" + GOOD.replace(",", ";"))
    with pytest.raises(DataError, match=r"line 1 \('sep=;'\) declares the cell separator ';'.*set delimiter = ';'"):
        read(path)
    assert read(path, delimiter=";")[0].n_points == 12
    tab = write_text(tmp_path, "sep=\t\n" + GOOD.replace(",", "\t"), name="tab.csv")
    assert read(tab, delimiter=" ")[0].n_points == 12  # whitespace includes tabs


def test_a_header_not_on_line_1_names_the_line_that_looks_like_it(tmp_path):
    path = write_text(tmp_path, "Test 1, 2026-01-01\nTime,Load\n" + GOOD.split("\n", 1)[1])
    message = read_error(path)
    assert "the header (line 1) has no column 'cmod'" in message and "line 2" in message
    assert "looks like it ('Time', 'Load')" in message


def test_empty_cells_after_the_last_column_are_ignored(tmp_path):
    text = "".join(line + ",,\n" for line in GOOD.splitlines())
    assert read(write_text(tmp_path, text))[0].n_points == 12


def test_an_unclosed_quote_names_its_line(tmp_path):
    lines = GOOD.splitlines()
    lines[3] = '"' + lines[3]
    with pytest.raises(DataError, match="line 4 runs over several lines: a quote"):
        read(write_text(tmp_path, "\n".join(lines) + "\n"))


def test_a_utf16_file_is_named_as_such(tmp_path):
    path = tmp_path / "curve.csv"
    path.write_bytes(GOOD.encode("utf-16"))
    with pytest.raises(DataError, match="UTF-16.*CSV UTF-8"):
        read(path)


# ------------------------------------------------------------------------------ arguments (API)


@pytest.mark.parametrize("options, words", [
    ({"force_columns": None}, "force_columns must be a column name (str) or a list of names, got None"),
    ({"force_columns": ["F", 3]}, "force_columns[1] must be a column name (str), got 3 (int)"),
    ({"control_column": None}, "control_column must be a column name (str), got None"),
    ({"control_unit_scale": "1e-3"}, "control_unit_scale must be a number, got '1e-3' (str)"),
    ({"force_unit_scale": True}, "force_unit_scale must be a number, got True (bool)"),
    ({"backtrack_tolerance": "0.01"}, "backtrack_tolerance must be a number, got '0.01' (str)"),
    ({"min_points": 2.5}, "min_points must be an integer, got 2.5 (float)"),
    ({"delimiter": None}, "delimiter and decimal must be str"),
])
def test_read_curve_csv_checks_its_arguments(tmp_path, options, words):
    path = write_csv(tmp_path, good_rows())
    with pytest.raises(DataTypeError) as info:
        read(path, **options)
    assert isinstance(info.value, TypeError) and isinstance(info.value, DataError)
    assert words in str(info.value)


def test_read_curve_csv_checks_its_path_and_values():
    with pytest.raises(DataTypeError, match=r"path must be a file path \(str or os.PathLike\), got None"):
        read_curve_csv(None, control_column="cmod", force_columns="F")
    with pytest.raises(DataError, match="control_unit_scale must be a finite non-zero number"):
        read_curve_csv("x.csv", control_column="cmod", force_columns="F", control_unit_scale=0.0)
    with pytest.raises(DataError, match="force_columns is empty"):
        read_curve_csv("x.csv", control_column="cmod", force_columns=[])


@pytest.mark.parametrize("control, force, error, words", [
    (np.zeros((3, 2)), np.zeros(3), DataError, "one-dimensional, got shape (3, 2)"),
    (["0", "1", "2"], [0.0, 1.0, 2.0], DataTypeError, "must be an array of numbers (int or float)"),
    ("012", [0.0, 1.0, 2.0], DataTypeError, "must be an array of numbers"),
    ([0.0, 1.0, [2.0]], [0.0, 1.0, 2.0], DataTypeError, "must be an array of numbers"),
    ([True, False, True], [0.0, 1.0, 2.0], DataTypeError, "dtype bool"),
    ([0.0, 1.0, 2.0], [0.0, 1.0], DataError, "control has 3 values but force has 2"),
])
def test_curve_from_arrays_checks_its_arguments(control, force, error, words):
    with pytest.raises(error) as info:
        curve_from_arrays(control, force)
    assert words in str(info.value)


def test_builders_check_their_arguments():
    curve = linear_curve(1.0, 0.0, np.linspace(0.0, 1.0, 5))
    with pytest.raises(DataTypeError, match="a list of Curve objects, got None"):
        from_repeats(None, 5)
    with pytest.raises(DataTypeError, match="std must be an array of numbers"):
        with_std(curve, "0.1", 5)
    with pytest.raises(DataTypeError, match="control_range"):
        with_std(curve, 0.1, 5, ("0.1", "0.5"))
    with pytest.raises(DataTypeError, match="std_floor must be a number"):
        from_repeats([curve, curve], 5, std_floor="0.01")


# ------------------------------------------------------------------------------- reading rules


def test_noise_backtrack_is_dropped_and_noted(tmp_path):
    rows = good_rows()
    rows[1][0] = 0.0201  # file row 3 above file row 4 (0.02) by 1e-4 mm < 1 % of the range
    path = write_csv(tmp_path, rows)
    (curve,) = read(path)
    assert curve.n_points == 11
    assert 0.02 not in curve.control and 0.0201 in curve.control
    assert np.all(np.diff(curve.control) > 0)
    assert len(curve.notes) == 1 and "1 backtracking point dropped" in curve.notes[0] and "row 4" in curve.notes[0]
    assert "curve.csv" in curve.notes[0]


def test_backtrack_tolerance_is_explicit(tmp_path):
    rows = good_rows()
    rows[1][0] = 0.0201
    path = write_csv(tmp_path, rows)
    with pytest.raises(DataError, match="backwards at row 4"):
        read(path, backtrack_tolerance=1e-5)


def test_unit_scaling_and_several_force_columns(tmp_path):
    rows = [[10.0 * k, 0.1 * k, 0.2 * k] for k in range(10)]  # control in um, forces in kN
    path = write_csv(tmp_path, rows, header="cmod_um,F1_kN,F2_kN")
    curves = read_curve_csv(
        path, control_column="cmod_um", force_columns=["F1_kN", "F2_kN"], control_unit_scale=1e-3, force_unit_scale=1e3
    )
    assert len(curves) == 2
    np.testing.assert_allclose(curves[0].control, 0.01 * np.arange(10))
    np.testing.assert_allclose(curves[0].force, 100.0 * np.arange(10))
    np.testing.assert_allclose(curves[1].force, 200.0 * np.arange(10))
    assert "'F2_kN'" in curves[1].source and "curve.csv" in curves[1].source
    assert any("multiplied by 1000 to N" in note for note in curves[1].notes)


def test_one_file_per_repeat(tmp_path):
    paths = [write_csv(tmp_path, good_rows(), name=f"repeat{k}.csv") for k in range(3)]
    curves = [curve for path in paths for curve in read(path)]
    assert all(f"repeat{k}.csv" in curve.source for k, curve in enumerate(curves))


def test_curve_requires_increasing_control():
    with pytest.raises(DataError, match="increase strictly"):
        Curve(control=[0.0, 2.0, 1.0], force=[0.0, 1.0, 2.0])
    curve = curve_from_arrays([0.0, 1.0, 0.999, 2.0, 3.0], [0.0, 1.0, 1.1, 2.0, 3.0])
    np.testing.assert_array_equal(curve.control, [0.0, 1.0, 2.0, 3.0])
    assert "index 2" in curve.notes[0]


# --------------------------------------------------------------------------------- y_exp, C_exp


def linear_curve(slope, intercept, control, source="linear"):
    control = np.asarray(control, dtype=float)
    return Curve(control=control, force=slope * control + intercept, source=source)


def test_sample_points_are_equally_spaced():
    np.testing.assert_allclose(sample_points(0.0, 1.0, 5), [0.0, 0.25, 0.5, 0.75, 1.0])
    with pytest.raises(DataError):
        sample_points(1.0, 0.0, 5)


def test_interpolation_is_exact_on_a_linear_curve():
    control = [0.0, 0.013, 0.05, 0.051, 0.12, 0.2]  # irregular
    data = with_std(linear_curve(3000.0, 20.0, control), 5.0, 9)
    np.testing.assert_allclose(data.control, np.linspace(0.0, 0.2, 9))
    np.testing.assert_allclose(data.y, 3000.0 * data.control + 20.0, rtol=1e-13)
    np.testing.assert_allclose(data.std, 5.0)
    relative = with_std(linear_curve(3000.0, 20.0, control), 0.1, 9, relative=True)
    # 10 % of y, floored at 1 % of the peak (6.2 N) where y is small (first point: 2 N -> 6.2 N, noted)
    np.testing.assert_allclose(relative.std, np.maximum(0.1 * relative.y, 6.2))
    assert any("floor" in note and "1 of 9 points" in note for note in relative.notes)


def test_repeats_give_mean_and_sample_variance():
    control = np.linspace(0.0, 1.0, 11)
    curves = [linear_curve(a, b, control, f"test {k}") for k, (a, b) in enumerate([(10, 1), (20, 2), (40, 4)])]
    data = from_repeats(curves, 3, control_range=(0.0, 1.0), std_floor=0.0)
    # at x: forces (10x+1, 20x+2, 40x+4) = (1, 2, 4) (10x+1): mean 7/3 (10x+1), variance 7/3 (10x+1)^2
    x = np.array([0.0, 0.5, 1.0])
    np.testing.assert_allclose(data.y, 7.0 / 3.0 * (10 * x + 1))
    np.testing.assert_allclose(np.diag(data.covariance), 7.0 / 3.0 * (10 * x + 1) ** 2)
    np.testing.assert_array_equal(data.covariance, np.diag(np.diag(data.covariance)))
    assert any("ddof = 1" in note for note in data.notes)
    with pytest.raises(DataError, match="repeats.*envelope.*explicit std"):
        from_repeats(curves[:1], 3)


def test_repeats_default_to_the_common_range_and_floor_is_noted():
    a = linear_curve(100.0, 0.0, [0.0, 1.0, 2.0], "a")
    b = linear_curve(100.0, 0.0, [0.5, 1.0, 3.0], "b")
    data = from_repeats([a, b], 4)
    np.testing.assert_allclose(data.control, [0.5, 1.0, 1.5, 2.0])
    np.testing.assert_allclose(data.std, 0.01 * 200.0)  # identical curves: s = 0 raised to 1 % of the peak
    assert any("floor" in note and "4 of 4 points" in note for note in data.notes)


def test_no_extrapolation():
    a = linear_curve(100.0, 0.0, [0.0, 1.0, 2.0], "curve a")
    with pytest.raises(DataError, match="exceeds the data of curve a.*never extrapolated"):
        with_std(a, 1.0, 5, control_range=(0.0, 2.5))
    with pytest.raises(DataError, match="never extrapolated"):
        from_repeats([a, linear_curve(50.0, 0.0, [0.1, 3.0], "b")], 5, control_range=(0.0, 2.0))


def test_envelope_rule():
    control = np.linspace(0.0, 1.0, 5)
    mean = linear_curve(100.0, 10.0, control, "mean")
    lower = linear_curve(80.0, 10.0, control, "min")
    upper = linear_curve(140.0, 10.0, control, "max")
    data = from_envelope(mean, lower, upper, 3)
    np.testing.assert_allclose(data.y, [10.0, 60.0, 110.0])
    # s = (max - min)/4 = 60 x / 4 = 15 x; the zero width at x = 0 is floored to 1 % of the peak mean
    np.testing.assert_allclose(data.std, [1.1, 7.5, 15.0])
    assert any("s = (max - min)/4 from the min/max envelope" in note for note in data.notes)
    assert any("floor" in note and "1 of 3 points" in note for note in data.notes)
    with pytest.raises(DataError, match="lower envelope"):
        from_envelope(mean, upper, lower, 3)


def test_local_block_and_stacking():
    control = np.linspace(0.0, 1.0, 5)
    first = with_std(linear_curve(100.0, 1.0, control, "beam D50"), 2.0, 4)
    second = with_std(linear_curve(50.0, 1.0, control, "beam D100"), 3.0, 3)
    local = local_block((control, 2.0 + 10.0 * control), 0.5, points=first.control)
    data = stack(first, second, local)
    assert data.n_y == 4 + 3 + 4
    assert data.blocks == (("global", 0, 4), ("global_2", 4, 7), ("local", 7, 11))
    np.testing.assert_allclose(data.y[data.block("local")], 2.0 + 10.0 * first.control)
    expected = np.diag(np.r_[np.full(4, 4.0), np.full(3, 9.0), np.full(4, 0.25)])
    np.testing.assert_array_equal(data.covariance, expected)
    assert any("renamed 'global_2'" in note for note in data.notes)
    assert any(note.startswith("[global_2]") and "beam D100" in note for note in data.notes)
    assert any(note.startswith("[local]") for note in data.notes)
    assert isinstance(data, ExperimentalData)


def test_experimental_data_is_validated():
    with pytest.raises(DataError, match="positive definite"):
        ExperimentalData(control=[0.0, 1.0], y=[1.0, 2.0], covariance=np.diag([1.0, 0.0]), blocks=(("a", 0, 2),))
    with pytest.raises(DataError, match="tile"):
        ExperimentalData(control=[0.0, 1.0], y=[1.0, 2.0], covariance=np.eye(2), blocks=(("a", 0, 1),))


# ------------------------------------------------------------------------------ bundled real data


def gregoire_curves():
    """The bundled Gregoire beam's mean, lower and upper curves (fracid.datasets, the one home of bundled data)."""
    return read_curve_csv(datasets.path("gregoire2013-beam4"), control_column="cmod_mm",
                          force_columns=["load_mean_N", "load_min_N", "load_max_N"])


def test_gregoire_raw_file():
    path = datasets.path("gregoire2013-beam4")
    assert path.is_file()
    mean, lower, upper = read_curve_csv(
        path, control_column="cmod_mm", force_columns=["load_mean_N", "load_min_N", "load_max_N"]
    )
    assert mean.n_points == 5708 - 1  # 5708 data rows, file row 3 backtracks by 4.4e-6 mm and is dropped
    assert "row 3" in mean.notes[0] and "1 backtracking point dropped" in mean.notes[0]
    cmod, peak = mean.peak()
    assert peak == pytest.approx(978.6185) and cmod == pytest.approx(0.01934611)
    assert mean.control_range == pytest.approx((2e-5, 0.2031462))
    assert np.all(lower.force <= mean.force) and np.all(mean.force <= upper.force)


def test_gregoire_bundled_data():
    data = from_envelope(*gregoire_curves(), 40, rule="range/4", name="gregoire2013_beam4")
    assert data.y.shape == (40,) and data.covariance.shape == (40, 40)
    assert data.blocks == (("gregoire2013_beam4", 0, 40),)
    assert data.control[0] == pytest.approx(2e-5) and data.control[-1] == pytest.approx(0.2031462)
    # the sampled peak is the raw peak (978.6185 N at 0.01934611 mm): the grid point nearest it moved onto it
    i = int(np.argmax(data.y))
    assert data.control[i] == 0.01934611 and data.y[i] == 978.6185
    assert np.count_nonzero(data.control != np.linspace(2e-5, 0.2031462, 40)) == 1
    assert any("s = (max - min)/4 from the min/max envelope" in note for note in data.notes)
    assert any("1 backtracking point dropped" in note and "row 3" in note for note in data.notes)
    assert np.all(data.std > 0)


def test_the_old_bundled_data_names_raise_and_name_the_new_path():
    """fracid.data.gregoire2013_beam4[_path] are markers: the bundled data live in fracid.datasets."""
    from fracid.data import gregoire2013_beam4, gregoire2013_beam4_path

    with pytest.raises(TypeError, match=r"fracid.datasets.path\('gregoire2013-beam4'\)"):
        gregoire2013_beam4_path()
    with pytest.raises(TypeError, match=r"fracid.datasets.load\('gregoire2013-beam4'\)"):
        gregoire2013_beam4(n_points=40)


def test_block_weights_scale_the_objective_of_their_block():
    from fracid.data import ExperimentalData, DataError
    from fracid.inverse.core.misfit import objective

    data = ExperimentalData([1.0, 2.0, 3.0], [1.0, 2.0, 3.0], np.diag([0.1, 0.2, 0.3]),
                            (("global", 0, 2), ("local", 2, 3)))
    y = np.array([[1.5, 2.5, 3.5]])
    f_global, f_local = (objective(data.y[s], data.covariance[s, s], y[:, s])[0]
                         for s in (slice(0, 2), slice(2, 3)))
    weighted = data.weighted({"global": 0.5, "local": 4.0})
    assert objective(weighted.y, weighted.covariance, y)[0] == pytest.approx(0.5 * f_global + 4.0 * f_local)
    assert any("'local' weighted p = 4" in note for note in weighted.notes)
    with pytest.raises(DataError, match="'fpz'"):
        data.weighted({"fpz": 2.0})
    with pytest.raises(DataError, match="-1"):
        data.weighted({"local": -1.0})
