"""The values every experiment kind's table shares: the units of its columns with their scale to mm and N,
the cell separators and decimal marks of its data files, the roles of a block, and the keys every block has
(:data:`BLOCK_KEYS`, described once: :class:`~fracid.settings.keys.Key`).

Imports nothing of fracid but :mod:`fracid.settings.keys`.
"""

from __future__ import annotations

from fracid.settings.keys import Key


def choices_text(values) -> str:
    """The allowed values of a key as its description writes them: ``"a" | "b"``."""
    return " | ".join(f'"{value}"' for value in values)

#: ``control_unit`` -> multiplier to mm
CONTROL_UNITS = {"mm": 1.0, "um": 1e-3, "m": 1e3}
#: ``delimiter`` values -> the cell separator ("tab" spells a tab; " " is any run of whitespace)
DELIMITERS = {",": ",", ";": ";", "\t": "\t", "tab": "\t", " ": " "}
DECIMALS = (".", ",")
#: ``force_unit`` of a force -> multiplier to N
FORCE_UNITS = {"N": 1.0, "kN": 1e3, "MN": 1e6}
#: ``force_unit`` of a local quantity (a length) -> multiplier to mm
LOCAL_UNITS = dict(CONTROL_UNITS)
#: "source": read and checked, neither calibrated on nor predicted: the field a derived block comes from
ROLES = ("calibration", "prediction", "source")

#: the keys every kind's block takes besides its own: their descriptions (a block's ``name`` is its kind's)
BLOCK_KEYS = {
    "weight": Key(1.0, "-", "> 0", "The block's weight p_b in the objective f = sum p_b f_b: its covariance is divided "
                                   "by p_b."),
    "role": Key(ROLES[0], "", " | ".join(f'"{role}"' for role in ROLES),
                '"calibration": calibrated on; "prediction": predicted at the estimate by `fracid study`, not '
                'calibrated on; "source": read and checked only (the field a derived block comes from).'),
}

#: the keys of a block read from delimited text files: its cells' separator and decimal mark
FORMAT_KEYS = {
    "delimiter": Key(",", "", '"," | ";" | "\\t" (or "tab") | " " (any run of spaces and tabs)',
                     "The cell separator of the files."),
    "decimal": Key(".", "", " | ".join(f'"{mark}"' for mark in DECIMALS),
                   'The decimal mark ("," needs another delimiter).'),
}


def file_format(ck, prefix: str, raw: dict, stem: str = "", default: tuple = (",", ".")) -> tuple[str, str]:
    """(cell separator, decimal mark) of the data files: ``delimiter`` and ``decimal``
    (``ck``: the configuration checker), or the keys of another file named with ``stem`` (``log_delimiter``),
    ``default`` when not given."""
    delimiter = raw.get(f"{stem}delimiter", default[0])
    if not isinstance(delimiter, str) or delimiter not in DELIMITERS:
        ck.fail(f"{prefix}.{stem}delimiter", delimiter, 'must be one of ",", ";", "\\t" (or "tab"), " " (any run '
                                                        "of spaces and tabs); the cell separator of the file")
    delimiter = DELIMITERS[delimiter]
    decimal = ck.choice(f"{prefix}.{stem}decimal", raw.get(f"{stem}decimal", default[1]), DECIMALS)
    if decimal == delimiter:
        ck.fail(f"{prefix}.{stem}decimal", decimal, 'a decimal comma needs another delimiter: with delimiter = "," (the '
                                              'default) a comma cannot also mark the decimals; files with decimal '
                                              'commas are separated by ";" or tabs: set delimiter = ";" or "tab"')
    return delimiter, decimal


__all__ = ["choices_text", "BLOCK_KEYS", "CONTROL_UNITS", "DECIMALS", "DELIMITERS", "FORCE_UNITS", "FORMAT_KEYS", "LOCAL_UNITS", "ROLES",
           "file_format"]
