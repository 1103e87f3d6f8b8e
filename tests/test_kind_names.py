"""Only a kind's own room names it (issue 37, item 5): no module outside the modules of a registry holds the
name of one of its registered kinds as a string literal. The configuration, the command, the report and the
studies iterate the registries instead, so that a new kind costs one module and one registry line.

Excepted: docstrings, and text built from the registry (an f-string's literal parts are not counted). A
literal equal to a kind's name counts even where it means something else (``"linear"`` is also a softening
shape of the PF-CZM): a name shared by two concepts is a trap too.

:data:`PENDING` holds today's count per module, {module: number of literals}; the test fails when a module
gains one (or a new module holds one) and when a count falls (lower it, so that the dict only shrinks).
"""

import ast
from collections import Counter
from pathlib import Path

import fracid

ROOT = Path(fracid.__file__).parent


def registries() -> dict:
    """{registry: (the names of its kinds, the module prefixes of its own room)}."""
    from fracid.inverse.experiments.registry import EXPERIMENTS
    from fracid.fem.material.laws import TRACTION_SEPARATION_LAWS
    from fracid.inverse.methods.registry import METHODS
    from fracid.models import MODEL_TYPES
    from fracid.specimens import SPECIMENS

    return {
        "specimens": (set(SPECIMENS), ("fracid.specimens",)),
        "models": (set(MODEL_TYPES), ("fracid.models",)),
        "methods": (set(METHODS), ("fracid.inverse.methods",)),
        "traction-separation laws": (set(TRACTION_SEPARATION_LAWS), ("fracid.fem.material",)),
        "experiment kinds": (set(EXPERIMENTS), ("fracid.inverse.experiments",)),
    }


#: string literals of registered kind names outside their rooms today, per module (55 in all for these five
#: registries); lowered as the kinds bring their own adapters
PENDING = {
    "fracid.cli.init": 3,
    "fracid.data.dic.derived": 1,
    "fracid.data.dic.field": 1,
    "fracid.datasets": 4,
    "fracid.fem.formulations.phase_field_problem": 1,
    "fracid.fem.formulations.problem": 1,
    "fracid.fem.material.phase_field": 1,
    "fracid.fem.material.tsl": 2,
    "fracid.fem.mesh.discretization": 2,
    "fracid.fem.mesh.dofs": 1,
    "fracid.inverse.core.derived_observations": 1,
    "fracid.inverse.core.field_observations": 2,  # the default block name "field" and its run-store key
    "fracid.report.field_figures": 3,
    "fracid.specimens.strip": 2,
    "fracid.specimens.wedge": 2,
    "fracid.store.provenance": 1,
}


def _module_name(path: Path, root: Path) -> str:
    parts = ("fracid", *path.relative_to(root).with_suffix("").parts)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _docstrings(tree) -> set:
    """The ids of the docstring nodes of a module and of its classes and functions."""
    found = set()
    for node in ast.walk(tree):
        if isinstance(node, (ast.Module, ast.ClassDef, ast.FunctionDef, ast.AsyncFunctionDef)) and node.body:
            first = node.body[0]
            if isinstance(first, ast.Expr) and isinstance(first.value, ast.Constant):
                found.add(id(first.value))
    return found


def literals(tree) -> list:
    """The string literals of a module, less its docstrings and the literal parts of f-strings."""
    skip = _docstrings(tree)
    for node in ast.walk(tree):
        if isinstance(node, ast.JoinedStr):
            skip |= {id(part) for part in node.values}
    return [node.value for node in ast.walk(tree)
            if isinstance(node, ast.Constant) and isinstance(node.value, str) and id(node) not in skip]


def kind_names_outside(root: Path, rooms: dict) -> Counter:
    """{module: number of its literals that name a registered kind of a registry whose room it is not in}."""
    found = Counter()
    for path in sorted(root.rglob("*.py")):
        module = _module_name(path, root)
        for value in literals(ast.parse(path.read_text(encoding="utf-8"))):
            for names, prefixes in rooms.values():
                inside = any(module == p or module.startswith(p + ".") for p in prefixes)
                if value in names and not inside:
                    found[module] += 1
    return found


def test_the_finder_counts_literals_outside_the_room_only(tmp_path):
    (tmp_path / "kinds").mkdir()
    (tmp_path / "kinds" / "a.py").write_text('"""The "beam" kind."""\nNAMES = ["beam"]\n')
    (tmp_path / "report.py").write_text('"""About "beam"."""\n'
                                        'def f(kind, name):\n    """Not "beam"."""\n'
                                        '    return kind == "beam" or f"{name} beam" or "beam"\n')
    rooms = {"kinds": ({"beam"}, ("fracid.kinds",))}
    assert kind_names_outside(tmp_path, rooms) == Counter({"fracid.report": 2})


def test_no_module_gains_a_kind_name_outside_its_room():
    found = kind_names_outside(ROOT, registries())
    grown = {module: (count, PENDING.get(module, 0)) for module, count in found.items()
             if count > PENDING.get(module, 0)}
    assert grown == {}, "module: (literals of kind names now, allowed by PENDING)"


def test_pending_counts_are_not_above_today():
    """A count of :data:`PENDING` above what is found is lowered (the dict only shrinks)."""
    found = kind_names_outside(ROOT, registries())
    fallen = {module: (found.get(module, 0), allowed) for module, allowed in PENDING.items()
              if found.get(module, 0) < allowed}
    assert fallen == {}, "module: (literals of kind names now, PENDING)"
