"""Forward runs through the run store and an executor (resumable, failure-tolerant).

Every forward run of an identification goes through here: the KNN population
(:func:`run_population`) and the Kalman filter's runs and sensitivities (:class:`StoredOperator`),
so that a rerun of an interrupted or finished identification recomputes nothing.
"""

from __future__ import annotations

import ast
import functools
import hashlib
import threading
from pathlib import Path

import numpy as np

from fracid.inverse.core.forward_operator import RunRecord
from fracid.runtime.batch import BatchStats, run_batch
from fracid.store.runs import key_for


#: The forward chain, relative to the package: what a forward run executes (the models, the finite
#: elements, the specimens and the forward operator). Directories are walked (every ``.py`` file, at
#: any depth), so that a new module is hashed without being listed; the ``fracid`` modules these
#: import are added by :func:`forward_sources`. The inverse methods, the configuration, the reports
#: and the command line are not: they choose the runs, they do not change a run's result.
FORWARD_CHAIN = ("fem", "specimens", "models", "settings/field_error.py", "inverse/core/forward_operator.py")


@functools.cache
def _package_root() -> Path:
    import fracid

    return Path(fracid.__file__).resolve().parent


def _imported_modules(path: Path, module: str) -> set[str]:
    """Dotted names of the modules ``path`` (module ``module``) imports, relative imports resolved;
    ``from a import b`` gives both ``a`` and ``a.b`` (``b`` may be a module)."""
    try:
        tree = ast.parse(path.read_bytes(), filename=str(path))
    except SyntaxError:
        return set()
    package = module if path.name == "__init__.py" else module.rpartition(".")[0]
    names: set[str] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            names.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                parts = package.split(".")
                parts = parts[:len(parts) - node.level + 1] if node.level > 1 else parts
                base = ".".join(parts + ([base] if base else []))
            if base:
                names.add(base)
                names.update(f"{base}.{alias.name}" for alias in node.names if alias.name != "*")
    return names


def _module_file(root: Path, name: str) -> Path | None:
    """The source file of module ``name`` (``fracid.x.y``) under the package ``root``, None if not there."""
    parts = name.split(".")
    if parts[0] != "fracid":
        return None
    base = root.joinpath(*parts[1:])
    for candidate in (base.with_suffix(".py") if len(parts) > 1 else None, base / "__init__.py"):
        if candidate is not None and candidate.is_file():
            return candidate
    return None


def forward_sources(root: Path | str | None = None) -> list[Path]:
    """The source files of the forward chain under the package directory ``root`` (the installed
    ``fracid`` if None), relative to ``root`` and sorted: every ``.py`` file of :data:`FORWARD_CHAIN`
    and, transitively, every ``fracid`` module they import (not the ``__init__`` of the packages
    above an imported module: importing ``fracid.x.y`` runs ``fracid/__init__.py``, but what a run
    computes does not depend on it)."""
    root = _package_root() if root is None else Path(root)
    found: set[Path] = set()
    for entry in FORWARD_CHAIN:
        path = root / entry
        if path.is_dir():
            found.update(p for p in path.rglob("*.py") if "__pycache__" not in p.parts)
        elif path.is_file():
            found.add(path)
    pending = list(found)
    while pending:
        path = pending.pop()
        relative = path.relative_to(root).with_suffix("")
        module = ".".join(("fracid", *relative.parts))
        if module.endswith(".__init__"):
            module = module[: -len(".__init__")]
        for name in _imported_modules(path, module):
            source = _module_file(root, name)
            if source is not None and source not in found and source != root / "__init__.py":
                found.add(source)
                pending.append(source)
    return sorted((p.relative_to(root) for p in found), key=lambda p: p.as_posix())


def _read_source(path: Path) -> bytes:
    return path.read_bytes()


@functools.lru_cache(maxsize=8)
def _source_hash(root: Path) -> str:
    digest = hashlib.sha256()
    for relative in forward_sources(root):
        content = _read_source(root / relative)
        digest.update(relative.as_posix().encode() + b"\0" + str(len(content)).encode() + b"\0" + content)
    return digest.hexdigest()


def code_version(root: Path | str | None = None) -> str:
    """fracid's version and a SHA-256 of the source of its forward chain (:func:`forward_sources`
    under the package directory ``root``, the installed ``fracid`` if None), computed once per process.

    Part of every run key, so that runs stored by another version of the forward code are never
    reused: an upgrade, or an edit of the model code (a new module included), recomputes.
    """
    import fracid

    root = _package_root() if root is None else Path(root).resolve()
    return f"{fracid.__version__}+{_source_hash(root)[:16]}"


