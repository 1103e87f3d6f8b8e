"""The values every experiment kind's table shares: the units of its columns with their scale to mm and N,
the cell separators and decimal marks of its data files, the roles of a block, and the keys every block has
(:data:`BLOCK_KEYS`, described once: :class:`~fracid.settings.keys.Key`).

Imports nothing of fracid but :mod:`fracid.settings.keys`.
"""

from __future__ import annotations

from fracid.settings.keys import Key

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

__all__ = ["BLOCK_KEYS", "CONTROL_UNITS", "DECIMALS", "DELIMITERS", "FORCE_UNITS", "LOCAL_UNITS", "ROLES"]
