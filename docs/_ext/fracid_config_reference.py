"""The configuration reference's directive: ``fracid-configuration`` renders
:func:`fracid.config.reference.entries` (every key the checker accepts, read from the registries and classes it
reads) as one section per table, each a definition list of its keys: default, unit, allowed values, meaning.

In a MyST page::

    ```{fracid-configuration}
    ```

The meanings are numpydoc text: their ````literals```` and ``:role:`targets``` are shown as code (a role's target
by its last name), so that no cross-reference can fail the build.
"""

from __future__ import annotations

import re

from docutils import nodes
from sphinx.util.docutils import SphinxDirective

from fracid.settings.keys import REQUIRED, UNSET

#: a ``literal``, a reST role with its target (``:func:`~a.b.c```, ``:class:`words <a.b>```), or a `command`
_MARK = re.compile(r"``(.+?)``|:[a-z]+(?::[a-z]+)?:`(~?)([^`<]*?)(?:\s*<[^`>]*>)?`|`([^`]+)`")


def inline(text: str) -> list:
    """``text`` as inline nodes: plain text, and code for its literals and roles."""
    out, last = [], 0
    for match in _MARK.finditer(text):
        out.append(nodes.Text(text[last:match.start()]))
        if match.group(1) is not None or match.group(4) is not None:
            out.append(nodes.literal(text=match.group(1) or match.group(4)))
        else:
            target = match.group(3).strip()
            out.append(nodes.literal(text=target.rsplit(".", 1)[-1] if match.group(2) else target))
        last = match.end()
    out.append(nodes.Text(text[last:]))
    return [node for node in out if not (isinstance(node, nodes.Text) and not str(node))]


def _facts(entry) -> nodes.paragraph:
    """Default, unit and allowed values of an entry, on one line."""
    para = nodes.paragraph()
    para += nodes.strong(text="default ")
    # a default in words ("required", "the specimen's") is not code; a TOML value is
    words = entry.default in (REQUIRED, UNSET) or isinstance(entry.default, str) and " " in entry.default \
        and not entry.default.startswith(("[", '"'))
    para += nodes.emphasis(text=entry.default) if words else nodes.literal(text=entry.default)
    if entry.unit:
        para += nodes.Text("; ")
        para += nodes.strong(text="unit ")
        para += nodes.Text(entry.unit)
    if entry.allowed:
        para += nodes.Text("; ")
        para += nodes.strong(text="allowed ")
        para += inline(entry.allowed)
    return para


def key_list(rows) -> nodes.definition_list:
    """The definition list of a table's entries."""
    items = nodes.definition_list()
    for entry in rows:
        term = nodes.term()
        term += nodes.literal(text=entry.key)
        definition = nodes.definition()
        definition += _facts(entry)
        meaning = nodes.paragraph()
        meaning += inline(entry.meaning)
        definition += meaning
        items += nodes.definition_list_item("", term, definition)
    return items


class ConfigurationReference(SphinxDirective):
    """``fracid-configuration``: a section per table of :func:`fracid.config.reference.entries`."""

    has_content = False

    def run(self) -> list:
        from fracid.config.reference import entries

        tables = {}
        for entry in entries():
            tables.setdefault(entry.table, []).append(entry)
        sections = []
        for table, rows in tables.items():
            section = nodes.section()
            section["ids"].append(nodes.make_id(f"configuration {table}"))
            section["names"].append(nodes.fully_normalize_name(f"configuration {table}"))
            title = nodes.title()
            title += nodes.Text(table)
            section += title
            section += key_list(rows)
            self.state.document.note_implicit_target(section, section)
            sections.append(section)
        return sections


def setup(app):
    app.add_directive("fracid-configuration", ConfigurationReference)
    return {"parallel_read_safe": True, "parallel_write_safe": True}
