"""The forward operator h(x): a vector of identified parameters -> computed observations.

An :class:`Observation` says what is measured on which specimen: a curve quantity (the force, or a
local quantity such as the FPZ width) sampled at given values of the specimen's control quantity.
:class:`ForwardOperator` maps a vector x of the identified parameters (a named subset of the model
parameters; the others fixed) to the concatenated computed values ``y_comp``, in the order of the
observations. A forward run that does not converge is retried once with smaller steps; if it still
fails, the result records the failure (reason, how far it got) instead of raising, so a study goes on.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field, replace

import numpy as np

from fracid.models import ConvergenceError, DamageModel, StepOptions


@dataclass(frozen=True, eq=False)
class Observation:
    """Computed counterpart of one measured data block.

    Parameters
    ----------
    specimen
        Specimen object (bar, beam, dog-bone).
    control_points : array_like
        Increasing values of the control quantity at which the data are sampled [mm].
    quantity : str
        ``"force"`` [N] or the name of an observable of the forward run (e.g. ``"fpz_width"`` [mm]).
    control : str or None
        The specimen's control quantity (its default if None).
    name : str
        Label of the block.
    damage_threshold : float
        Damage above which a point counts in a local width observable [-] (0: any damage).

    Observations of the same specimen object, control and threshold share one forward run (the
    force curve and the FPZ width of one test come from the same analysis).
    """

    specimen: object
    control_points: np.ndarray
    quantity: str = "force"
    control: str | None = None
    name: str = "global"
    damage_threshold: float = 0.0

    def __post_init__(self):
        from fracid.forward import check_specimen

        check_specimen(self.specimen)
        object.__setattr__(self, "control_points", _control_points(self.control_points))
        if not isinstance(self.quantity, str) or not self.quantity:
            raise TypeError(f"quantity = {self.quantity!r}; give 'force' or the name of an observable of the "
                            "forward run (e.g. 'fpz_width')")

    @property
    def run_key(self) -> tuple:
        """(specimen, control, threshold): observations with compatible keys share one forward run.

        The force does not depend on the threshold, so a force observation has threshold None.
        """
        try:
            specimen = (hash(self.specimen), self.specimen)  # equal frozen specimens share a run
        except TypeError:
            specimen = id(self.specimen)
        return (specimen, self.control, None if self.quantity == "force" else self.damage_threshold)


def _control_points(values) -> np.ndarray:
    """``values`` as a 1-D float array of finite, strictly increasing control values, or a ValueError."""
    try:
        points = np.asarray(values, dtype=float)
    except (TypeError, ValueError):
        raise TypeError(f"control_points is a {type(values).__name__} that is not an array of numbers") from None
    if points.ndim != 1 or points.size == 0:
        raise ValueError(f"control_points has shape {points.shape}; give a non-empty 1-D array of control values [mm] "
                         "(the data's control, e.g. ExperimentalData.control of one block)")
    if not np.all(np.isfinite(points)):
        raise ValueError("control_points holds NaN or infinite values; every control value must be a finite number")
    steps = np.diff(points)
    if np.any(steps <= 0):
        i = int(np.argmax(steps <= 0))
        raise ValueError(f"control_points must increase strictly, but point {i + 1} ({points[i + 1]:.6g} mm) does not "
                         f"exceed point {i} ({points[i]:.6g} mm)")
    return points


@dataclass
class RunRecord:
    """Outcome of one evaluation of the forward operator.

    ``y`` holds the computed values (NaN where not computed); ``status`` is ``"ok"`` or ``"failed"``;
    ``error`` the reason of a failure and ``reached`` the control value reached per observation.
    ``S`` is d y / d x (n_outputs x n_parameters) when the run computed it by direct differentiation
    (an operator with ``sensitivities=True``), else None.
    """

    x: np.ndarray
    y: np.ndarray
    status: str = "ok"
    error: str = ""
    reached: list = field(default_factory=list)
    seconds: float = 0.0
    retried: bool = False
    S: np.ndarray | None = None

    @property
    def ok(self) -> bool:
        return self.status == "ok"

    def as_dict(self) -> dict:
        out = {"x": self.x, "y": self.y, "status": self.status, "error": self.error, "reached": list(self.reached),
               "seconds": self.seconds, "retried": self.retried}
        if self.S is not None:
            out["S"] = self.S
        return out

    @classmethod
    def from_dict(cls, d: dict) -> "RunRecord":
        S = d.get("S")
        return cls(np.asarray(d["x"], float), np.asarray(d["y"], float), d["status"], d["error"], list(d["reached"]),
                   float(d["seconds"]), bool(d["retried"]), None if S is None else np.asarray(S, float))


@dataclass(frozen=True, eq=False)
class ForwardOperator:
    """h(x) for a set of observations, x being the parameters ``names`` (the rest from ``base``).

    Parameters
    ----------
    observations : sequence of Observation
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
        analysis (:mod:`fracid.fem.ddm`), where the model and the observed quantities allow it (see
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
        strangers = [type(o).__name__ for o in self.observations if not isinstance(o, Observation)]
        if strangers or not self.observations:
            raise TypeError(f"observations must be a non-empty sequence of Observation, got {strangers or 'none'}")
        if self.model is None:
            object.__setattr__(self, "model", DamageModel(self.regularization or "gradient"))
        elif self.regularization is not None and self.regularization != getattr(self.model, "regularization", None):
            raise ValueError(f"regularization = {self.regularization!r} contradicts the model {self.model.key!r}; "
                             "give one of them")
        object.__setattr__(self, "regularization", getattr(self.model, "regularization", None))
        if not isinstance(self.base, self.model.parameters):
            raise TypeError(f"base is a {type(self.base).__name__}; the model {self.model.key!r} takes "
                            f"{self.model.parameters.__name__}")
        known = self.model.parameters.names()
        unknown = set(self.names) - set(known)
        if unknown or not self.names:
            raise ValueError(f"identified parameters {sorted(unknown) or '[]'} are not among {known}")
        sizes = [o.control_points.size for o in self.observations]
        object.__setattr__(self, "_offsets", np.concatenate([[0], np.cumsum(sizes)]))

    @property
    def differentiable(self) -> bool:
        """Whether the model differentiates its runs with respect to every identified parameter and
        every observed quantity has derivatives: the force, the functionals and energies do; the
        specimen's ``observables`` and the model's ``observer_names`` (zone widths, crack lengths, from
        observers) only with a model whose ``differentiates_observers`` is true."""
        names = set(getattr(self.model, "differentiable", ()))
        if getattr(self.model, "differentiates_observers", False):
            return set(self.names) <= names
        observed = {o.quantity for o in self.observations}
        for o in self.observations:
            if observed & {*getattr(o.specimen, "observables", ()), *getattr(self.model, "observer_names", ())}:
                return False
        return set(self.names) <= names

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
        record = RunRecord(x=x, y=np.full(self.n_outputs, np.nan))
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
        wanted = [obs.control_points[: min(part.stop, limit) - part.start] for obs, part in group]
        checkpoints = np.unique(np.concatenate(wanted))
        local = sorted({obs.quantity for obs, _ in group} - {"force"})  # observers cost time at every step
        run, error, retried = self._run(group[0][0], params, float(checkpoints[-1]), checkpoints, threshold, local)
        record.retried |= retried
        if run is None:
            record.status, record.error = "failed", error
            record.reached.append(0.0)
            return False
        record.reached.append(float(run.control[-1]))
        for (obs, part), points in zip(group, wanted):
            values = run.force if obs.quantity == "force" else run.observables[obs.quantity]
            rows = slice(part.start, part.start + points.size)
            record.y[rows] = np.interp(points, run.control, values)
            if record.S is None:
                continue
            derivative = (getattr(run, "derivatives", None) or {}).get(obs.quantity)
            if derivative is None:  # a quantity the run did not differentiate: no S from this run
                record.S = None
            else:  # the checkpoints are steps: the interpolation picks the step's value
                record.S[rows] = np.column_stack([np.interp(points, run.control, d) for d in derivative.T])
        return True

    def _run(self, obs, params, target, checkpoints, threshold, observables):
        """Forward run to ``target``; one retry with smaller steps. Returns (result or partial, error, retried)."""
        error = ""
        for attempt, steps in enumerate(self._step_rules(obs, target)):
            try:
                result = self.model.simulate(obs.specimen, params, control=obs.control, target=target,
                                             stop_force_fraction=None, steps=steps, field_steps=None,
                                             checkpoints=checkpoints, damage_threshold=threshold,
                                             observables=observables,
                                             **({"sensitivities": self.names} if self.sensitivities else {}))
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
        quarter = (lambda v: None if v is None else v / 4)  # noqa: E731
        smaller = replace(first, initial=quarter(first.initial), maximum=quarter(first.maximum),
                          max_factor=first.max_factor / 4, onset_fraction=first.onset_fraction / 4)
        return (first, smaller)
