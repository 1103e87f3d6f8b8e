"""fracid.store.tables: CSV that spreadsheets read back cell for cell, and JSON without NaN."""

import csv
import json
import math

import numpy as np

from fracid.store.tables import cell, without_nan, write_csv_table


def test_names_with_commas_quotes_and_line_breaks_come_back_as_one_cell(tmp_path):
    names = ['beam "A", 2026', "two\nlines", "plain", "tab\there"]
    path = write_csv_table(tmp_path / "t.csv", ["x", "name"], [[float(i), n] for i, n in enumerate(names)])
    with open(path, newline="", encoding="utf-8") as handle:
        rows = list(csv.reader(handle))
    assert rows[0] == ["x", "name"]
    assert [r[1] for r in rows[1:]] == names
    assert [float(r[0]) for r in rows[1:]] == [0.0, 1.0, 2.0, 3.0]


def test_text_a_spreadsheet_would_evaluate_is_quoted_but_numbers_are_not():
    for text in ("=1+1", "+A1", "-2+3", "@SUM(A1)", "\t=x", "\r=x"):
        assert cell(text) == "'" + text
    assert cell(-2.5) == "-2.5" and cell(np.float64(-1e-5)) == "-1e-05" and cell(3) == "3"
    assert cell("a=b") == "a=b"


def test_missing_and_infinite_values_are_empty_cells(tmp_path):
    assert cell(math.inf) == "" and cell(-math.inf) == "" and cell(math.nan) == ""
    path = write_csv_table(tmp_path / "p.csv", ["c", "f", "status"], [[1.0, math.inf, "failed"], [2.0, 0.5, "ok"]])
    assert path.read_text().splitlines() == ["c,f,status", "1,,failed", "2,0.5,ok"]


def test_json_without_nan_is_valid_json_and_keeps_the_finite_values():
    value = {"a": [1.0, math.nan, np.float64(2.5)], "b": (np.int64(3), math.inf), "c": {"d": -math.inf, "e": "x"},
             "f": True}
    plain = without_nan(value)
    assert plain == {"a": [1.0, None, 2.5], "b": [3, None], "c": {"d": None, "e": "x"}, "f": True}
    assert json.loads(json.dumps(plain, allow_nan=False)) == plain
