"""What an incremental analysis keeps of its converged steps: the curves, the observables and the fields."""

from __future__ import annotations

from typing import Callable

import numpy as np

from fracid.fem.formulations.protocol import state_energy, state_fields
from fracid.fem.mesh.assembly import dot


class Recorder:
    """Collects the curves, observables and fields of the converged steps.

    Parameters
    ----------
    problem : Problem
        The problem being traced.
    observers : dict {name: f(problem, q, arrays) -> float}
        Scalar observables evaluated at every converged step.
    field_steps : "last", "all", None or iterable of int
        Steps whose fields are stored (see :func:`~fracid.fem.path.path_following.follow_path`).

    Attributes
    ----------
    peak : float
        Largest absolute force recorded so far [N].
    """

    def __init__(self, problem, observers: dict, field_steps):
        self.problem, self.observers, self.field_steps = problem, observers, field_steps
        self.keep = field_selector(field_steps)
        # displacement work-conjugate to the load factor, for the whole specimen
        self.load_point = problem.symmetry_factor * problem.load_vector
        names = ["tau", "force", "work", "elastic", "load_point", *problem.functionals, *observers]
        self.records = {name: [0.0] for name in names}
        self.fields, self.last, self.peak = {}, None, 0.0

    def record(self, step, tau, q, force, arrays) -> float:
        """Record converged step ``step`` (control ``tau``, free dofs ``q``, load factor ``force``); returns ``force``."""
        rec, problem = self.records, self.problem
        displacement = dot(self.load_point, q)
        work = 0.5 * (force + rec["force"][-1]) * (displacement - rec["load_point"][-1])
        rec["work"].append(rec["work"][-1] + work)
        rec["tau"].append(tau)
        rec["force"].append(force)
        rec["load_point"].append(displacement)
        rec["elastic"].append(state_energy(problem, q, arrays))
        for name, vec in problem.functionals.items():
            rec[name].append(dot(vec, q))
        for name, fn in self.observers.items():
            rec[name].append(float(fn(problem, q, arrays)))
        if self.keep(step):
            self.fields[step] = state_fields(problem, q, arrays)
        self.last = (step, q, arrays)
        self.peak = max(self.peak, abs(force))
        return force

    def curves(self) -> tuple:
        """(control, force, observables, fields) of the steps recorded, as :class:`PathResult` holds them.

        The fields of the last step are added unless ``field_steps`` is None.
        """
        if self.last is not None and self.field_steps is not None and self.last[0] not in self.fields:
            step, q, arrays = self.last
            self.fields[step] = state_fields(self.problem, q, arrays)
        rec = {name: np.array(values) for name, values in self.records.items()}
        obs = {name: rec[name] for name in [*self.problem.functionals, *self.observers]}
        obs["load_point_displacement"] = rec["load_point"]
        obs["external_work"] = rec["work"]
        obs["elastic_energy"] = rec["elastic"]
        obs["dissipated_energy"] = rec["work"] - rec["elastic"]
        return rec["tau"], rec["force"], obs, self.fields


def field_selector(field_steps) -> Callable[[int], bool]:
    """Whether a step's fields are stored as it converges (the last step is added at the end).

    Parameters
    ----------
    field_steps : "last", "all", None or iterable of int
    """
    if field_steps is None or field_steps == "last":
        return lambda step: False
    if field_steps == "all":
        return lambda step: True
    wanted = {int(s) for s in field_steps}
    return lambda step: step in wanted
