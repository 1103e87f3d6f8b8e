"""Reading a class's numpydoc docstring for the comments of ``fracid init``: its ``Parameters`` entries, its
summary, its paragraphs outside the numpydoc sections."""

from __future__ import annotations

import inspect
import re

#: the ordinals of the fields an entry naming several of them shares (``width, height : float``)
_ORDINALS = ("1st", "2nd", "3rd", "4th", "5th", "6th")


def numpydoc_parameters(cls) -> dict:
    """The entries of the numpydoc ``Parameters`` section of ``cls``'s docstring.

    Parameters
    ----------
    cls : type
        A class whose docstring has a ``Parameters`` section.

    Returns
    -------
    dict
        name -> (type text, description on one line); an entry naming several fields
        (``width, height : float``) gives each of them the shared description.
    """
    doc = inspect.getdoc(cls) or ""
    match = re.search(r"^Parameters\n-+\n(.*?)(?:\n\n(?! )|\Z)", doc, re.S | re.M)
    entries, names = {}, []
    for line in (match.group(1).splitlines() if match else []):
        if line and not line.startswith(" "):
            names_text, _, kind = line.partition(" : ")
            names = [n.strip() for n in names_text.split(",")]
            for i, name in enumerate(names):
                entries[name] = (kind.strip() if len(names) == 1 else
                                 f"{kind.strip()}; {_ORDINALS[i]} of {', '.join(names)}", "")
        elif names:
            for name in names:
                kind, text = entries[name]
                entries[name] = (kind, f"{text} {line.strip()}".strip())
    return entries


def summary(cls) -> str:
    """The first paragraph of ``cls``'s docstring, on one line."""
    return " ".join((inspect.getdoc(cls) or "").split("\n\n")[0].split())


def description(cls) -> list:
    """The paragraphs of ``cls``'s docstring outside its numpydoc sections (Parameters, Examples ...),
    each on one line."""
    kept, skipping = [], False
    for paragraph in (inspect.getdoc(cls) or "").split("\n\n"):
        heading = re.match(r"[A-Z][a-z ]+\n-+\n", paragraph)
        skipping = bool(heading) or (skipping and paragraph.startswith(" "))
        if not skipping:
            kept.append(" ".join(paragraph.split()))
    return kept
