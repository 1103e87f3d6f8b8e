"""Reading a class's numpydoc docstring for the comments of ``fracid init`` and the configuration reference
(:mod:`fracid.config.reference`): its ``Parameters`` (or ``Attributes``) entries, its summary, its paragraphs
outside the numpydoc sections.

Imports nothing of fracid.
"""

from __future__ import annotations

import inspect
import re

#: the ordinals of the fields an entry naming several of them shares (``width, height : float``)
_ORDINALS = ("1st", "2nd", "3rd", "4th", "5th", "6th")


def numpydoc_parameters(cls, section: str = "Parameters") -> dict:
    """The entries of the numpydoc ``Parameters`` section (or another: ``section``) of ``cls``'s docstring.

    Parameters
    ----------
    cls : type
        A class whose docstring has a ``Parameters`` section.
    section : str
        The section's heading (``"Attributes"`` for a settings dataclass documented that way).

    Returns
    -------
    dict
        name -> (type text, description on one line); an entry naming several fields
        (``width, height : float``) gives each of them the shared description.
    """
    doc = inspect.getdoc(cls) or ""
    match = re.search(rf"^{section}\n-+\n(.*?)(?:\n\n(?! )|\Z)", doc, re.S | re.M)
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


def documented(cls) -> dict:
    """name -> (type text, description) of the ``Parameters`` and ``Attributes`` entries of ``cls``'s docstring
    (those of ``Parameters`` first)."""
    return {**numpydoc_parameters(cls, "Attributes"), **numpydoc_parameters(cls)}


#: a reST role with its target (``:func:`~fracid.models.forward.simulate```, ``:mod:`text <target>```)
_ROLE = re.compile(r":[a-z]+(?::[a-z]+)?:`~?([^`<]*?)(?:\s*<[^`>]*>)?`")


def plain(text: str) -> str:
    """numpydoc ``text`` as plain text: a role's target as its last name (``:func:`~a.b.c``` -> ``c``; ``:mod:`a.b```
    -> ``a.b``; ``:class:`words <a.b>``` -> ``words``), a ````literal```` as its content."""

    def name(match) -> str:
        target = match.group(1).strip()
        return target.rsplit(".", 1)[-1] if match.group(0)[match.group(0).index("`") + 1] == "~" else target

    return _ROLE.sub(name, text).replace("``", "")


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
