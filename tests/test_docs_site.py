"""The documentation site (issue 40): it builds with no warning (warnings are errors), every public name has an
API entry, the cross-references the docstrings write name objects that exist, and the built site renders in a
real browser whose search finds a page for "cohesive".

The build is the one a user runs after ``pip install ".[docs]"``::

    python -m sphinx -W --keep-going -b html docs docs/_build/html

It executes the gallery (examples/gallery/), so no example can rot. Skips without Sphinx (the ``docs`` extra);
README's test command installs it, so CI builds the site.
"""

import importlib
import re
import subprocess
import sys
import zlib
from pathlib import Path

import pytest

from _browser import render
from test_docs_paths import resolves

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "docs" / "_ext"))

import fracid_api_reference as api  # noqa: E402


def inventory(path: Path) -> set:
    """The object names of a Sphinx ``objects.inv`` (its version 2 format: four text lines, then zlib)."""
    raw = path.read_bytes()
    body = raw.split(b"\n", 4)[4]
    names = set()
    for line in zlib.decompress(body).decode("utf-8").splitlines():
        match = re.match(r"(\S+)\s+py:\w+\s", line)
        if match:
            names.add(match.group(1))
    return names


def missing_entries(names: set, packages=None) -> list:
    """The ``package.name`` of every public name (the packages' ``__all__``) whose documented home is not in
    ``names`` (an inventory), and the package pages that do not mention a re-exported name."""
    packages = packages or api.public_packages()
    home = api.homes(packages)
    missing = []
    for package in packages:
        for name in api.public_names(package):
            if f"{home[(package, name)]}.{name}" not in names:
                missing.append(f"{package}.{name}")
    return missing


@pytest.fixture(scope="module")
def site(tmp_path_factory):
    pytest.importorskip("sphinx", reason="the docs extra: pip install '.[docs]'")
    out = tmp_path_factory.mktemp("site")
    done = subprocess.run([sys.executable, "-m", "sphinx", "-W", "--keep-going", "-b", "html", "-q",
                           str(ROOT / "docs"), str(out / "html"), "-d", str(out / "doctrees")],
                          capture_output=True, text=True, timeout=900, cwd=ROOT)
    return out / "html", done


@pytest.mark.slow
def test_the_site_builds_with_no_warning(site):
    html, done = site
    warnings = [line for line in done.stderr.splitlines() if "WARNING" in line or "ERROR" in line]
    assert done.returncode == 0 and warnings == [], done.stderr[-4000:]
    for page in ("index.html", "getting-started.html", "reference/cli.html", "reference/configuration.html",
                 "gallery/index.html", "search.html"):
        assert (html / page).is_file(), page


@pytest.mark.slow
def test_every_public_name_has_an_api_entry(site):
    html, done = site
    names = inventory(html / "objects.inv")
    assert missing_entries(names) == []
    # the re-exported names are listed on their package's page with a link to their entry
    for package in api.public_packages():
        text = (html / "reference" / "api" / f"{package}.html").read_text(encoding="utf-8")
        for name in api.public_names(package):
            assert f"{package}.{name}" in text or f">{name}<" in text, (package, name)


@pytest.mark.slow
def test_every_command_and_option_has_a_cli_entry(site):
    import argparse

    from fracid.cli.dispatch import parser

    html, _ = site
    text = " ".join(re.sub(r"<[^>]+>", " ", (html / "reference" / "cli.html").read_text(encoding="utf-8")).split())
    text = re.sub(r"\s*-\s*", "-", text)  # the usage lines' highlighting splits "size-effect", "--out"
    sub = next(a for a in parser()._actions if isinstance(a, argparse._SubParsersAction))
    for name, command in sub.choices.items():
        assert f"fracid {name} [" in text, name
        section = text[text.index(f"fracid {name} ["):]
        for action in command._actions:
            for option in set(action.option_strings) - {"-h", "--help"}:
                assert re.search(rf"(?<![\w-]){re.escape(option)}(?![\w-])", section), (name, option)


def test_missing_entries_names_a_public_name_without_entry():
    packages = ["fracid.specimens"]
    names = {f"fracid.specimens.{n}" for n in api.public_names("fracid.specimens")}
    assert missing_entries(names, packages) == []
    dropped = sorted(names)[0]
    assert missing_entries(names - {dropped}, packages) == [dropped]


@pytest.mark.slow
def test_the_site_renders_and_its_search_finds_cohesive(site, tmp_path):
    html, _ = site
    dom, log = render(html / "index.html", tmp_path)
    assert "<body" in dom and "fracid" in re.sub(r"<[^>]+>", " ", dom)
    assert [line for line in log.splitlines() if "Uncaught" in line] == []
    dom, _ = render(html / "search.html", tmp_path, query="?q=cohesive")
    results = re.search(r'<ul[^>]*class="search"[^>]*>(.*?)</ul>', dom, re.S)
    assert results, f"no search results list: {dom[-3000:]}"
    found = re.findall(r'<li[^>]*><a href="([^"]+)"', results.group(1))
    # the pages that teach the cohesive crack among them
    assert len(found) >= 3 and any("pfczm" in page or "other-models" in page for page in found), found


#: ``:func:`fracid.x.y``` and the like in a docstring (a fully qualified target, optionally ``~``-shortened)
ROLE = re.compile(r":(?:py:)?(?:func|class|meth|mod|data|attr|obj|exc):`~?(fracid(?:\.\w+)+)`")


def docstring_references() -> set:
    """{(module, target)} of the fully qualified cross-references in fracid's sources."""
    found = set()
    for module in api.all_modules():
        path = Path(importlib.import_module(module).__file__)
        found |= {(module, target) for target in ROLE.findall(path.read_text(encoding="utf-8"))}
    return found


def test_the_docstrings_cross_references_name_objects_that_exist():
    broken = sorted((module, target) for module, target in docstring_references() if not resolves(target))
    assert broken == []


def test_the_cross_reference_check_can_fail():
    assert ROLE.findall("see :func:`~fracid.models.nowhere` and :class:`fracid.models.ForwardModel`") == [
        "fracid.models.nowhere", "fracid.models.ForwardModel"]
    assert not resolves("fracid.models.nowhere") and resolves("fracid.models.ForwardModel")
