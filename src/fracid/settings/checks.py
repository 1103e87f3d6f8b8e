"""The settings an inverse method reads from the configuration's ``[identify.<table>]`` tables, checked by
the method itself.

A method's ``from_config(tables, context)`` validates its tables with the small pure checkers of this
module (:func:`table`, :func:`integer`, :func:`number`, :func:`choice`); each raises a :class:`SettingError`
naming the key relative to ``[identify]`` (``"knn.n"``), the value and what is allowed, which the
configuration turns into its message (``<file>: identify.knn.n = 1: must be an integer >= 2``). The
configuration's own checker (:class:`fracid.config.checker.Checker`) uses the same checkers, so a value is
judged the same way in every section. :func:`toml_line` writes a ``key = value  # comment`` line of the
configuration ``fracid init`` generates (a method's ``config_template``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass


class SettingError(ValueError):
    """A setting of the configuration refused.

    Parameters
    ----------
    key : str
        The dotted key, relative to the section being read (``"knn.n"``, ``"gauss-newton.tol"``, a table
        name); the configuration prefixes it (``identify.knn.n``).
    value : object
        The value given.
    allowed : str
        What is allowed (the text after ``key = value: `` in the message).
    """

    def __init__(self, key: str, value, allowed: str):
        super().__init__(f"{key} = {show(value)}: {allowed}")
        self.key, self.value, self.allowed = key, value, allowed


@dataclass(frozen=True)
class SettingsContext:
    """What a method's ``from_config`` may need besides its tables.

    Attributes
    ----------
    n_y : int or None
        Total number of data values calibrated on (the sum of the experiments' ``n_points``); None when
        unknown.
    parameters : tuple of str
        The identified parameters' names (``[identify] parameters``).
    """

    n_y: int | None = None
    parameters: tuple = ()


def show(value) -> str:
    """``value`` as a message shows it: ``repr``, or ``a table {a, b}`` for a dict; at most 200 characters."""
    text = "a table {" + ", ".join(value) + "}" if isinstance(value, dict) else repr(value)
    return text if len(text) <= 200 else text[:197] + "..."


def bytes_text(n: float) -> str:
    """A memory size in words: ``18.6 GiB``, ``195 MiB``, ``12 KiB``."""
    for unit, size in (("TiB", 2**40), ("GiB", 2**30), ("MiB", 2**20), ("KiB", 2**10)):
        if n >= size:
            return f"{n / size:.3g} {unit}"
    return f"{n:.0f} bytes"


def is_number(value) -> bool:
    """Whether ``value`` is a finite int or float (a bool is not a number)."""
    return not isinstance(value, bool) and isinstance(value, (int, float)) and math.isfinite(value)


def is_integer(value) -> bool:
    """Whether ``value`` is an int (a bool is not, nor a float such as 3.0)."""
    return not isinstance(value, bool) and isinstance(value, int)


def table(key: str, raw, allowed_keys) -> dict:
    """``raw`` if it is a table (dict) whose keys are all in ``allowed_keys``.

    Raises
    ------
    SettingError
        ``key`` when ``raw`` is not a dict; ``key.<k>`` for the first unknown key ``k`` (``<k>`` alone when
        ``key`` is empty).
    """
    if not isinstance(raw, dict):
        raise SettingError(key, raw, f"must be a table (section) with keys {', '.join(allowed_keys)}")
    prefix = f"{key}." if key else ""
    for name, value in raw.items():
        if name not in allowed_keys:
            raise SettingError(prefix + name, value, f"unknown key; allowed keys here: {', '.join(allowed_keys)}")
    return raw


def integer(key: str, value, allowed: str = "must be an integer", ok=lambda v: True) -> int:
    """``value`` as an int if it is an integer (not a bool, not a float) and ``ok(value)``; else
    :class:`SettingError` with ``allowed``."""
    if not is_integer(value) or not ok(value):
        raise SettingError(key, value, allowed)
    return int(value)


def number(key: str, value, allowed: str = "must be a number", ok=lambda v: True) -> float:
    """``value`` as a float if it is a finite number (an int or a float, not a bool) and ``ok(value)``; else
    :class:`SettingError` with ``allowed``."""
    if not is_number(value) or not ok(value):
        raise SettingError(key, value, allowed)
    return float(value)


def choice(key: str, value, choices) -> str:
    """``value`` if it is one of the strings ``choices``; else :class:`SettingError` listing them."""
    if not isinstance(value, str) or value not in choices:
        raise SettingError(key, value, "must be one of " + ", ".join(repr(c) for c in choices))
    return value


#: comment column of a :func:`toml_line` (the lines ``fracid init`` writes)
COMMENT_COLUMN = 36


def toml_value(value) -> str:
    """``value`` (number, string, bool or list of them) as TOML."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(toml_value(v) for v in value) + "]"
    if isinstance(value, str):
        return '"' + value.replace("\\", "\\\\").replace('"', '\\"') + '"'
    return repr(value)


def toml_line(key: str, value, comment: str = "", commented: bool = False) -> str:
    """``key = value``, with ``# comment`` at column :data:`COMMENT_COLUMN` when given; ``commented``
    writes the line commented out (``# key = value``)."""
    text = f"{'# ' if commented else ''}{key} = {toml_value(value)}"
    return f"{text.ljust(COMMENT_COLUMN - 1)} # {comment}" if comment else text


__all__ = ["COMMENT_COLUMN", "SettingError", "SettingsContext", "bytes_text", "choice", "integer", "is_integer",
           "is_number", "number", "show", "table", "toml_line", "toml_value"]
