"""The code blocks of the getting-started page and the tutorials run (issue 40, items 2 and 6).

Convention: in docs/getting-started.md and docs/tutorials/*.md, every fenced block with info string ``bash``
is executed in order, per page, in a fresh temporary directory into which docs/tutorials/files/<page-stem>/
(if it exists) is copied; ``pip install`` lines are skipped; every command must exit 0; fenced ``python``
blocks are executed too (in the same directory, one namespace per page). Blocks shown but not run (long runs)
use the info string ``console``.

A reader copies a block and runs it: so nothing here prepares the directory beyond the page's files folder.
``fracid`` is the installed entry point when it is on PATH, else ``python -m fracid`` (a shell function).
"""

import os
import re
import shutil
import subprocess
import sys
import time
from dataclasses import dataclass
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"
FILES = DOCS / "tutorials" / "files"

#: the pages whose blocks run
PAGES = [DOCS / "getting-started.md", *sorted(p for p in (DOCS / "tutorials").glob("*.md") if p.stem != "index")]

#: seconds one bash block may take (the slowest, compare, takes about 30 s on 2 loaded cores)
TIMEOUT = 300

FENCE = re.compile(r"^(?P<indent> {0,3})(?P<fence>`{3,}|~{3,})(?P<info>[^`]*)$")

@dataclass(frozen=True)
class Block:
    """A fenced block of a page: its language (first word of the info string), 1-based line and text."""
    language: str
    line: int
    text: str


def blocks(text: str) -> list:
    """The fenced blocks of Markdown ``text``, in order (a fence closes on the same character, at least as long)."""
    found, lines, i = [], text.splitlines(), 0
    while i < len(lines):
        opening = FENCE.match(lines[i])
        if not opening:
            i += 1
            continue
        fence, info, start = opening["fence"], opening["info"].strip(), i
        body = []
        i += 1
        while i < len(lines) and not re.match(rf"^ {{0,3}}{fence[0]}{{{len(fence)},}}\s*$", lines[i]):
            body.append(lines[i])
            i += 1
        found.append(Block(info.split()[0] if info else "", start + 1, "\n".join(body) + "\n"))
        i += 1
    return found


def runnable(block: Block) -> bool:
    return block.language in ("bash", "python")


def shell_script(text: str) -> str:
    """A bash block as run: ``pip install`` lines dropped, ``fracid`` as installed or ``python -m fracid``,
    stopping at the first command that fails."""
    kept = "\n".join(line for line in text.splitlines() if not line.lstrip().startswith("pip install"))
    fallback = "" if shutil.which("fracid") else f'fracid() {{ "{sys.executable}" -m fracid "$@"; }}\n'
    return f"set -eo pipefail\n{fallback}{kept}\n"


class BlockFailed(AssertionError):
    pass


def run_page(page: Path, directory: Path, files: Path = FILES) -> None:
    """Run the bash and python blocks of ``page`` in order in ``directory`` (the page's files copied first);
    raise :class:`BlockFailed` naming the page, the block's line and its output at the first failure."""
    source = files / page.stem
    if source.is_dir():
        shutil.copytree(source, directory, dirs_exist_ok=True)
    namespace = {"__name__": f"page_{page.stem}"}
    where = f"{page.name}"
    old = os.getcwd()
    os.chdir(directory)
    try:
        for block in filter(runnable, blocks(page.read_text(encoding="utf-8"))):
            label = f"{where}, {block.language} block at line {block.line}"
            start = time.perf_counter()
            if block.language == "bash":
                proc = subprocess.run(["bash", "-c", shell_script(block.text)], cwd=directory, capture_output=True,
                                      text=True, timeout=TIMEOUT, stdin=subprocess.DEVNULL)
                if proc.returncode:
                    raise BlockFailed(f"{label} exited {proc.returncode}:\n{block.text}\nstdout:\n"
                                      f"{proc.stdout[-3000:]}\nstderr:\n{proc.stderr[-3000:]}")
            else:
                try:
                    exec(compile(block.text, label, "exec"), namespace)
                except Exception as error:  # noqa: BLE001 - any error of a page's code fails that page
                    raise BlockFailed(f"{label} raised {type(error).__name__}: {error}\n{block.text}") from error
            if os.environ.get("FRACID_TEST_TIMES"):
                print(f"TIME {time.perf_counter() - start:6.2f} s  {label}", file=sys.__stderr__, flush=True)
    finally:
        os.chdir(old)


@pytest.mark.slow
@pytest.mark.parametrize("page", PAGES, ids=lambda p: p.relative_to(DOCS).as_posix())
def test_page_blocks_run(page, tmp_path):
    assert any(b.language == "bash" and "fracid" in b.text for b in blocks(page.read_text(encoding="utf-8"))), \
        f"{page.name} runs no fracid command"
    run_page(page, tmp_path)


# ------------------------------------------------------------------------------------ the harness itself

PAGE = """\
# A page

```bash
pip install nothing-at-all-xyz
echo one > a.txt
```

```console
$ false
```

```python
shared = open("a.txt").read().strip()
```

````python
assert shared == "one"
````

```bash
test -f copied.txt
{last}
```
"""


@pytest.fixture
def fake(tmp_path):
    """A page 'fake.md' with a files folder holding copied.txt; returns a writer of its last bash line."""
    (tmp_path / "files" / "fake").mkdir(parents=True)
    (tmp_path / "files" / "fake" / "copied.txt").write_text("x")
    run_dir = tmp_path / "run"
    run_dir.mkdir()

    def run(last):
        page = tmp_path / "fake.md"
        page.write_text(PAGE.format(last=last))
        run_page(page, run_dir, files=tmp_path / "files")
        return run_dir
    return run


def test_harness_runs_bash_and_python_in_order_skipping_console_and_pip(fake):
    directory = fake("echo two > b.txt")
    assert (directory / "b.txt").read_text() == "two\n"


def test_harness_names_the_failing_bash_block(fake):
    with pytest.raises(BlockFailed, match=r"fake.md, bash block at line 20 exited 3"):
        fake("exit 3")


def test_harness_stops_at_the_first_failing_command_of_a_block(fake):
    with pytest.raises(BlockFailed, match="exited 1"):
        fake("false\necho never")


def test_harness_names_the_failing_python_block(tmp_path):
    page = tmp_path / "p.md"
    page.write_text("```python\nx = 1\n```\n\n```python\nassert x == 2, 'x is not 2'\n```\n")
    with pytest.raises(BlockFailed, match=r"p.md, python block at line 5 raised AssertionError: x is not 2"):
        run_page(page, tmp_path, files=tmp_path / "none")


def test_blocks_reads_info_strings_and_longer_fences():
    found = blocks("```{toctree}\nx\n```\n````bash\n```\ninner\n```\n````\n~~~python\ny = 1\n~~~\n")
    assert [(b.language, b.line) for b in found] == [("{toctree}", 1), ("bash", 4), ("python", 9)]
    assert found[1].text == "```\ninner\n```\n"


def test_fracid_falls_back_to_python_m_fracid_off_path(monkeypatch, tmp_path):
    monkeypatch.setattr(shutil, "which", lambda name: None)
    script = shell_script("pip install fracid\nfracid --version\n")
    assert "pip install" not in script and f'"{sys.executable}" -m fracid' in script
    proc = subprocess.run(["bash", "-c", script], cwd=tmp_path, capture_output=True, text=True, timeout=120,
                          env={**os.environ, "PATH": "/usr/bin:/bin"})
    assert proc.returncode == 0 and proc.stdout.startswith("fracid "), proc.stderr
