"""The cells of a row of a CSV file read as numbers, and why a cell is not one.

The decimal mark ``decimal`` is ``"."`` or ``","`` (decimal commas, e.g. ``0,001``; then a ``"."`` in a
number is refused: it would be a thousands separator). A number read with the wrong decimal mark gets a
message saying which one the file seems to use; a number written with a thousands separator (``"1,234.5"``,
``1 234,5``, ``1.234,5``) is refused, naming its row, column and the separator to remove. Empty cells after
the last column (``0.1,2.0,``) are ignored.
"""

from __future__ import annotations

import math
import re
from collections.abc import Sequence

from fracid.data.errors import DataError
from fracid.settings.checks import show

#: the advice for a number written with thousands separators
_REMOVE_THOUSANDS = "remove the thousands separators ({}; in a spreadsheet: a number format without them)"

#: a number written with a decimal comma (``0,001``, ``-12,5e3``)
_DECIMAL_COMMA = re.compile(r"^[+-]?\d*,\d+(?:[eE][+-]?\d+)?$")

#: a run of digits: the pieces a comma-separated file makes of decimal-comma numbers
_DIGITS = re.compile(r"^[+-]?\d+(?:[eE][+-]?\d+)?$")

#: decimal mark -> a number with thousands separators (group 1) and that decimal mark: ``1,234.5``, ``1 234,5``
_THOUSANDS = {
    ".": re.compile(r"^[+-]?[1-9]\d{0,2}([, \u00a0\u202f'])\d{3}(?:\1\d{3})*(?:\.\d*)?$"),
    ",": re.compile(r"^[+-]?[1-9]\d{0,2}([. \u00a0\u202f'])\d{3}(?:\1\d{3})*(?:,\d*)?$"),
}

#: the pieces of ``1,234.5`` split at its thousands separator by a comma-separated file
_THOUSANDS_HEAD = re.compile(r"^[+-]?[1-9]\d{0,2}$")
_THOUSANDS_TAIL = re.compile(r"^\d{3}(?:\.\d*)?$")

#: thousands separators as named in messages
_SEPARATOR_NAMES = {",": "','", ".": "'.'", " ": "spaces", "\u00a0": "non-breaking spaces",
                    "\u202f": "narrow non-breaking spaces", "'": "apostrophes"}


def trimmed(cells: Sequence[str]) -> list[str]:
    """The cells without the empty cells at the end of the row (``0.1,2.0,,`` written by spreadsheets)."""
    cells = list(cells)
    while cells and not cells[-1].strip():
        cells.pop()
    return cells


def _to_float(text: str, decimal: str) -> float:
    """``float`` of a stripped cell with the given decimal mark (ValueError if it is not a number)."""
    if decimal == ",":
        if "." in text:
            raise ValueError(text)
        text = text.replace(",", ".")
    return float(text)


def is_number(text: str, decimal: str = ".") -> bool:
    """Whether a cell is a number written with the decimal mark ``decimal``."""
    try:
        _to_float(text.strip(), decimal)
    except ValueError:
        return False
    return True


def decimal_comma_hint(cells: Sequence[str], delimiter: str, decimal: str, n_header: int) -> str | None:
    """Why the numbers of a data row cannot be read if they seem to have decimal commas, else None.

    Either cells such as ``0,001`` read with decimal ".", or (delimiter ",") a row split into more
    cells than the header, all of them digits: the pieces of decimal-comma numbers.
    """
    if decimal != ".":
        return None
    cells = trimmed(cells)
    texts = [cell.strip() for cell in cells if cell.strip()]
    if delimiter != "," and any(_DECIMAL_COMMA.match(text) for text in texts):
        example = next(text for text in texts if _DECIMAL_COMMA.match(text))
        return f'numbers such as {example!r} have decimal commas: set decimal = ","'
    if delimiter == "," and len(cells) > n_header and texts and all(_DIGITS.match(text) for text in texts):
        return ("the row has more cells than the header, all digits: the numbers seem to have decimal commas, "
                "which a comma-separated file cannot hold; save the file separated by ';' and set "
                'delimiter = ";" and decimal = ","')
    return None


def _split_thousands_hint(cells: Sequence[str], delimiter: str, n_header: int) -> str | None:
    """Why a comma-separated row has more cells than the header if an unquoted number such as
    ``1,234.5`` was split at its thousands separator, else None."""
    texts = [cell.strip() for cell in trimmed(cells)]
    if delimiter != "," or len(texts) <= n_header:
        return None
    for head, tail in zip(texts, texts[1:]):
        if _THOUSANDS_HEAD.match(head) and _THOUSANDS_TAIL.match(tail):
            return (f"numbers such as '{head},{tail}' seem written with a thousands separator ',', which splits them "
                    f"into two cells; {_REMOVE_THOUSANDS.format(',')}")
    return None


def _thousands_hint(text: str, decimal: str) -> str | None:
    """Advice for a cell that is a number written with a thousands separator (``1,234.5``, ``1 234,5``,
    ``1.234,5``), else None."""
    for mark, pattern in _THOUSANDS.items():
        found = pattern.match(text)
        if found is None:
            continue
        separator = found.group(1)
        advice = _REMOVE_THOUSANDS.format(_SEPARATOR_NAMES.get(separator, repr(separator)))
        if mark != decimal and mark in text:
            advice += f" and set decimal = {mark!r}"
        return f"{text!r} seems written with a thousands separator: {advice}"
    return None


def _number_hint(text: str, delimiter: str, decimal: str) -> str | None:
    """Why a cell is not a number, if a decimal mark or a thousands separator explains it, else None."""
    hint = decimal_comma_hint([text], delimiter, decimal, 1) or _thousands_hint(text, decimal)
    if hint is None and decimal == "," and "." in text:
        hint = 'with decimal = "," a "." is not allowed in a number; if the file has decimal points, set decimal = "."'
    elif decimal == "," and "." in text:
        hint = f'with decimal = "," a "." is not allowed in a number: {hint}'
    return hint


def parse_cell(path: str, line: int, column: str, text: str, decimal: str = ".", delimiter: str = ",") -> float:
    """The number of a cell, else a DataError naming the file, its row and column, and the cause if known."""
    stripped = text.strip()
    if not stripped:
        raise DataError(f"{path}: row {line}, column {show(column)}: empty cell (missing value)")
    try:
        value = _to_float(stripped, decimal)
    except ValueError:
        hint = _number_hint(stripped, delimiter, decimal)
        raise DataError(
            f"{path}: row {line}, column {show(column)}: {stripped!r} is not a number" + (f"; {hint}" if hint else "")
        ) from None
    if math.isnan(value):
        raise DataError(f"{path}: row {line}, column {show(column)}: missing value ({stripped!r})")
    if math.isinf(value):
        raise DataError(f"{path}: row {line}, column {show(column)}: {stripped!r} is not finite")
    return value


def check_cell_count(path: str, line: int, cells: list[str], header: list[str], delimiter: str, decimal: str):
    """Refuse a row with fewer cells than the header, or more unless the extra cells are empty."""
    if len(header) in (len(cells), len(trimmed(cells))):
        return
    hint = decimal_comma_hint(cells, delimiter, decimal, len(header)) or _split_thousands_hint(
        cells, delimiter, len(header))
    raise DataError(
        f"{path}: row {line} has {len(cells)} cells but the header has {len(header)} "
        f"({', '.join(show(cell) for cell in header)})" + (f"; {hint}" if hint else "")
    )
