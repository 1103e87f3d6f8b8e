"""The values every experiment kind's table shares: the units of its columns with their scale to mm and N,
the cell separators and decimal marks of its data files, and the roles of a block.

Imports nothing of fracid.
"""

from __future__ import annotations

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

__all__ = ["CONTROL_UNITS", "DECIMALS", "DELIMITERS", "FORCE_UNITS", "LOCAL_UNITS", "ROLES"]
