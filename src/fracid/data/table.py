"""A CSV data file read into a header and rows of cells, and the values of its named columns.

Rows are counted as the lines of the file: with the header on line 1, the first data row is row 2. Files are
UTF-8 (a BOM allowed); a UTF-16 file or another encoding is refused with the advice to save it as 'CSV UTF-8'.

Cell separator and decimal mark (:func:`check_format`): ``delimiter`` is ``","`` (default), ``";"``, ``"\\t"``
or ``" "`` (any run of spaces and tabs); ``decimal`` is ``"."`` (default) or ``","``. A header read as one cell
holding another separator is named as such (:func:`delimiter_hint`); the cells are read as numbers by
:mod:`fracid.data.cells`, whose messages name a wrong decimal mark or a thousands separator.

Lines above the header (:func:`read_table`): a first line ``sep=;`` (Excel's declaration of the cell
separator) is skipped if it agrees with ``delimiter`` and refused if it does not; the header is the first
line naming all the requested columns among the lines above the first data row, so that comment lines
(``# ...``, also a header written ``# cmod,F`` by ``numpy.savetxt``) and text lines of a test machine's
export (``Test 1, 2026-01-01``) above it are skipped, and listed in :meth:`CsvTable.notes`. Without a line
naming them, the header is the first line that is neither blank nor a comment, and a missing column names the
line that looks like the header instead.
"""

from __future__ import annotations

import csv
import difflib
import os
import re
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from fracid.data.arguments import shown
from fracid.data.cells import check_cell_count, is_number, parse_cell, trimmed
from fracid.data.errors import DataError, DataTypeError
from fracid.settings.checks import show

#: cell separators read by :func:`read_table`; " " splits at any run of spaces and tabs
DELIMITERS = (",", ";", "\t", " ")

#: decimal marks read by :func:`read_table`
DECIMALS = (".", ",")

#: Excel's first line declaring the cell separator, ``sep=;`` (quoted or followed by separators after a re-save)
_SEP_LINE = re.compile(r'^"?sep=(.)"?\1*\s*$')


@dataclass(frozen=True)
class CsvTable:
    """The cells of a data file as :func:`read_table` found them.

    Parameters
    ----------
    path : str
        The file.
    header : list of str
        Header cells, stripped (a comment header ``# a,b`` without its ``#``), trailing empty cells removed.
    header_line : int
        File line of the header (1-based).
    rows : list of (int, list of str)
        File line and cells of every data row (the lines after the header; blank lines at the end removed).
    skipped : tuple of int
        Lines above the header that were skipped: a ``sep=`` line, comments, text lines.
    other_header : (int, list of str) or None
        The last text line above the first data row when it is not the header: the line that looks like
        the header if a requested column is missing.
    """

    path: str
    header: list[str]
    header_line: int
    rows: list[tuple[int, list[str]]]
    skipped: tuple[int, ...] = ()
    other_header: tuple[int, list[str]] | None = None

    def notes(self) -> tuple[str, ...]:
        """The note on the skipped lines (empty if none)."""
        if not self.skipped:
            return ()
        lines = ", ".join(map(str, self.skipped))
        return (f"{self.path}: line{'s' if len(self.skipped) > 1 else ''} {lines} above the header (line "
                f"{self.header_line}) skipped (a sep= line, comments, text of the export)",)

    def missing_column(self, name: str, named: bool = True) -> str:
        """Why ``name`` is not a column: the header's line and columns, and the line that looks like
        the header instead if there is one (``named``: the name is said, else the message already said it;
        a long name is cut, :func:`fracid.settings.checks.show`)."""
        available = ", ".join(show(cell) for cell in self.header)
        column = f"column {show(name)}" if named else "such column"
        text = f"the header (line {self.header_line}) has no {column}; available columns: {available}"
        close = difflib.get_close_matches(name, self.header, n=1)
        if close:
            text += f"; did you mean {show(close[0])}?"
        if self.other_header is not None:
            line, cells = self.other_header
            text += (f"; if the header is not on line {self.header_line}: line {line}, the last text line above the "
                     f"data, looks like it ({', '.join(show(cell) for cell in cells)}) but names no {column} "
                     "either; give the column names as written there (lines above the line naming them are skipped)")
        return text


