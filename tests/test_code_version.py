"""The code version in every run key hashes the whole forward chain: every module of fem/ and specimens/
(a new one included, without a list to update), the models, the forward operator; and changes with them."""

import shutil
from pathlib import Path

import pytest

import fracid
from fracid.inverse.core import runs

PACKAGE = Path(fracid.__file__).resolve().parent


def _python_files(root, directory):
    return {p.relative_to(root) for p in (root / directory).rglob("*.py") if "__pycache__" not in p.parts}


@pytest.fixture
def package_copy(tmp_path):
    """A copy of the installed package's source tree (where the hashed files can be edited)."""
    root = tmp_path / "fracid"
    shutil.copytree(PACKAGE, root, ignore=shutil.ignore_patterns("__pycache__", "*.pyc"))
    return root


def test_hash_reads_every_module_of_the_forward_chain(monkeypatch):
    read = []
    monkeypatch.setattr(runs, "_read_source", lambda path: read.append(path) or path.read_bytes())
    runs._source_hash.cache_clear()
    version = runs.code_version()
    assert version.startswith(fracid.__version__ + "+")
    files = {path.relative_to(PACKAGE) for path in read}
    assert len(read) == len(files)  # each once
    expected = _python_files(PACKAGE, "fem") | _python_files(PACKAGE, "specimens") | _python_files(PACKAGE, "models")
    expected |= {Path("settings/field_error.py"), Path("inverse/core/forward_operator.py")}
    assert expected <= files
    # not the code that only chooses the runs or shows their results
    assert not {f for f in files if f.parts[0] in ("report", "config", "cli")
                or f in (Path("inverse/core/runs.py"), Path("inverse/methods/kalman.py"), Path("__init__.py"))}
    # in the order of the relative paths
    assert read == [PACKAGE / f for f in sorted(files, key=Path.as_posix)]
    # computed once per process
    read.clear()
    assert runs.code_version() == version
    assert read == []


def test_a_new_forward_module_is_hashed(package_copy):
    before = runs.code_version(package_copy)
    (package_copy / "fem" / "new_element.py").write_text("ORDER = 2\n")
    (package_copy / "specimens" / "sub").mkdir()
    (package_copy / "specimens" / "sub" / "notch.py").write_text("DEPTH = 1.0\n")
    sources = runs.forward_sources(package_copy)
    assert Path("fem/new_element.py") in sources and Path("specimens/sub/notch.py") in sources
    assert set(sources) >= _python_files(package_copy, "fem") | _python_files(package_copy, "specimens")
    runs._source_hash.cache_clear()
    assert runs.code_version(package_copy) != before


@pytest.mark.parametrize("relative", ["fem/material/damage.py", "specimens/beam.py", "models/damage.py",
                                      "models/forward.py",
                                      "inverse/core/forward_operator.py"])
def test_hash_changes_with_a_forward_module(package_copy, relative):
    before = runs.code_version(package_copy)
    assert before == runs.code_version(PACKAGE)  # the content is hashed, not where it is
    path = package_copy / relative
    path.write_bytes(path.read_bytes() + b"\n# edited\n")
    runs._source_hash.cache_clear()
    assert runs.code_version(package_copy) != before


def test_hash_ignores_code_outside_the_forward_chain(package_copy):
    before = runs.code_version(package_copy)
    for relative in ("cli/dispatch.py", "report/html.py", "inverse/methods/kalman.py", "config/loading.py"):
        path = package_copy / relative
        path.write_bytes(path.read_bytes() + b"\n# edited\n")
    runs._source_hash.cache_clear()
    assert runs.code_version(package_copy) == before


def test_modules_imported_by_the_forward_chain_are_hashed(package_copy):
    """A module outside fem/ and specimens/ that the forward chain starts to import joins the hash."""
    (package_copy / "materials.py").write_text("E = 37000.0\n")
    assert Path("materials.py") not in runs.forward_sources(package_copy)
    laws = package_copy / "fem" / "material" / "laws.py"
    laws.write_text(laws.read_text() + "\nfrom fracid.materials import E  # noqa: E402,F401\n")
    assert Path("materials.py") in runs.forward_sources(package_copy)
    before = runs.code_version(package_copy)
    (package_copy / "materials.py").write_text("E = 30000.0\n")
    runs._source_hash.cache_clear()
    assert runs.code_version(package_copy) != before
