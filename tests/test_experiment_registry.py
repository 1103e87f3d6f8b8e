"""The registry of experiment kinds (fracid.inverse.experiments): what each kind declares, the reading order of
derived kinds, and the package's imports (the inverse floor, below the methods; no kind named outside its room
by the configuration's builders)."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

import fracid
from fracid.inverse.experiments.registry import (
    EXPERIMENTS,
    ExperimentKind,
    column_keys,
    derived_kinds,
    kind_names,
)

ROOT = Path(fracid.__file__).parent


def test_every_kind_declares_the_protocol_and_a_known_source():
    assert kind_names() == ("repeats", "envelope", "single", "field", "opening", "fpz-width")
    for name, kind in EXPERIMENTS.items():
        assert isinstance(kind, ExperimentKind) and kind.name == name and "kind" in kind.keys
        assert kind.source is None or kind.source in EXPERIMENTS
    assert derived_kinds() == ("opening", "fpz-width")
    assert column_keys()["envelope"] == ("mean_column", "lower_column", "upper_column")
    assert [name for name, kind in EXPERIMENTS.items() if kind.view] == ["field"]
    assert EXPERIMENTS["field"].view == "displacement-field"


def _imports(path: Path) -> set:
    tree = ast.parse(path.read_text(encoding="utf-8"))
    names = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and node.module:
            names.add(node.module)
        elif isinstance(node, ast.Import):
            names.update(alias.name for alias in node.names)
    return {name for name in names if name.startswith("fracid.")}


ALLOWED = ("fracid.settings", "fracid.specimens", "fracid.models", "fracid.data", "fracid.inverse.core",
           "fracid.inverse.experiments")


@pytest.mark.parametrize("path", sorted((ROOT / "inverse" / "experiments").glob("*.py")), ids=lambda p: p.name)
def test_the_kinds_import_only_what_their_package_docstring_allows(path):
    assert {name for name in _imports(path) if not name.startswith(ALLOWED)} == set()


def test_the_inverse_core_does_not_import_the_kinds():
    core = sorted(ROOT.glob("inverse/core/*.py"))
    assert [p.name for p in core if any(n.startswith("fracid.inverse.experiments") for n in _imports(p))] == []


def _literals(path: Path) -> set:
    """The string constants of a module that are not docstrings."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    docstrings = {id(node.body[0].value) for node in ast.walk(tree)
                  if isinstance(node, (ast.Module, ast.ClassDef, ast.FunctionDef)) and node.body
                  and isinstance(node.body[0], ast.Expr) and isinstance(node.body[0].value, ast.Constant)}
    return {node.value for node in ast.walk(tree)
            if isinstance(node, ast.Constant) and isinstance(node.value, str) and id(node) not in docstrings}


@pytest.mark.parametrize("module", ["config/builders.py", "config/experiments.py", "config/vocabulary.py",
                                    "config/loading.py", "report/views.py", "inverse/core/diagnostics.py"])
def test_the_outer_ring_names_no_experiment_kind(module):
    assert _literals(ROOT / module) & set(EXPERIMENTS) == set()


def test_every_view_a_kind_names_is_one_of_the_reports():
    views = pytest.importorskip("fracid.report.views")  # needs matplotlib
    assert {kind.view for kind in EXPERIMENTS.values() if kind.view} <= set(views.VIEWS)
