"""Sizes a newcomer can read (issue 37, item 5): no source file of fracid over 400 lines, no function over 80
lines (from its ``def`` to its last line, docstring included). A longer one is split along a seam, not
trimmed of its documentation.

The files and functions other work is splitting are in :data:`PENDING`: each must still be over its limit
(an entry that is no longer needed fails, so that the set only shrinks), and none may be added to.
"""

import ast
from pathlib import Path

import fracid

MAX_FILE_LINES = 400
MAX_FUNCTION_LINES = 80

#: over a limit today and being split (issue 37): "path/relative/to/fracid.py" for a file,
#: "path.py:function" for a function (a method: "path.py:Class.method"); the lead empties it after the merge
PENDING: set = set()

ROOT = Path(fracid.__file__).parent


def _functions(tree, prefix=""):
    """(qualified name, number of lines) of every function and method, nested ones included."""
    for node in ast.iter_child_nodes(tree):
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
            name = f"{prefix}{node.name}"
            yield name, node.end_lineno - node.lineno + 1
            yield from _functions(node, f"{name}.")
        elif isinstance(node, ast.ClassDef):
            yield from _functions(node, f"{prefix}{node.name}.")
        else:
            yield from _functions(node, prefix)


def oversized(root: Path = ROOT) -> dict:
    """{"file.py" or "file.py:function": its number of lines} of what is over its limit under ``root``."""
    found = {}
    for path in sorted(root.rglob("*.py")):
        name = path.relative_to(root).as_posix()
        text = path.read_text(encoding="utf-8")
        lines = len(text.splitlines())
        if lines > MAX_FILE_LINES:
            found[name] = lines
        for function, length in _functions(ast.parse(text)):
            if length > MAX_FUNCTION_LINES:
                found[f"{name}:{function}"] = length
    return found


def test_the_size_finder_finds_long_files_and_functions(tmp_path):
    body = "".join(f"        x{i} = {i}\n" for i in range(MAX_FUNCTION_LINES))
    (tmp_path / "long.py").write_text(f"class A:\n    def f(self):\n{body}" + "\n" * MAX_FILE_LINES)
    (tmp_path / "short.py").write_text("def g():\n    return 1\n")
    assert oversized(tmp_path) == {"long.py": MAX_FILE_LINES + 2 + MAX_FUNCTION_LINES,
                                   "long.py:A.f": MAX_FUNCTION_LINES + 1}


def test_no_source_file_or_function_is_too_long():
    """Every file at most 400 lines and every function at most 80, but those of :data:`PENDING`."""
    found = oversized()
    assert sorted(set(found) - PENDING) == [], {k: found[k] for k in set(found) - PENDING}


def test_pending_lists_only_what_is_still_too_long():
    """An entry of :data:`PENDING` that is within its limit now is removed from it."""
    assert sorted(PENDING - set(oversized())) == []
