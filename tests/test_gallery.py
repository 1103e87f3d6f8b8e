"""The gallery's scripts (examples/gallery/plot_*.py, issue 40 item 4) have what sphinx-gallery needs to show
them: a title and a paragraph in the module docstring, figures finished in the cell that shows them (the
scraper takes every open figure at the end of each cell, so a figure labelled in a later cell is shown
unlabelled), labelled axes, no ``__file__`` (sphinx-gallery does not define it), and fracid names that exist.
The documentation build executes them (``abort_on_example_error``); this test reads them, in well under a second.
"""

import ast
import re
from pathlib import Path

import pytest

from test_docs_paths import DOTTED, resolves

GALLERY = Path(__file__).resolve().parents[1] / "examples" / "gallery"
SCRIPTS = sorted(GALLERY.glob("plot_*.py"))

#: a cell separator of sphinx-gallery (``# %%`` or a line of 20 or more ``#``)
CELL = re.compile(r"^(# %%.*|#{20,})$", re.MULTILINE)
NEW_FIGURE = re.compile(r"\bplt\.(subplots|figure|subplot_mosaic)\(")


def title_problems(docstring: str | None) -> list:
    """What the docstring lacks: a title underlined with ``=`` at least as long, then a paragraph."""
    if not docstring:
        return ["no module docstring (sphinx-gallery takes the title from it)"]
    lines = docstring.strip().splitlines()
    if len(lines) < 2 or not lines[1] or set(lines[1]) != {"="} or len(lines[1]) < len(lines[0]):
        return [f"the docstring does not start with a title underlined by '=' (got {lines[:2]!r})"]
    if not " ".join(lines[2:]).strip():
        return ["no paragraph after the title"]
    return []


def cell_problems(code: str) -> list:
    """Cells that create a figure but do not show it (it would be captured before it is finished)."""
    return [f"cell {k} creates a figure but does not call plt.show()" for k, cell in enumerate(CELL.split(code))
            if cell and NEW_FIGURE.search(cell) and "plt.show()" not in cell]


def gallery_problems(source: str) -> list:
    """Everything :mod:`test_gallery` asks of one gallery script, as messages (empty: the script is fine)."""
    tree = ast.parse(source)
    problems = title_problems(ast.get_docstring(tree, clean=False))
    has_docstring = ast.get_docstring(tree) is not None
    code = "\n".join(source.splitlines()[tree.body[0].end_lineno if has_docstring else 0:])  # the cells
    problems += cell_problems(code)
    if not NEW_FIGURE.search(source) or "plt.show()" not in source:
        problems.append("no figure: a gallery example draws at least one (plt.subplots ... plt.show())")
    for axis in ("x", "y"):
        if not re.search(rf"\b{axis}label\s*=|set_{axis}label\(", source):
            problems.append(f"no {axis} label: label the axes with their units")
    if "__file__" in source:
        problems.append("__file__: sphinx-gallery does not define it (it runs the script from its folder)")
    problems += [f"{name} does not exist" for name in sorted(set(DOTTED.findall(source))) if not resolves(name)]
    return problems


def test_the_gallery_has_at_least_eight_examples():
    assert len(SCRIPTS) >= 8, [p.name for p in SCRIPTS]


@pytest.mark.parametrize("script", SCRIPTS, ids=lambda p: p.name)
def test_gallery_script(script):
    assert gallery_problems(script.read_text(encoding="utf-8")) == []


GOOD = '''"""
A title
=======

A paragraph on what to see, with units [mm].
"""

# %%
# Text.
import matplotlib.pyplot as plt

import fracid

fig, ax = plt.subplots()
ax.set(xlabel="x [mm]", ylabel="force [N]")
plt.show()
'''


@pytest.mark.parametrize("change, words", [
    (lambda s: s.replace('"""\nA title\n=======\n\nA paragraph on what to see, with units [mm].\n"""\n', ""),
     "no module docstring"),
    (lambda s: s.replace("=======", "-------"), "title underlined"),
    (lambda s: s.replace("=======", "===="), "title underlined"),
    (lambda s: s.replace("A paragraph on what to see, with units [mm].", ""), "no paragraph"),
    (lambda s: s.replace('ax.set(xlabel="x [mm]", ylabel="force [N]")\nplt.show()',
                         '\n# %%\n# Later.\nax.set(xlabel="x [mm]", ylabel="force [N]")\nplt.show()'),
     "creates a figure but does not call plt.show()"),
    (lambda s: s.replace("fig, ax = plt.subplots()\n", "").replace("plt.show()\n", ""), "no figure"),
    (lambda s: s.replace('ylabel="force [N]"', 'title="t"'), "no y label"),
    (lambda s: s.replace('xlabel="x [mm]", ', ""), "no x label"),
    (lambda s: s.replace("import fracid\n", "import fracid\nDATA = __file__\n"), "__file__"),
    (lambda s: s.replace("import fracid\n", "import fracid\nfracid.models.NoSuchModel\n"),
     "fracid.models.NoSuchModel does not exist"),
])
def test_gallery_problems_are_found(change, words):
    assert gallery_problems(GOOD) == []
    problems = gallery_problems(change(GOOD))
    assert any(words in p for p in problems), problems
