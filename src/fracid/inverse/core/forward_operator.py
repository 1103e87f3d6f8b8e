"""The forward operator h(x): a vector of identified parameters -> computed observations.

An observation kind (:mod:`fracid.inverse.core.observations`) says what is measured on which specimen and
how it is sampled from a run: a curve quantity at control points (:class:`Observation`), a
displacement field at points and frames (:class:`FieldObservation`), or any object with the members
of :class:`ObservationKind`. :class:`ForwardOperator` maps a vector x of the identified parameters (a named subset of the model
parameters; the others fixed) to the concatenated computed values ``y_comp``, in the order of the
observations. A forward run that does not converge is retried once with smaller steps; if it still
fails, the result records the failure (reason, how far it got) instead of raising, so a study goes on.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field, replace

import numpy as np
import scipy.sparse as sp

from fracid.inverse.core.field_observations import FieldObservation
from fracid.inverse.core.observations import Observation, ObservationKind, check_control_points
from fracid.inverse.core.probed import ProbedSpecimen, merge_probes
from fracid.models.forward import model_with_regularization
from fracid.models import ConvergenceError, StepOptions, declared

__all__ = ["FieldObservation", "ForwardOperator", "Observation", "ObservationKind", "RETRY_STEP_DIVISOR", "RunRecord"]
_control_points = check_control_points  # the old private name
#: A run that does not converge is run again once with its step increments divided by this: the retry takes
#: about this many times the steps of the first attempt (what a failed run costs, fracid check's estimate)
RETRY_STEP_DIVISOR = 4


@dataclass
class RunRecord:
    """Outcome of one evaluation of the forward operator.

    ``y`` holds the computed values (NaN where not computed); ``status`` is ``"ok"`` or ``"failed"``;
    ``error`` the reason of a failure and ``reached`` the control value reached per observation.
    ``S`` is d y / d x (n_outputs x n_parameters) when the run computed it by direct differentiation
    (an operator with ``sensitivities=True``), else None. ``curves`` holds, per observation, the run's own
    curve (``{"control", "values"}`` at every step, from a kind's optional ``curve(run)``) when the run covered
    the whole observation, else None (an empty list from a record stored without them).
    """

    x: np.ndarray
    y: np.ndarray
    status: str = "ok"
    error: str = ""
    reached: list = field(default_factory=list)
    seconds: float = 0.0
    retried: bool = False
    S: np.ndarray | None = None
    curves: list = field(default_factory=list)

    @property
    def ok(self) -> bool:
        return self.status == "ok"

    def as_dict(self) -> dict:
        out = {"x": self.x, "y": self.y, "status": self.status, "error": self.error, "reached": list(self.reached),
               "seconds": self.seconds, "retried": self.retried}
        if self.S is not None:
            out["S"] = self.S
        if any(c is not None for c in self.curves):
            out["curves"] = list(self.curves)
        return out

    @classmethod
    def from_dict(cls, d: dict) -> "RunRecord":
        S = d.get("S")
        return cls(np.asarray(d["x"], float), np.asarray(d["y"], float), d["status"], d["error"], list(d["reached"]),
                   float(d["seconds"]), bool(d["retried"]), None if S is None else np.asarray(S, float),
                   list(d.get("curves") or []))


@dataclass(frozen=True, eq=False)
class ForwardOperator:
    """h(x) for a set of observations, x being the parameters ``names`` (the rest from ``base``).

    Parameters
    ----------
    observations : sequence of observation kinds
        :class:`Observation`, :class:`FieldObservation` or any :class:`ObservationKind`; y is their
        values concatenated in this order.
    base : parameter object
        Values of the parameters that are not identified (an instance of ``model.parameters``).
    names : sequence of str
        Identified parameters, in the order of x.
    regularization : str, optional
        ``"gradient"``, ``"local"`` or ``"integral"``: shorthand for ``model=DamageModel(regularization)``
        (not with ``model``). After construction it is the model's regularization (None for models
        without one).
    steps : StepOptions or None
        Step rule (the specimen's default if None); the retry divides its increments by 4.
    model : ForwardModel, optional
        The forward model (see :mod:`fracid.models`); :class:`~fracid.models.DamageModel` by default.
    sensitivities : bool
        Every run also returns S = d y / d x (``RunRecord.S``) by direct differentiation inside the
        analysis (:mod:`fracid.fem.path.ddm`), where the model and the observed quantities allow it (see
        :meth:`differentiated`); None for a quantity without derivatives (a local width).
    """

    observations: tuple
    base: object
    names: tuple
    regularization: str | None = None
    steps: StepOptions | None = None
    model: object = None
    sensitivities: bool = False

    def __post_init__(self):
        object.__setattr__(self, "observations", tuple(self.observations))
        if isinstance(self.names, str):
            raise TypeError(f"names = {self.names!r} is a string; give a sequence of parameter names, e.g. "
                            f"({self.names!r},)")
        object.__setattr__(self, "names", tuple(self.names))
        strangers = [type(o).__name__ for o in self.observations if not isinstance(o, ObservationKind)]
        if strangers or not self.observations:
            raise TypeError(f"observations must be a non-empty sequence of Observation (or FieldObservation, or an "
                            f"object with the members of ObservationKind), got {strangers or 'none'}")
        object.__setattr__(self, "model", model_with_regularization(self.model, self.regularization, restated=True))
        object.__setattr__(self, "regularization", declared(self.model).regularization)
        if not isinstance(self.base, self.model.parameters):
            raise TypeError(f"base is a {type(self.base).__name__}; the model {self.model.key!r} takes "
                            f"{self.model.parameters.__name__}")
        known = self.model.parameters.names()
        unknown = set(self.names) - set(known)
        if unknown or not self.names:
            raise ValueError(f"identified parameters {sorted(unknown) or '[]'} are not among {known}")
        sizes = [int(o.size) for o in self.observations]
        object.__setattr__(self, "_offsets", np.concatenate([[0], np.cumsum(sizes)]))

    @property
    def differentiable(self) -> bool:
        """Whether the model differentiates its runs with respect to every identified parameter and
        every observation has derivatives (its ``differentiable_with(model)``: the force, the
        functionals, energies and probes do; the specimen's ``observables`` and the model's
        ``observer_names`` (zone widths, crack lengths, from observers) only with a model whose
        ``differentiates_observers`` is true)."""
        names = set(declared(self.model).differentiable)
        return set(self.names) <= names and all(o.differentiable_with(self.model) for o in self.observations)

    def differentiated(self) -> "ForwardOperator":
        """This operator with ``sensitivities=True`` if it is :attr:`differentiable`, else itself."""
        return replace(self, sensitivities=True) if self.differentiable and not self.sensitivities else self

    @property
    def n_outputs(self) -> int:
        return int(self._offsets[-1])

    def valid_bounds(self) -> tuple[np.ndarray, np.ndarray]:
        """Valid ranges of the identified parameters (the model's), for clipping estimates."""
        return self.model.parameters.valid_bounds(self.names)

    @property
    def units(self) -> dict:
        """Units of the identified parameters."""
        units = self.model.parameters.units()
        return {name: units.get(name, "") for name in self.names}

    def parameters(self, x):
        """The full parameter set for the vector x (raises ValueError for invalid values)."""
        x = np.asarray(x, dtype=float)
        if x.shape != (len(self.names),):
            raise ValueError(f"x must have {len(self.names)} entries {self.names}, got shape {x.shape}")
        return self.base.replace(**dict(zip(self.names, x.tolist())))

    def slices(self) -> list[slice]:
        """Position of each observation block in y."""
        return [slice(int(a), int(b)) for a, b in zip(self._offsets[:-1], self._offsets[1:])]

    def __call__(self, x, needed: int | None = None) -> RunRecord:
        """Evaluate h(x); only the first ``needed`` outputs are guaranteed (runs stop early)."""
        start = time.perf_counter()
        x = np.asarray(x, dtype=float)
        record = RunRecord(x=x, y=np.full(self.n_outputs, np.nan), curves=[None] * len(self.observations))
        try:
            params = self.parameters(x)
        except ValueError as err:
            record.status, record.error = "failed", f"invalid parameters: {err}"
            return record
        limit = self.n_outputs if needed is None else int(needed)
        if self.sensitivities:
            record.S = np.full((self.n_outputs, len(self.names)), np.nan)
        for threshold, group in self._run_groups(limit):
            if not self._fill(record, group, params, limit, threshold):
                break
        record.seconds = time.perf_counter() - start
        return record

    def _run_groups(self, limit):
        """Needed observations (obs, slice) grouped by shared run, in order of first appearance."""
        groups = []  # [(specimen, control), threshold or None, members]
        for obs, part in zip(self.observations, self.slices()):
            if part.start >= limit:
                continue
            *test, threshold = obs.run_key
            for group in groups:
                if group[0] == test and (group[1] == threshold or None in (group[1], threshold)):
                    group[1] = threshold if group[1] is None else group[1]
                    group[2].append((obs, part))
                    break
            else:
                groups.append([test, threshold, [(obs, part)]])
        return [(threshold or 0.0, members) for _, threshold, members in groups]

    def _fill(self, record, group, params, limit, threshold) -> bool:
        """Run one group's analysis to its largest needed control value and sample its blocks."""
        counts = [min(part.stop, limit) - part.start for _, part in group]
        target = max(float(obs.controls[n - 1]) for (obs, _), n in zip(group, counts))
        # every control a kind samples within the run's range is a step: a kind samples all of them (a
        # field's frames past the needed entries too), and the extra rows are dropped below
        checkpoints = np.unique(np.concatenate([obs.controls[obs.controls <= target] for obs, _ in group]))
        observables = sorted({name for obs, _ in group for name in obs.observables})
        probes = merge_probes(obs for obs, _ in group)
        matrix, kind_rows = stacked_probes([obs for obs, _ in group])
        run, error, retried = self._run(group[0][0], params, float(checkpoints[-1]), checkpoints, threshold,
                                        observables, probes, matrix)
        record.retried |= retried
        if run is None:
            record.status, record.error = "failed", error
            record.reached.append(0.0)
            return False
        record.reached.append(float(run.control[-1]))
        for (obs, part), n, own in zip(group, counts, kind_rows):
            whole = own is None or matrix.shape[0] == own.stop - own.start
            y, S = obs.sample(run if whole else probe_rows(run, own))
            rows = slice(part.start, part.start + n)
            record.y[rows] = np.asarray(y, float)[:n]
            if n == part.stop - part.start and callable(getattr(obs, "curve", None)):  # the whole block: its curve
                record.curves[self._block_index(part)] = obs.curve(run if whole else probe_rows(run, own))
            if record.S is not None and S is None:  # a quantity the run did not differentiate: no S
                record.S = None
            elif record.S is not None:  # the checkpoints are steps: the samples are the steps' values
                record.S[rows] = np.asarray(S, float)[:n]
        return True

    def _block_index(self, part: slice) -> int:
        """Index of the observation whose block is ``part``."""
        return int(np.searchsorted(self._offsets, part.start, side="right")) - 1

    def _run(self, obs, params, target, checkpoints, threshold, observables, probes, matrix=None):
        """Forward run to ``target`` (with the sparse probe ``matrix`` if not None); one retry with smaller
        steps. Returns (result or partial, error, retried)."""
        error = ""
        specimen = ProbedSpecimen(obs.specimen, probes) if probes else obs.specimen
        for attempt, steps in enumerate(self._step_rules(obs, target)):
            try:
                result = self.model.simulate(specimen, params, control=obs.control, target=target,
                                             stop_force_fraction=None, steps=steps, field_steps=None,
                                             checkpoints=checkpoints, damage_threshold=threshold,
                                             observables=observables,
                                             **({"sensitivities": self.names} if self.sensitivities else {}),
                                             **({} if matrix is None else {"probes": matrix}))
                return result, "", attempt > 0
            except ConvergenceError as err:
                error = str(err)
                partial = err.partial
        reached = partial.control[-1] if partial.n_steps else 0.0
        return None, f"forward run failed at control {reached:.6g} of {target:.6g} mm: {error}", True

    def _step_rules(self, obs, target):
        first = self.steps
        if first is None:
            first = obs.specimen.default_steps(target) if hasattr(obs.specimen, "default_steps") else StepOptions()
        d = RETRY_STEP_DIVISOR
        quarter = (lambda v: None if v is None else v / d)  # noqa: E731
        smaller = replace(first, initial=quarter(first.initial), maximum=quarter(first.maximum),
                          max_factor=first.max_factor / d, onset_fraction=first.onset_fraction / d)
        return (first, smaller)



def stacked_probes(kinds) -> tuple:
    """The probe matrices of the kinds of one run stacked, and each kind's rows (None: no ``probe_matrix``).

    Returns
    -------
    matrix : scipy.sparse.csr_matrix or None
        The kinds' ``probe_matrix()`` one under the other (None if no kind has one).
    rows : list of slice or None
        The rows of each kind in ``matrix``.
    """
    blocks, rows, start = [], [], 0
    for kind in kinds:
        make = getattr(kind, "probe_matrix", None)
        if make is None:
            rows.append(None)
            continue
        block = sp.csr_matrix(make())
        blocks.append(block)
        rows.append(slice(start, start + block.shape[0]))
        start += block.shape[0]
    return (sp.vstack(blocks, format="csr") if blocks else None), rows


def probe_rows(run, rows: slice):
    """``run`` (a :class:`~fracid.models.PathResult`) with its probed values and their derivatives cut to
    ``rows``: what one kind of a shared run sees."""
    probed = {step: values[rows] for step, values in run.probed.items()}
    derivatives = run.derivatives
    if derivatives is not None and "probed" in derivatives:
        derivatives = {**derivatives, "probed": {step: d[rows] for step, d in derivatives["probed"].items()}}
    return replace(run, probed=probed, derivatives=derivatives)