def check_format(delimiter, decimal) -> tuple[str, str]:
    """``delimiter`` and ``decimal`` checked: a separator of :data:`DELIMITERS` (or any other single
    character) and a decimal mark of :data:`DECIMALS`, the two different.

    Raises
    ------
    DataError
        If the delimiter is not one character, the decimal mark not "." or ",", or both are ",".
    """
    if not isinstance(delimiter, str) or not isinstance(decimal, str):
        raise DataTypeError(f"delimiter and decimal must be str, got {shown(delimiter)} and {shown(decimal)}")
    if len(delimiter) != 1:
        raise DataError(f"delimiter = {delimiter!r}: give one character, e.g. ',' ';' '\\t' or ' ' (whitespace)")
    if decimal not in DECIMALS:
        raise DataError(f"decimal = {decimal!r}: give '.' or ','")
    if decimal == delimiter:
        raise DataError(f"decimal = {decimal!r} and delimiter = {delimiter!r}: a comma cannot both separate the cells "
                        "and mark the decimals; files with decimal commas are separated by ';' or tabs")
    return delimiter, decimal


def iter_rows(lines, delimiter: str, first_line: int = 1):
    """(first file line, cells) of every row of an iterable of text lines (an open file) whose first line is
    line ``first_line``; ``delimiter`` " " splits at any run of whitespace, any other is read by
    :mod:`csv` (quotes allowed)."""
    if delimiter == " ":
        for number, line in enumerate(lines, start=first_line):
            yield number, line.split()
        return
    reader = csv.reader(lines, delimiter=delimiter)
    end = 0  # the last line of the previous row: a row with a quoted line break spans several lines
    for cells in reader:
        yield end + first_line, cells
        end = reader.line_num


def delimiter_hint(header: Sequence[str], delimiter: str) -> str | None:
    """The separator a file seems to use when its header, split by ``delimiter``, is one cell
    holding another separator (``"cmod_mm;F_N"`` read with ","); None otherwise."""
    if len(header) != 1:
        return None
    cell = header[0].strip()
    for candidate in (";", "\t", ",", " "):
        if candidate != delimiter and candidate in cell:
            return candidate
    return None


#: largest data file read [bytes]: its text lines and cells take about 10 times the file's size in memory, so
#: 200 MiB (about 3 million DIC points of 7 columns) is about 2 GiB read; a larger export is thinned or split
MAX_TABLE_BYTES = 200 * 2**20
#: bytes read at the start of a file to tell a binary file (a NUL byte) from text
SNIFF_BYTES = 65536


def check_text_file(path: str, limit: int = MAX_TABLE_BYTES) -> None:
    """Refuse, before reading it, a file larger than ``limit`` bytes or one whose first :data:`SNIFF_BYTES` hold a
    NUL byte (a binary file: a spreadsheet, an image, a MATLAB file, not CSV text).

    Raises
    ------
    DataError
        Naming the file, its size and the limit, or the NUL byte's offset, and what to do.
    """
    size = os.path.getsize(path)
    if size > limit:
        raise DataError(f"{path}: {size / 2**20:.0f} MiB, more than the {limit / 2**20:.0f} MiB a data file may have "
                        "(its text takes about 10 times its size in memory): export fewer points (a coarser DIC "
                        "step, a region of interest) or split it into one file per frame")
    with open(path, "rb") as handle:
        head = handle.read(SNIFF_BYTES)
    nul = head.find(b"\x00")
    if nul >= 0 and not head.startswith((b"\xff\xfe", b"\xfe\xff")):  # UTF-16 is named by the decoder
        raise DataError(f"{path}: a NUL byte at offset {nul}: a binary file, not CSV text; export "
                        "the data as CSV (text) from the program that wrote it")


