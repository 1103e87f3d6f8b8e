"""Result tables as files. CSV as spreadsheets read it: written with the :mod:`csv` module (a name holding
a comma, a quote or a line break stays one cell), numbers to 9 significant digits, a missing value (NaN,
a failed run's infinite objective) as an empty cell, and text that a spreadsheet would take for a formula
(``=``, ``+``, ``-``, ``@`` first) quoted with ``'``. JSON without NaN, which JSON does not have: null.
"""

from __future__ import annotations

import csv
import math
import numbers
from pathlib import Path
from typing import Iterable, Sequence

#: first characters that make a spreadsheet evaluate a cell (OWASP's "CSV injection")
_FORMULA_START = ("=", "+", "-", "@", "\t", "\r")


def cell(value) -> str:
    """The text of one cell: a number to 9 significant digits ('' if it is not finite), or safe text."""
    if isinstance(value, numbers.Real) and not isinstance(value, bool):
        return f"{value:.9g}" if math.isfinite(value) else ""
    text = str(value)
    return "'" + text if text.startswith(_FORMULA_START) else text


def write_csv_table(path, header: Sequence[str], rows: Iterable[Sequence]) -> Path:
    """Write ``header`` and ``rows`` (numbers or text) to ``path`` as RFC 4180 CSV; returns the path."""
    path = Path(path)
    with open(path, "w", newline="", encoding="utf-8") as handle:
        writer = csv.writer(handle, lineterminator="\n")
        writer.writerow([cell(h) for h in header])
        writer.writerows([cell(v) for v in row] for row in rows)
    return path


def without_nan(value):
    """``value`` (dicts, lists, tuples, numbers, strings) as plain JSON types, every non-finite number None."""
    if isinstance(value, dict):
        return {k: without_nan(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [without_nan(v) for v in value]
    if isinstance(value, numbers.Integral) and not isinstance(value, bool):
        return int(value)
    if isinstance(value, numbers.Real) and not isinstance(value, bool):
        return float(value) if math.isfinite(value) else None
    return value
