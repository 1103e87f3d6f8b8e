"""What the report shows of a block that is not a curve: :class:`BlockView` (heading, text, table, figures), built
by a view of :data:`fracid.report.views.VIEWS`.

Imports the report's figures only.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field

from fracid.report.figures import to_png


@dataclass
class BlockView:
    """What the report shows of a block that is not a curve.

    Attributes
    ----------
    block : str
        The block's name.
    heading : str
        The section's heading, e.g. ``"Displacement field dic"``.
    text : str
        A paragraph (plain text, escaped by the report).
    header, rows : list
        A table (formatted cells); empty: none.
    figures : dict of str -> (Figure, caption)
        The figures by file stem (``fracid identify`` writes ``figures/<stem>.png``), in order.

    :meth:`png` renders a figure once: the report and figures/ share the bytes.
    """

    block: str
    heading: str
    text: str
    header: list = field(default_factory=list)
    rows: list = field(default_factory=list)
    figures: dict = field(default_factory=dict)
    _png: dict = field(default_factory=dict, repr=False)

    def png(self, stem: str) -> bytes:
        """The figure ``stem`` as PNG bytes (rendered on the first call)."""
        if stem not in self._png:
            self._png[stem] = to_png(self.figures[stem][0])
        return self._png[stem]


def file_stem(name: str) -> str:
    """``name`` fit for a file name: letters, digits, ``-`` and ``_`` kept, anything else ``_``."""
    return re.sub(r"[^A-Za-z0-9_-]", "_", str(name)) or "_"


__all__ = ["BlockView", "file_stem"]
