"""Validation shared by the specimen dataclasses."""

from __future__ import annotations

import math


def require_positive(specimen, names, unit: str = "") -> None:
    """Raise ValueError naming the class, field and value unless every field in ``names`` is a
    positive finite number (``unit``, e.g. ``" [mm]"``, ends the message)."""
    for name in names:
        value = getattr(specimen, name)
        if not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0):
            raise ValueError(f"{type(specimen).__name__}.{name} = {value!r}; it must be a positive number{unit}")