def _text_lines(path: str) -> list[str]:
    """The lines of a UTF-8 text file (a BOM removed), line ends kept for :mod:`csv`; a file too large or binary
    refused first (:func:`check_text_file`)."""
    check_text_file(path)
    try:
        with open(path, newline="", encoding="utf-8-sig") as handle:
            return handle.readlines()
    except UnicodeDecodeError as error:
        raise DataError(f"{path}: not a UTF-8 text file ({error}); {_encoding_hint(path)}") from None


def _encoding_hint(path: str) -> str:
    """What to do with a file that is not UTF-8: UTF-16 (Excel's "Unicode Text") or another encoding."""
    with open(path, "rb") as handle:
        start = handle.read(2)
    if start in (b"\xff\xfe", b"\xfe\xff"):
        return "it is UTF-16 (a spreadsheet's 'Unicode Text'): save it as 'CSV UTF-8'"
    return "save it as 'CSV UTF-8' (a spreadsheet's Latin-1 or Windows-1252 text, e.g. with 'µm', is not read)"


def _declared_separator(path: str, lines: list[str], delimiter: str) -> int:
    """1 if the first line is Excel's ``sep=X`` agreeing with ``delimiter`` (skip it), 0 if there is none.

    Raises
    ------
    DataError
        If the declared separator is not ``delimiter``.
    """
    found = _SEP_LINE.match(lines[0].rstrip("\r\n")) if lines else None
    if found is None:
        return 0
    declared = found.group(1)
    if declared == delimiter or (delimiter == " " and declared == "\t"):
        return 1
    first = lines[0].rstrip("\r\n")
    raise DataError(f"{path}: line 1 ({first!r}) declares the cell separator {declared!r} (a spreadsheet's 'sep=' "
                    f"line), but the file is read with delimiter = {delimiter!r}: set delimiter = {declared!r}")


def _check_line_breaks(path: str, rows: list) -> None:
    """Refuse a row spanning several lines: a quote that is not closed, or a quoted cell with a line break."""
    for line, cells in rows:
        if any("\n" in cell or "\r" in cell for cell in cells):
            raise DataError(f"{path}: the row of line {line} runs over several lines: a quote '\"' opened on line "
                            f"{line} is not closed, or a quoted cell holds a line break; remove it")


def _row_kind(cells: list[str], decimal: str) -> str:
    """"blank", "comment" (first cell starts with #), "data" (all non-empty cells numbers) or "text"."""
    texts = [cell.strip() for cell in cells if cell.strip()]
    if not texts:
        return "blank"
    if texts[0].startswith("#"):
        return "comment"
    return "data" if all(is_number(text, decimal) for text in texts) else "text"


def _row_kinds(rows: list, decimal: str) -> list[str]:
    """:func:`_row_kind` of every row up to the first data row; after it, "blank" or "data" (the cells are
    read later)."""
    kinds, seen_data = [], False
    for _, cells in rows:
        if seen_data:
            kinds.append("data" if any(cell.strip() for cell in cells) else "blank")
        else:
            kinds.append(_row_kind(cells, decimal))
            seen_data = kinds[-1] == "data"
    return kinds


def _header_cells(cells: list[str]) -> list[str]:
    """Stripped header cells, a leading ``#`` (comment header) and trailing empty cells removed."""
    names = [cell.strip() for cell in trimmed(cells)]
    if names and names[0].startswith("#"):
        names[0] = names[0].lstrip("#").strip()
    return names


def _find_header(path: str, rows: list, kinds: list[str], columns: Sequence[str]) -> tuple[int, tuple | None]:
    """Index of the header among ``rows`` and the other line that looks like a header (see
    :class:`CsvTable`)."""
    first_data = next((k for k, kind in enumerate(kinds) if kind == "data"), len(rows))
    above = [k for k in range(first_data) if kinds[k] in ("text", "comment")]
    named = [k for k in above if columns and set(columns) <= set(_header_cells(rows[k][1]))]
    texts = [k for k in above if kinds[k] == "text"]
    if named:
        return named[0], None
    if not texts:
        if first_data == len(rows):
            raise DataError(f"{path}: the file is empty (no header row, no data)")
        line, cells = rows[first_data]
        comments = " (lines starting with # are comments)" if above else ""
        raise DataError(f"{path}: row {line} looks like data ({', '.join(cell.strip() for cell in cells)}); a header "
                        f"row naming the columns is required{comments}")
    other = rows[texts[-1]] if texts[-1] != texts[0] else None
    return texts[0], None if other is None else (other[0], _header_cells(other[1]))