def run_key(operator, x, needed: int | None = None) -> str:
    """Store key of the run of ``operator`` at ``x`` (outputs up to ``needed``, all if None): model,
    specimens, meshes, controls, parameters and :func:`code_version`."""
    observations = [o.key() for o in operator.observations]  # each kind says what defines it
    return key_for(
        model=operator.model.key,
        model_options=operator.model,
        observations=observations,
        parameters=operator.parameters(x) if _valid(operator, x) else {"names": list(operator.names), "x": list(map(float, x))},
        steps=repr(operator.steps),
        needed=None if needed is None or needed >= operator.n_outputs else int(needed),
        code=code_version(),
        **({"sensitivities": True} if getattr(operator, "sensitivities", False) else {}),
    )


def _valid(operator, x) -> bool:
    try:
        operator.parameters(x)
        return True
    except ValueError:
        return False


def _evaluate(task) -> dict:
    operator, x, needed = task
    return operator(x, needed).as_dict()


def run_population(operator, points, *, executor=None, store=None, progress=None, stats: BatchStats | None = None,
                   study: str = "", needed: int | None = None, retry_failed: bool = False) -> list[RunRecord]:
    """Evaluate ``operator`` at every point; runs already in ``store`` are loaded, new ones stored as they finish.

    A worker that dies or raises yields a failed record (the study goes on). Returns records in the
    order of ``points``. ``needed`` limits the runs to the first outputs (see ForwardOperator);
    ``retry_failed`` runs again the points stored as failed.
    """
    points = [np.asarray(x, dtype=float) for x in points]
    keys = [run_key(operator, x, needed) for x in points] if store is not None else None
    raw = run_batch(_evaluate, [(operator, x, needed) for x in points],
                    executor=executor if executor is not None else "serial", store=store, keys=keys, study=study,
                    progress=progress, stats=stats, retry_failed=retry_failed)
    out = []
    for x, record in zip(points, raw):
        if "y" in record:
            out.append(RunRecord.from_dict(record))
        else:  # the task itself raised: run_batch's failure record
            out.append(RunRecord(x=x, y=np.full(operator.n_outputs, np.nan), status="failed",
                                 error=str(record.get("error", "unknown failure"))))
    return out


class StoredOperator:
    """A forward operator whose runs go through a run store (and a memory of this process's runs).

    Behaves as ``operator`` for the inverse methods (``evaluate(x, needed) -> RunRecord``) and gives
    them ``evaluate_many(points, needed, executor)``, which :func:`~fracid.inverse.core.sensitivity.evaluate_points`
    uses: runs already stored are loaded, new ones are stored as they finish. Counters ``computed``,
    ``reused`` and ``failed`` say what happened.

    Parameters
    ----------
    operator : ForwardOperator
    store : RunStore, optional
        Without one, runs are only remembered in this process.
    study : str
        Label stored with the runs.
    retry_failed : bool
        Run again the points stored as failed (once per point in this process).
    """

    def __init__(self, operator, store=None, *, study: str = "kalman", retry_failed: bool = False):
        self.operator, self.store, self.study, self.retry_failed = operator, store, study, retry_failed
        self.memory: dict = {}
        self.computed = self.reused = self.failed = 0
        self._lock = threading.Lock()  # filters of a study may share this operator from several threads

    def __getattr__(self, name):  # names, units, n_outputs, parameters(), ... of the operator
        if name in ("operator", "_lock"):
            raise AttributeError(name)
        return getattr(self.operator, name)

    def __call__(self, x, needed=None) -> RunRecord:
        return self.evaluate_many([x], needed)[0]

    def differentiated(self) -> "StoredOperator":
        """The same store and settings over ``operator.differentiated()`` (runs with S), or itself when
        the operator has no direct differentiation."""
        exact = self.operator.differentiated()
        if exact is self.operator:
            return self
        return StoredOperator(exact, self.store, study=self.study, retry_failed=self.retry_failed)

    def evaluate_many(self, points, needed=None, executor=None) -> list[RunRecord]:
        needed = None if needed is None or needed >= self.operator.n_outputs else int(needed)
        points = [np.asarray(x, float) for x in points]
        keys = [(x.tobytes(), needed) for x in points]
        missing = {key: x for key, x in zip(keys, points) if key not in self.memory}
        if missing:
            stats = BatchStats()
            records = run_population(self.operator, list(missing.values()), executor=executor, store=self.store,
                                     progress=False, stats=stats, study=self.study, needed=needed,
                                     retry_failed=self.retry_failed)
            with self._lock:
                self.computed, self.reused, self.failed = (self.computed + stats.computed, self.reused + stats.reused,
                                                           self.failed + stats.failed)
                self.memory.update(zip(missing, records))
        return [self.memory[key] for key in keys]
