"""The formats ``fracid export --to`` writes (:data:`EXPORT_FORMATS`), one line each: a new format is a writer
module and a line here."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

from fracid.exchange.abaqus import write_abaqus
from fracid.exchange.csv_law import write_csv
from fracid.exchange.diana import write_diana

#: ``--as``: the crack as an interface with a traction-separation law, or smeared over a band of elements
REPRESENTATIONS = ("discrete", "smeared")


@dataclass(frozen=True)
class ExportFormat:
    """A format of ``fracid export``.

    Attributes
    ----------
    name : str
        What the file is for (e.g. ``"Abaqus"``).
    suffix : str
        The usual file name's suffix (``.inp``).
    write : callable
        ``write(identified, table, units, representation) -> str``: the file's text.
    representations : tuple of str
        The representations of :data:`REPRESENTATIONS` it writes.
    representations_note : str
        What each representation becomes in the code (``fracid export --help``, the docs).
    comment : str
        What starts a comment line in the file.
    """

    name: str
    suffix: str
    write: Callable
    representations: tuple
    representations_note: str
    comment: str


def _csv(identified, table, units, representation) -> str:
    return write_csv(identified, table, units)


#: ``--to`` of ``fracid export``: format name -> :class:`ExportFormat`
EXPORT_FORMATS = {
    "csv": ExportFormat("a CSV table", ".csv", _csv, REPRESENTATIONS,
                        "the traction-separation law (opening, traction), whatever the representation", "#"),
    "abaqus": ExportFormat("Abaqus", ".inp", write_abaqus, REPRESENTATIONS,
                           "discrete: a cohesive interface with tabular damage evolution; smeared: concrete damaged "
                           "plasticity with tension stiffening by cracking displacement", "**"),
    "diana": ExportFormat("DIANA", ".py", write_diana, ("smeared",),
                          "smeared only: the total strain crack model with its tension softening curve, as DIANA "
                          "Python commands; DIANA's interface elements are not written (their keywords were not "
                          "confirmed)", "#"),
}
