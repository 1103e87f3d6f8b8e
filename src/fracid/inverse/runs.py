"""Forward runs of a population through the run store and an executor (resumable, failure-tolerant)."""

from __future__ import annotations

import numpy as np

from fracid.inverse.forward_operator import RunRecord
from fracid.parallel import BatchStats, run_batch
from fracid.store import key_for


def run_key(operator, x) -> str:
    """Store key of the run of ``operator`` at ``x``: model, specimens, meshes, controls and parameters."""
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
    )


def _valid(operator, x) -> bool:
    try:
        operator.parameters(x)
        return True
    except ValueError:
        return False


def _evaluate(task) -> dict:
    operator, x = task
    return operator(x).as_dict()


def run_population(operator, points, *, executor=None, store=None, progress=None, stats: BatchStats | None = None,
                   study: str = "") -> list[RunRecord]:
    """Evaluate ``operator`` at every point; runs already in ``store`` are loaded, new ones stored as they finish.

    A worker that dies or raises yields a failed record (the study goes on). Returns records in the
    order of ``points``.
    """
    points = [np.asarray(x, dtype=float) for x in points]
    keys = [run_key(operator, x) for x in points] if store is not None else None
    raw = run_batch(_evaluate, [(operator, x) for x in points], executor=executor if executor is not None else "serial",
                    store=store, keys=keys, study=study, progress=progress, stats=stats)
    out = []
    for x, record in zip(points, raw):
        if "y" in record:
            out.append(RunRecord.from_dict(record))
        else:  # the task itself raised: run_batch's failure record
            out.append(RunRecord(x=x, y=np.full(operator.n_outputs, np.nan), status="failed",
                                 error=str(record.get("error", "unknown failure"))))
    return out
