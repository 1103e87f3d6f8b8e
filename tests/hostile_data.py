"""Hostile-input cases (data files: signs, order, separators, spreadsheet exports, comment lines, swapped columns);
run by tests/test_hostile_inputs.py. Each ends while the data are loaded: exit 2 naming the file, the line and the
fix, or (``reads-*``) the data are read and the output path, a file, ends the command with exit 4."""

from __future__ import annotations

from hostile import IDENTIFY, REACHES_OUTPUT, Case, _cells, _out_is_file, case, csv_case, write_csv


def _negated(control_sign, force_sign):
    """The standard file with its control and force columns multiplied by these signs."""
    return lambda d, c: write_csv(d / "bar.csv", control_sign * c[0], force_sign * c[1])


def _reversed(curve):
    """The rows of the standard file last first (a table exported in reverse order), the header on top."""
    rows = _cells(curve)
    return [rows[0], *rows[:0:-1]]


def _swapped(curve):
    """The header as before, the cells of the two columns swapped: "u_mm" holds the forces."""
    rows = _cells(curve)
    return [rows[0], *([force, control] for control, force in rows[1:])]


def _lines(*above, header=None, cell=None, sep=",", decimal=".", end=""):
    """The standard file with ``above`` lines before the header (``header``: another header line), separated by
    ``sep`` with ``decimal``, ``end`` after every line and ``cell`` (a text) as the force of data row 30 (file
    line 32 when nothing is above)."""
    def edit(i, row):
        row = [number.replace(".", decimal) for number in row]
        return [row[0], cell] if i == 30 and cell is not None else row

    def csv(d, curve):
        rows = _cells(curve, edit)
        lines = [header or sep.join(rows[0]), *(sep.join(row) for row in rows[1:])]
        (d / "bar.csv").write_text("\n".join([*above, *(line + end for line in lines)]) + "\n", encoding="utf-8")
    return csv


def _utf16(d, curve):
    """The standard file saved as a spreadsheet's "Unicode Text": UTF-16 with its byte order mark."""
    write_csv(d / "bar.csv", *curve)
    (d / "bar.csv").write_bytes((d / "bar.csv").read_text().encode("utf-16"))


def _reads(csv, **config) -> Case:
    """A data file that must be read: the command reaches the output path, a file ("taken is a file")."""
    return case(4, ["taken is a file"], csv=csv, config=config or None, files=_out_is_file,
                args=("identify", "cfg.toml", *REACHES_OUTPUT))


SEMICOLON = {"experiment": 'delimiter = ";"\ndecimal = ","'}

CASES = {
    # ---- signs: checked before the order of the rows (not "raise backtrack_tolerance")
    "data-negative-tension-test": case(2, ["'u_mm' is negative", 'negate = ["control"]', "'F_N' is negative too"],
                                       csv=_negated(-1, -1), args=IDENTIFY),
    "data-negative-control-only": case(2, ["'u_mm' is negative", "multiply it by -1"], csv=_negated(-1, 1),
                                       args=IDENTIFY),
    "data-negative-tension-test-negated-by-the-config": case(
        4, ["taken is a file"], csv=_negated(-1, -1), config={"experiment": 'negate = ["control", "force"]'},
        files=_out_is_file, args=("identify", "cfg.toml", *REACHES_OUTPUT)),
    "data-negate-unknown-column": case(2, ["experiments[0].negate", '"control" and/or "force"'],
                                       config={"experiment": 'negate = ["cmod"]'}),
    # ---- order and columns
    "data-rows-in-reverse-order": csv_case(2, ["reverse order", "'u_mm'", "sort them"], rows=_reversed, args=IDENTIFY),
    "data-swapped-columns": csv_case(2, ["look swapped", "control_column = 'F_N'", "'u_mm'"], rows=_swapped,
                                     args=IDENTIFY),
    # ---- thousands separators: the line, the cell and the separator to remove
    "data-thousands-separator-quoted": case(2, ["row 32", "'F_N'", "'1,234.5'", "thousands separator"],
                                            csv=_lines(cell='"1,234.5"'), args=IDENTIFY),
    "data-thousands-separator-unquoted": case(2, ["row 32", "3 cells", "'1,234.5'", "thousands separator"],
                                              csv=_lines(cell="1,234.5"), args=IDENTIFY),
    "data-thousands-space-decimal-comma": case(2, ["row 32", "'1 234,5'", "thousands separator"], config=SEMICOLON,
                                               csv=_lines(cell="1 234,5", sep=";", decimal=","), args=IDENTIFY),
    "data-thousands-point-decimal-comma": case(2, ["row 32", "'1.234,5'", "thousands separator"], config=SEMICOLON,
                                               csv=_lines(cell="1.234,5", sep=";", decimal=","), args=IDENTIFY),
    # ---- spreadsheet and machine exports: read, or refused naming the line
    "reads-excel-sep-line": _reads(_lines("sep=,")),
    "reads-excel-sep-semicolon-line": _reads(_lines("sep=;", sep=";", decimal=","), **SEMICOLON),
    "data-excel-sep-contradicts-delimiter": case(2, ["experiments[0].file", "line 1", "sep=;", "delimiter = ';'"],
                                                 csv=_lines("sep=;", sep=";", decimal=",")),
    "reads-comment-line-above-header": _reads(_lines("# exported by Instron Bluehill 3")),
    "reads-text-lines-above-header": _reads(_lines("Test 1, 2026-01-01", "Specimen,B4")),
    "reads-numpy-savetxt-header": _reads(_lines(header="# u_mm,F_N")),
    "data-header-not-on-line-1": case(2, ["experiments[0].control_column", "line 1", "line 2", "looks like it",
                                          "'Extension'"], csv=_lines("Test 1, 2026-01-01", header="Extension,Load")),
    "reads-trailing-empty-cells": _reads(_lines(end=",,")),
    "data-unclosed-quote": csv_case(2, ["line 32", "quote", "not closed"],
                                    lambda i, row: [row[0], '"' + row[1]] if i == 30 else row, args=IDENTIFY),
    "data-utf16-unicode-text": case(2, ["experiments[0].file", "UTF-16", "CSV UTF-8"], csv=_utf16),
}
