"""Every module path the README and docs/ name exists (issue 37, item 5): a dotted name ``fracid.x.y`` is a
module, or an attribute of one (``fracid.datasets.load``); a path ``src/fracid/...`` is a file or folder of the
source tree. A map of the extension points that names removed modules sends a newcomer nowhere.

:data:`PENDING` holds what is broken today, (document, name); the lead rewrites those documents and empties it.
An entry that resolves again fails, so the set only shrinks.
"""

import importlib
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]

#: the documents checked: the README and the Markdown of docs/ (not the built site)
DOCUMENTS = [ROOT / "README.md", *sorted(p for p in (ROOT / "docs").rglob("*.md") if "_build" not in p.parts)]

DOTTED = re.compile(r"(?<![\w/.\-])fracid(?:\.[A-Za-z_]\w*)+")
SOURCE_PATH = re.compile(r"src/fracid/[\w/.\-]*[\w/]")

#: broken today (issue 37): the README's extension map names modules moved by the last tidy, and the demo's
#: files moved to src/fracid/datasets/gregoire2013_beam4/ (one home of bundled data)
PENDING: set = set()


def resolves(dotted: str) -> bool:
    """Whether ``dotted`` is a module of fracid or an attribute (chain) of one."""
    parts = dotted.split(".")
    for i in range(len(parts), 0, -1):
        try:
            found = importlib.import_module(".".join(parts[:i]))
        except ImportError:
            continue
        for name in parts[i:]:
            if not hasattr(found, name):
                return False
            found = getattr(found, name)
        return True
    return False


def broken(documents=DOCUMENTS, root=ROOT) -> set:
    """{(document relative to root, name)} of the dotted names and source paths that do not exist."""
    found = set()
    for document in documents:
        text = document.read_text(encoding="utf-8")
        where = document.relative_to(root).as_posix()
        found |= {(where, name) for name in set(DOTTED.findall(text)) if not resolves(name)}
        paths = {path.rstrip("/") for path in SOURCE_PATH.findall(text)}
        found |= {(where, path) for path in paths if not (root / path).exists()}
    return found


@pytest.fixture(scope="module")
def found():
    return broken()


def test_the_checker_finds_a_missing_module_an_attribute_and_a_path(tmp_path):
    (tmp_path / "src" / "fracid").mkdir(parents=True)
    (tmp_path / "src" / "fracid" / "here.py").write_text("")
    doc = tmp_path / "README.md"
    doc.write_text("`fracid.datasets.load`, `fracid.nowhere.f`, `fracid.datasets.nope`, src/fracid/here.py, "
                   "src/fracid/gone.py and fracid.data.")
    assert broken([doc], tmp_path) == {("README.md", "fracid.nowhere.f"), ("README.md", "fracid.datasets.nope"),
                                       ("README.md", "src/fracid/gone.py")}


def test_every_named_module_and_source_path_exists(found):
    assert sorted(found - PENDING) == []


def test_pending_lists_only_what_is_still_broken(found):
    assert sorted(PENDING - found) == []
