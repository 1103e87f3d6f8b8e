"""The README stays what a visitor needs (issue 40, item 5): at most 150 lines, the test command CI runs,
links that lead somewhere; and the module map of docs/extending.md names every module of fracid (the
README's old map named modules that no longer existed and missed new ones: nothing checked it).
"""

import pkgutil
import re
from pathlib import Path

import fracid

ROOT = Path(__file__).resolve().parents[1]
README = ROOT / "README.md"
EXTENDING = ROOT / "docs" / "extending.md"

#: the most lines the README may have
MAX_LINES = 150

MARKER = "<!-- test-command"
LOCAL_LINK = re.compile(r"\]\((?!https?://|#)([^)#\s]+)")


def command_after_marker(text: str) -> str:
    """The command of the code block after the test-command marker, as `.ci/run` reads it ('' if none)."""
    lines = text.splitlines()
    starts = [i for i, line in enumerate(lines) if line.startswith(MARKER)]
    if not starts:
        return ""
    block, inside = [], False
    for line in lines[starts[0] + 1:]:
        if line.startswith("```"):
            if inside:
                break
            inside = True
            continue
        if inside:
            block.append(line)
    return "\n".join(block).strip()


def missing_links(text: str, base: Path) -> list:
    """The relative links of a Markdown text whose file does not exist under ``base``."""
    return sorted({link for link in LOCAL_LINK.findall(text) if not (base / link).exists()})


def modules() -> list:
    """Every module and package of fracid but ``__main__``."""
    found = [info.name for info in pkgutil.walk_packages(fracid.__path__, "fracid.")]
    return [name for name in found if not name.endswith(".__main__")]


def test_readme_has_at_most_150_lines():
    lines = README.read_text(encoding="utf-8").splitlines()
    assert len(lines) <= MAX_LINES, f"README.md has {len(lines)} lines; move text to a page of docs/"


def test_readme_carries_the_test_command_ci_runs():
    command = command_after_marker(README.read_text(encoding="utf-8"))
    assert "pytest" in command, f"no pytest command after the {MARKER} marker of README.md: {command!r}"


def test_the_command_reader_finds_the_block_after_the_marker_only():
    text = "```bash\nnot this\n```\n<!-- test-command: x -->\n```bash\npip install . && pytest\n```\n```\nno\n```"
    assert command_after_marker(text) == "pip install . && pytest"
    assert command_after_marker("```bash\npytest\n```") == ""


def test_readme_links_lead_to_files():
    assert missing_links(README.read_text(encoding="utf-8"), ROOT) == []


def test_the_link_check_finds_a_missing_file(tmp_path):
    (tmp_path / "here.md").write_text("")
    text = "[a](here.md) [b](gone.md#x) [c](https://example.org/gone.md) [d](#anchor)"
    assert missing_links(text, tmp_path) == ["gone.md"]


def test_the_module_map_names_every_module():
    text = EXTENDING.read_text(encoding="utf-8")
    absent = [name for name in modules() if f"`{name}`" not in text]
    assert absent == [], (f"docs/extending.md's module map misses {absent}: add a row "
                          "| `fracid.x.y` | the first sentence of its docstring | to its package's table")