def read_table(path: str, delimiter: str = ",", decimal: str = ".", columns: Sequence[str] = ()) -> CsvTable:
    """The header and data rows of a CSV file, with the lines above the header skipped.

    Parameters
    ----------
    path : str
        The file (UTF-8, a BOM allowed).
    delimiter, decimal : str
        Cell separator and decimal mark, checked by :func:`check_format`.
    columns : sequence of str
        The requested column names: the header is the first line above the data naming them all.

    Returns
    -------
    CsvTable

    Raises
    ------
    DataError
        If the file is not UTF-8 or not CSV, empty, has no header, a ``sep=`` line contradicting
        ``delimiter``, or a blank line between data rows.
    """
    lines = _text_lines(path)
    start = _declared_separator(path, lines, delimiter)
    try:
        rows = list(iter_rows(lines[start:], delimiter, first_line=start + 1))
    except csv.Error as error:
        odd_quotes = sum(line.count('"') for line in lines[start:]) % 2  # the file says it, not the error's text
        unclosed = "; a quote '\"' that is not closed makes the rest of the file one cell" if odd_quotes else ""
        raise DataError(f"{path}: not a readable CSV file ({error}){unclosed}") from None
    _check_line_breaks(path, rows)
    kinds = _row_kinds(rows, decimal)
    while kinds and kinds[-1] == "blank":
        rows.pop()
        kinds.pop()
    k, other = _find_header(path, rows, kinds, columns)
    for (line, _), kind in zip(rows[k + 1:], kinds[k + 1:]):
        if kind == "blank":
            raise DataError(f"{path}: row {line} is empty, between data rows")
    skipped = (*range(1, start + 1), *(line for (line, _), kind in zip(rows[:k], kinds[:k]) if kind != "blank"))
    return CsvTable(path, _header_cells(rows[k][1]), rows[k][0], rows[k + 1:], skipped, other)


def column_indices(table: CsvTable, wanted: list[str], delimiter: str = ",") -> list[int]:
    """Index in ``table.header`` of each name of ``wanted``; a missing name gets the message of
    :meth:`CsvTable.missing_column`, or of :func:`delimiter_hint` if the header is one cell."""
    indices = []
    for name in wanted:
        hits = [k for k, cell in enumerate(table.header) if cell == name]
        if not hits:
            guess = delimiter_hint(table.header, delimiter)
            if guess is not None:
                raise DataError(
                    f"{table.path}: the header is one cell {show(table.header[0])} when split by delimiter = "
                    f"{delimiter!r}: the file seems to be separated by {guess!r}; give delimiter = {guess!r} "
                    "(and decimal = \",\" for decimal commas)"
                )
            raise DataError(f"{table.path}: {table.missing_column(name)}")
        if len(hits) > 1:
            raise DataError(f"{table.path}: the header names column {show(name)} {len(hits)} times; it is ambiguous")
        indices.append(hits[0])
    return indices


def parse_table(
    table: CsvTable,
    names: list[str],
    indices: list[int],
    decimal: str = ".",
    delimiter: str = ",",
) -> tuple[np.ndarray, np.ndarray]:
    """Values (n_rows, n_columns) of the requested columns and the file row of each data row."""
    values = np.empty((len(table.rows), len(names)))
    lines = np.empty(len(table.rows), dtype=int)
    for r, (line, cells) in enumerate(table.rows):
        check_cell_count(table.path, line, cells, table.header, delimiter, decimal)
        lines[r] = line
        for c, (name, index) in enumerate(zip(names, indices)):
            values[r, c] = parse_cell(table.path, line, name, cells[index], decimal, delimiter)
    return values, lines
