"""Validation shared by the specimen dataclasses."""

from __future__ import annotations

import math

from fracid.settings.field_error import FieldError


def require_positive(specimen, names, unit: str = "") -> None:
    """Raise ValueError naming the class, field and value unless every field in ``names`` is a
    positive finite number (``unit``, e.g. ``" [mm]"``, ends the message)."""
    for name in names:
        value = getattr(specimen, name)
        if not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0):
            raise FieldError(name, value,
                             f"{type(specimen).__name__}.{name} = {value!r}; it must be a positive number{unit}")


def resolve_defaults(specimen, defaults) -> None:
    """Set every field named in ``defaults`` {name: callable() -> float} that is None to its derived
    value [mm], on a frozen dataclass.

    The specimen then holds the numbers its mesh uses, so its equality, its repr and its run key
    (:func:`fracid.store.runs.key_for`) are those of a specimen given these numbers explicitly.
    ``dataclasses.replace`` copies the resolved numbers: build a new specimen to derive them afresh.
    """
    for name, derive in defaults.items():
        if getattr(specimen, name) is None:
            object.__setattr__(specimen, name, float(derive()))
