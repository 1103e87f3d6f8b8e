"""The errors of :mod:`fracid.data`: data that cannot be used as given, and arguments of the wrong type."""


class DataError(ValueError):
    """Experimental data that cannot be used as given (bad file, bad values, impossible request)."""


class DataTypeError(DataError, TypeError):
    """An argument of the wrong type (a str where a number is expected, None where a column name is):
    both a :class:`DataError` and a ``TypeError``."""
