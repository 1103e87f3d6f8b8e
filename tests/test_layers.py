"""Imports follow the floors of the README's Layout: no module of fracid imports a higher floor."""

import ast
from pathlib import Path

import fracid

# floor of each top-level unit of the package: a module may import its own floor and those below
FLOORS = {
    "fem": 0,
    "specimens": 1,
    "models": 2, "forward": 2, "data": 2, "store": 2, "tables": 2, "parallel": 2, "progress": 2, "provenance": 2,
    "inverse": 3,
    "report": 4,
    "config": 5,
    "cli": 6, "cli_studies": 6, "cli_init": 6, "cli_check": 6, "exits": 6, "lock": 6, "outputs": 6, "__main__": 6, "__init__": 6,
}


def imports(root: Path):
    """(importing unit, imported unit, module) for every fracid import of the package's sources."""
    for path in root.rglob("*.py"):
        parts = path.relative_to(root).with_suffix("").parts
        unit = parts[0]
        tree = ast.parse(path.read_text(encoding="utf-8"))
        for node in ast.walk(tree):
            names = [node.module] if isinstance(node, ast.ImportFrom) and node.module else \
                [a.name for a in node.names] if isinstance(node, ast.Import) else []
            for name in names:
                if name.startswith("fracid."):
                    yield unit, name.split(".")[1], ".".join(parts)


def test_every_unit_has_a_floor():
    root = Path(fracid.__file__).parent
    units = {p.relative_to(root).with_suffix("").parts[0] for p in root.rglob("*.py")}
    assert units <= set(FLOORS), sorted(units - set(FLOORS))


def test_no_module_imports_a_higher_floor():
    root = Path(fracid.__file__).parent
    upward = sorted({(module, imported) for unit, imported, module in imports(root)
                     if FLOORS[imported] > FLOORS[unit]})
    assert upward == []


def test_the_inverse_core_reaches_models_only_through_the_interface():
    """The inverse methods see a model through fracid.models (simulate, parameters, key), never the
    finite-element internals."""
    root = Path(fracid.__file__).parent
    into_fem = sorted(module for unit, imported, module in imports(root) if unit == "inverse" and imported == "fem")
    assert into_fem == []
