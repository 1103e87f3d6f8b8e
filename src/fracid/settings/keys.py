"""The description of a configuration key, declared where the key is: its default, unit, allowed values and
meaning (:class:`Key`). A section's keys are a mapping key -> Key whose keys are the ones the section's checker
accepts (``tuple(mapping)``), so that the configuration reference (:mod:`fracid.config.reference`), ``fracid
init``'s comments and the checker read one declaration.

A key of a settings class (a frozen dataclass with a numpydoc ``Parameters`` or ``Attributes`` section) takes its
meaning, and its default where it is the class's, from that class (:func:`described`): the text of a key lives
in one place.

Imports nothing of fracid outside :mod:`fracid.settings`.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Mapping
from dataclasses import dataclass

from fracid.settings.checks import toml_value
from fracid.settings.docstrings import documented

class Said(str):
    """A default said in words, not a TOML value (``Said("the specimen's first control")``): shown as it is where
    a value would be shown as TOML."""


#: the default of a key that must be given
REQUIRED = Said("required")
#: the default of a key that may be left out and has no value then (the meaning says what happens)
UNSET = Said("not set")
#: the default of a key that is its settings class's field default (:func:`described`)
FROM_CLASS = Said("from the class")


@dataclass(frozen=True)
class Key:
    """One configuration key.

    Parameters
    ----------
    default : object
        The value taken when the key is left out (a TOML value), or in words (:class:`Said`): :data:`REQUIRED`
        (must be given), :data:`UNSET` (no value), :data:`FROM_CLASS` (the settings class's field default, filled
        in by :func:`described`).
    unit : str
        The unit of a number (``"mm"``, ``"N"``, ``"-"`` for a ratio); empty for a word, a name or a path.
    allowed : str or callable
        The values allowed in words (``"integer >= 2"``, ``'"sobol" | "lhs" | "grid"'``); a callable returns
        them when asked (a registry's names, read when the reference is built).
    meaning : str
        What the key sets; empty: the numpydoc entry of the settings class's field of the same name
        (:func:`described`).
    """

    default: object = UNSET
    unit: str = ""
    allowed: str | Callable = ""
    meaning: str = ""

    def default_text(self) -> str:
        """``default`` as written in a configuration (TOML), or its words (:class:`Said`)."""
        if isinstance(self.default, Said):
            return str(self.default)
        if isinstance(self.default, float) and len(repr(self.default)) > 10:  # 1/3: 0.333333, still a TOML float
            return f"{self.default:.6g}"
        return toml_value(self.default)

    def allowed_text(self) -> str:
        """``allowed`` in words (a callable asked now)."""
        return self.allowed() if callable(self.allowed) else self.allowed


def described(keys: Mapping, cls=None) -> dict:
    """``keys`` (key -> :class:`Key`) with their empty meanings read from the numpydoc ``Parameters`` /
    ``Attributes`` entry of ``cls``'s field of the same name and their :data:`FROM_CLASS` defaults from its
    dataclass fields; without ``cls`` the mapping as it is. A key left without meaning stays empty (the
    reference's test names it)."""
    if cls is None:
        return dict(keys)
    docs = documented(cls)
    fields = {f.name: f for f in dataclasses.fields(cls)} if dataclasses.is_dataclass(cls) else {}
    out = {}
    for name, key in keys.items():
        default = key.default
        if default is FROM_CLASS and name in fields and fields[name].default is not dataclasses.MISSING:
            default = fields[name].default
        meaning = key.meaning or docs.get(name, ("", ""))[1]
        out[name] = dataclasses.replace(key, default=default, meaning=meaning)
    return out


__all__ = ["FROM_CLASS", "Key", "REQUIRED", "Said", "UNSET", "described"]
