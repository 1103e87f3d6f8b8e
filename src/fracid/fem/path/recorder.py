"""What an incremental analysis keeps of its converged steps: the curves, the observables and the fields."""

from __future__ import annotations

from typing import Callable

import numpy as np
import scipy.sparse as sp

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
    probes : ProbeSampler or None
        The sparse probe matrix applied to the state at the steps it wants.

    Attributes
    ----------
    peak : float
        Largest absolute force recorded so far [N].
    probed : dict {step: ndarray (n_probes,)}
        The probes' values [mm] at the steps the sampler wants.
    """

    def __init__(self, problem, observers: dict, field_steps, probes=None):
        self.problem, self.observers, self.field_steps = problem, observers, field_steps
        self.probes, self.probed = probes, {}
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
        if self.probes is not None and self.probes.wanted(tau):
            self.probed[step] = self.probes.matrix @ q
        if self.keep(step):
            self.fields[step] = state_fields(problem, q, arrays)
        self.last = (step, q, arrays)
        self.peak = max(self.peak, abs(force))
        return force

    def drop_last(self) -> None:
        """Forget the last step recorded (its derivatives failed): its values, fields and probes; the
        fields of the step before are then not added at the end."""
        step = len(self.records["tau"]) - 1
        if step < 1:
            return
        for values in self.records.values():
            values.pop()
        self.fields.pop(step, None)
        self.probed.pop(step, None)
        self.last = None
        self.peak = float(np.max(np.abs(self.records["force"])))

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


class ProbeSampler:
    """A sparse probe matrix over the nodal displacements, applied to the state at chosen control values.

    Parameters
    ----------
    problem : Problem
        The problem traced; it must have a ``dofs`` map (:class:`~fracid.fem.mesh.dofs.DofMap`).
    matrix : scipy.sparse matrix, shape (n_probes, n_u)
        Row k gives probe k [mm] as weights of the nodal displacement vector, laid out as
        ``PathResult.fields[step]["u"]`` (dof ``dim j + c`` is component c of node j; eliminated dofs
        count as zero).
    checkpoints : array_like or None
        Control values [mm] at which the probes are recorded (a step lands on each, see
        :func:`~fracid.fem.path.path_following.follow_path`); None: at every step.

    Attributes
    ----------
    matrix : scipy.sparse.csr_matrix, shape (n_probes, n_free)
        The probes as weights of the free unknowns q: applied to q and to dq/dx directly.
    """

    def __init__(self, problem, matrix, checkpoints=None):
        self.matrix = free_dof_probes(problem, matrix)
        self.marks = None if checkpoints is None else np.unique(np.asarray(checkpoints, dtype=float).ravel())

    def wanted(self, tau: float) -> bool:
        """Whether the step reached at control ``tau`` [mm] is one whose probes are recorded."""
        if self.marks is None:
            return True
        return bool(np.any(np.abs(self.marks - tau) <= 1e-9 * np.abs(self.marks) + 1e-15))


def free_dof_probes(problem, matrix) -> sp.csr_matrix:
    """``matrix`` (n_probes, n_u) over the nodal displacements as a matrix over the free unknowns of ``problem``.

    Eliminated (fixed) dofs drop out; tied dofs add up on their shared unknown.

    Raises
    ------
    TypeError
        When ``matrix`` is not a scipy.sparse matrix or the problem has no ``dofs`` map.
    ValueError
        When its number of columns is not the problem's number of displacement dofs.
    """
    if not sp.issparse(matrix):
        raise TypeError(f"probes is a {type(matrix).__name__}; give a scipy.sparse matrix (n_probes, n_u) over the "
                        "nodal displacement vector (e.g. from fracid.fem.mesh.probes.probe_matrix and dof_matrix)")
    dofs = getattr(problem, "dofs", None)
    if dofs is None:
        raise TypeError(f"{type(problem).__name__} has no dofs map, so probes over its displacements cannot be "
                        "applied; use functionals of the problem instead")
    u_index = dofs.free_index[dofs.ranges["u"]]
    if matrix.shape[1] != u_index.size:
        raise ValueError(f"probes has {matrix.shape[1]} columns; the problem has {u_index.size} displacement dofs "
                         "(the length of fields[step]['u'])")
    free = np.flatnonzero(u_index >= 0)
    to_free = sp.csr_matrix((np.ones(free.size), (free, u_index[free])), shape=(u_index.size, problem.n_free))
    return (sp.csr_matrix(matrix, dtype=float) @ to_free).tocsr()


def probed_at(result, controls) -> tuple:
    """A :class:`~fracid.fem.path.path_following.PathResult`'s probe values at the control values ``controls``.

    Parameters
    ----------
    result : PathResult
        A run with ``probes`` recorded at (at least) ``controls``.
    controls : array_like, shape (n,)
        Control values [mm], each a step of the run where the probes were recorded (a checkpoint),
        or beyond the run's last step (not reached: NaN).

    Returns
    -------
    values : ndarray (n, n_probes)
        The probes [mm].
    derivatives : ndarray (n, n_probes, p) or None
        Their derivatives with respect to the run's parameters (None without sensitivities).

    Raises
    ------
    ValueError
        When a control value within the run is not a step whose probes were recorded.
    """
    controls = np.atleast_1d(np.asarray(controls, dtype=float))
    derivatives = (result.derivatives or {}).get("probed")
    width = next(iter(result.probed.values())).size if result.probed else 0
    p = len(result.derivatives["names"]) if derivatives is not None else 0
    values, slopes = np.full((controls.size, width), np.nan), np.full((controls.size, width, p), np.nan)
    for k, c in enumerate(controls):
        if c > result.control[-1] * (1.0 + 1e-9) + 1e-15:
            continue  # not reached
        steps = np.flatnonzero(np.abs(result.control - c) <= 1e-9 * abs(c) + 1e-15)
        step = next((int(s) for s in steps if int(s) in result.probed), None)
        if step is None:
            raise ValueError(f"the run has no probe values at control {c:.9g} mm: probes are recorded at the steps "
                             "that land on its checkpoints; pass this control value among follow_path's checkpoints")
        values[k] = result.probed[step]
        if derivatives is not None:
            slopes[k] = derivatives[step]
    return values, (slopes if derivatives is not None else None)
