"""Forward runs through the run store and an executor (resumable, failure-tolerant).

Every forward run of an identification goes through here: the KNN population
(:func:`run_population`) and the Kalman filter's runs and sensitivities (:class:`StoredOperator`),
so that a rerun of an interrupted or finished identification recomputes nothing.
"""

from __future__ import annotations

import functools
import hashlib
import threading
from importlib import resources

import numpy as np

from fracid.inverse.forward_operator import RunRecord
from fracid.parallel import BatchStats, run_batch
from fracid.store import key_for


@functools.lru_cache(maxsize=1)
def code_version() -> str:
    """fracid's version and a hash of the source of its forward chain (models, specimens, operator).

    Part of every run key, so that runs stored by another version of the forward code are never
    reused: an upgrade, or an edit of the model code, recomputes.
    """
    import fracid

    digest = hashlib.sha256()
    root = resources.files("fracid")
    sources = [root / "forward.py", root / "models.py", root / "inverse" / "forward_operator.py"]
    for package in ("fem", "specimens"):
        sources += sorted((p for p in (root / package).iterdir() if p.name.endswith(".py")), key=lambda p: p.name)
    for source in sources:
        digest.update(source.name.encode() + b"\0" + source.read_bytes())
    return f"{fracid.__version__}+{digest.hexdigest()[:16]}"


def run_key(operator, x, needed: int | None = None) -> str:
    """Store key of the run of ``operator`` at ``x`` (outputs up to ``needed``, all if None): model,
    specimens, meshes, controls, parameters and :func:`code_version`."""
    observations = [
        {"specimen": o.specimen, "points": o.control_points.tolist(), "quantity": o.quantity, "control": o.control,
         "damage_threshold": o.damage_threshold}
        for o in operator.observations
    ]
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
    them ``evaluate_many(points, needed, executor)``, which :func:`~fracid.inverse.sensitivity.evaluate_points`
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
