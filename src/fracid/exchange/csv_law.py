"""The traction-separation law as a plain CSV table (opening, traction) for any code, and its reader
(:func:`read_law_csv`), which turns a table back into a law fracid's crack models run
(:class:`~fracid.fem.material.tabular_law.TabularSoftening`)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from fracid.exchange.header import header_lines
from fracid.runtime.exits import UsageError


def write_csv(identified, table, units) -> str:
    """The CSV text: ``#`` comment lines (:func:`~fracid.exchange.header.header_lines`), then
    ``opening_<length>,traction_<stress>`` and one row per point."""
    head = header_lines(identified, table, units, "traction-separation law (opening, traction) as a table")
    converted = table.scaled(units.to_length, units.to_stress)
    rows = [f"{a:.9g},{b:.9g}" for a, b in zip(converted.opening, converted.traction)]
    return "\n".join([*(f"# {line}" for line in head), f"opening_{units.length},traction_{units.stress}", *rows]) + "\n"


def read_law_csv(path) -> tuple[np.ndarray, np.ndarray]:
    """(opening, traction) of a CSV table written by :func:`write_csv` (``#`` comments, a header row, two
    columns), in the file's own units.

    Raises
    ------
    UsageError
        Naming the file and what is wrong with it.
    """
    path = Path(path)
    try:
        lines = [line for line in path.read_text(encoding="utf-8").splitlines() if line.strip()
                 and not line.startswith("#")]
        table = np.array([[float(v) for v in line.split(",")] for line in lines[1:]])
    except (OSError, UnicodeDecodeError) as err:
        raise UsageError(f"{path}: cannot read the law's table: {err}") from None
    except ValueError as err:
        raise UsageError(f"{path}: the rows after the header must be two numbers: {err}") from None
    if table.ndim != 2 or table.shape[1] != 2 or table.shape[0] < 2:
        raise UsageError(f"{path}: the law's table needs two columns (opening, traction) and at least 2 rows")
    return table[:, 0], table[:, 1]
