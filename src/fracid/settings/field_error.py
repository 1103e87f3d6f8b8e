"""An invalid value of a named field or parameter, classified by type instead of by its message."""

from __future__ import annotations


class FieldError(ValueError):
    """A ValueError about the field or parameter ``name`` (of a specimen, a parameter set ...).

    Parameters
    ----------
    name : str or tuple of str
        The field the value was given for (or the fields of a condition joining several, the one the
        value belongs to first): a configuration names its key from it.
    value : object
        The value refused.
    message : str
        The whole message (it names the field and the value itself).
    """

    def __init__(self, name, value, message: str):
        super().__init__(message)
        self.names = (name,) if isinstance(name, str) else tuple(name)
        self.name = self.names[0]
        self.value = value
