"""The numpydoc readers of ``fracid init``'s comments: :mod:`fracid.settings.docstrings` (on the lowest floor, so
that the configuration reference reads the same text)."""

from fracid.settings.docstrings import description, documented, numpydoc_parameters, summary

__all__ = ["description", "documented", "numpydoc_parameters", "summary"]
