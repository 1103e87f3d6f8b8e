"""The kinds of record a stage of an inverse method leaves, and how a result finds them by kind.

A method declares, beside its ``stages`` (name -> label), the kind of record each leaves
(``stage_records``: name -> kind); the report keeps one view per kind and the studies read a record by its
kind, so neither names a method or a stage. The kinds:

``"population"`` (:data:`POPULATION`)
    A dict over a population of forward runs: ``points`` (N, p) [units of the parameters], ``f`` (N,) the
    objective [-] (None or inf where a run failed), ``status`` (N,) ``"ok"`` or why a run failed,
    ``errors`` (N,) the failures' messages, ``order`` the ranking (best first), ``k`` the points the prior
    is drawn from and, when the search gives the next stage a prior, ``x0`` (p,) and ``C0`` (p, p).
``"path"`` (:data:`PATH`)
    A list of estimates in the order they were reached: dicts with ``x`` (p,), ``C`` (p, p) and
    ``iteration`` (the pass it belongs to, from 1).
``"generic"`` (:data:`GENERIC`)
    Any JSON-serialisable value: the report lists it.

Numpy only; on the lowest floor of :mod:`fracid.inverse`.
"""

from __future__ import annotations

import numpy as np

#: a population of forward runs (points, objective, ranking and the prior they give)
POPULATION = "population"
#: a path of estimates (x and C at every step)
PATH = "path"
#: anything else, listed as it is
GENERIC = "generic"
#: every kind of record, in the order above
RECORD_KINDS = (POPULATION, PATH, GENERIC)


class StageRecords:
    """Mixin of :class:`~fracid.inverse.core.method.MethodResult`: the record of a stage and its kind, the
    search's population and prior, by kind (the result's ``stages``, ``stage_records`` and ``records``)."""

    def record_kind(self, stage: str) -> str:
        """The kind of record the stage ``stage`` left (:data:`GENERIC` when it declared none)."""
        return (getattr(self, "stage_records", None) or {}).get(stage, GENERIC)

    def record(self, stage: str):
        """What the stage ``stage`` recorded (``records[stage]``; None when nothing)."""
        return (getattr(self, "records", None) or {}).get(stage)

    def stages_of_kind(self, kind: str) -> list[str]:
        """The declared stages whose record is of the kind ``kind``, in the order they ran."""
        return [stage for stage in getattr(self, "stages", None) or {} if self.record_kind(stage) == kind]

    def population(self) -> dict:
        """The record of the first stage that left a :data:`POPULATION` (empty without one)."""
        found = [self.record(stage) for stage in self.stages_of_kind(POPULATION)]
        return next((record for record in found if record), {})

    def search_prior(self):
        """The prior the population gave the next stage: ``(stage, x0, C0)`` (x0 (p,), C0 (p, p) in the
        units of the parameters), or None when no population record holds one."""
        for stage in self.stages_of_kind(POPULATION):
            record = self.record(stage) or {}
            if record.get("x0") is not None and record.get("C0") is not None:
                p = len(record["x0"])
                return stage, np.asarray(record["x0"], float).reshape(p), np.asarray(record["C0"], float).reshape(p, p)
        return None

    def stage_after(self, stage: str) -> str | None:
        """The stage that ran after ``stage`` (None for the last or an unknown one)."""
        names = list(getattr(self, "stages", None) or {})
        return names[names.index(stage) + 1] if stage in names[:-1] else None


__all__ = ["GENERIC", "PATH", "POPULATION", "RECORD_KINDS", "StageRecords"]
