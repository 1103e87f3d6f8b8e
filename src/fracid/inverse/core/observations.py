"""Observation kinds: what is measured, and how it is sampled from a forward run.

An observation kind is any object with the members of :class:`ObservationKind`; the
:class:`~fracid.inverse.core.forward_operator.ForwardOperator` sees nothing else. A kind says which run it
needs (``run_key``: specimen, control, damage threshold; kinds with equal keys share one run), what the
run must record (``observables``: observers of the model; ``probes``: linear functionals of the nodal
displacements, which the run records and differentiates like the specimen's own functionals), its
size and the control value of each entry (``controls``, non-decreasing: the first k entries need the
run up to ``controls[k - 1]``), the coordinates of its entries, and ``sample(run) -> (y, S)``.

Two kinds are built in:

- :class:`Observation`: a curve quantity (the force, or an observable of the run such as the FPZ
  width) interpolated at control points;
- :class:`~fracid.inverse.core.field_observations.FieldObservation`: a nodal displacement component sampled at
  given points (a sensor, the pixels a camera follows) at given control values (frames), through the point-probe
  operator :func:`~fracid.fem.mesh.probes.probe_matrix` (through :mod:`fracid.models`, the inverse code's window
  on the model).

A kind may also have ``probe_matrix()``: a scipy.sparse matrix (n_probes x n_u) over the nodal
displacement vector; the operator stacks those of the kinds of one run and the run applies it to the
state (and its derivatives) at the checkpoint steps only (``follow_path(probes=...)``,
``PathResult.probed``), handing each kind its rows. The field observation samples that way.

A test file or a user module adds its own kind by writing a class with these members
(``tests/test_extension_observation.py``: the crack-opening profile along the ligament, through ``probes``).

Notes
-----
``probes`` (named terms) become functionals of the run's problem: each is a dense vector over the
unknowns, dotted with the state (and, with sensitivities, its derivatives) at every step: exact and
cheap for tens of values. ``probe_matrix`` stays sparse and is applied at the frames only: full-field
data (thousands of points, digital image correlation) cost O(points) memory per frame.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol, runtime_checkable

import numpy as np

from fracid.inverse.core.probed import specimen_key

#: the observed quantity of a force curve: the run's force [N] (any other quantity is an observable of the run)
FORCE = "force"


@runtime_checkable
class ObservationKind(Protocol):
    """The contract of an observation kind (see the module docstring).

    Attributes
    ----------
    name : str
        Label of the data block.
    specimen : object
        The specimen the run is made on.
    control : str or None
        The run's control quantity (the specimen's default if None).
    """

    name: str
    specimen: object
    control: str | None

    @property
    def run_key(self) -> tuple:
        """(specimen key, control, damage threshold or None): kinds with compatible keys share a run."""

    @property
    def size(self) -> int:
        """Number of values of the block."""

    @property
    def controls(self) -> np.ndarray:
        """Control value of every entry [mm], non-decreasing."""

    @property
    def observables(self) -> tuple:
        """Names of the observers the run must record."""

    @property
    def probes(self) -> dict:
        """``{name: ((node, component, weight), ...)}``: displacement functionals the run must record."""

    def coordinates(self) -> dict:
        """``{name: ndarray (size,)}``: ``control`` [mm] and what else locates each entry."""

    def differentiable_with(self, model) -> bool:
        """Whether the runs of ``model`` differentiate what this kind samples."""

    def key(self) -> dict:
        """What defines the observation, for the run store's keys."""

    def sample(self, run) -> tuple:
        """``(y, S)``: the values (size,) from ``run``, and d y / d x (size, p) when the run carries
        its derivatives (``run.derivatives``), else None."""


def interpolate(run, name: str, points: np.ndarray) -> tuple[np.ndarray, np.ndarray | None]:
    """The run's curve ``name`` (``"force"``, an observable or a probe) at the control values ``points``,
    and its derivatives there ((n, p), None if the run has none for it). Points that are steps of the
    run (checkpoints) take the step's value exactly."""
    values = run.force if name == FORCE else run.observables[name]
    y = np.interp(points, run.control, values)
    derivative = (getattr(run, "derivatives", None) or {}).get(name)
    if derivative is None:
        return y, None
    return y, np.column_stack([np.interp(points, run.control, d) for d in np.asarray(derivative).T])


def run_curve(run, name: str, end: float) -> dict:
    """``{"control": ndarray, "values": ndarray}``: the run's curve ``name`` (``"force"``, an observable or a
    probe) at every step whose control is at most ``end`` [mm]."""
    values = np.asarray(run.force if name == FORCE else run.observables[name], float)
    control = np.asarray(run.control, float)
    keep = control <= end * (1 + 1e-12) + 1e-15
    return {"control": control[keep], "values": values[keep]}


def check_control_points(values, what: str = "control_points") -> np.ndarray:
    """``values`` as a 1-D float array of finite, strictly increasing control values, or a ValueError."""
    try:
        points = np.asarray(values, dtype=float)
    except (TypeError, ValueError):
        raise TypeError(f"{what} is a {type(values).__name__} that is not an array of numbers") from None
    if points.ndim != 1 or points.size == 0:
        raise ValueError(f"{what} has shape {points.shape}; give a non-empty 1-D array of control values [mm] "
                         "(the data's control, e.g. ExperimentalData.control of one block)")
    if not np.all(np.isfinite(points)):
        raise ValueError(f"{what} holds NaN or infinite values; every control value must be a finite number")
    steps = np.diff(points)
    if np.any(steps <= 0):
        i = int(np.argmax(steps <= 0))
        raise ValueError(f"{what} must increase strictly, but point {i + 1} ({points[i + 1]:.6g} mm) does not "
                         f"exceed point {i} ({points[i]:.6g} mm)")
    return points


@dataclass(frozen=True, eq=False)
class Observation:
    """A curve quantity at control points: the computed counterpart of one measured curve.

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
    quantity: str = FORCE
    control: str | None = None
    name: str = "global"
    damage_threshold: float = 0.0

    def __post_init__(self):
        from fracid.models.forward import check_specimen

        check_specimen(self.specimen)
        object.__setattr__(self, "control_points", check_control_points(self.control_points))
        if not isinstance(self.quantity, str) or not self.quantity:
            raise TypeError(f"quantity = {self.quantity!r}; give 'force' or the name of an observable of the "
                            "forward run (e.g. 'fpz_width')")

    @property
    def run_key(self) -> tuple:
        """(specimen, control, threshold): observations with compatible keys share one forward run.

        The force does not depend on the threshold, so a force observation has threshold None.
        """
        return (specimen_key(self.specimen), self.control, None if self.quantity == FORCE else self.damage_threshold)

    @property
    def measures_force(self) -> bool:
        """Whether the block holds forces [N] (else a local observable [mm])."""
        return self.quantity == FORCE

    @property
    def size(self) -> int:
        return int(self.control_points.size)

    @property
    def controls(self) -> np.ndarray:
        return self.control_points

    @property
    def observables(self) -> tuple:
        return () if self.quantity == FORCE else (self.quantity,)  # observers cost time at every step

    @property
    def probes(self) -> dict:
        return {}

    def coordinates(self) -> dict:
        return {"control": self.control_points}

    def differentiable_with(self, model) -> bool:
        """The force, functionals and energies are; the specimen's ``observables`` and the model's
        ``observer_names`` only with a model whose ``differentiates_observers`` is true."""
        observers = {*getattr(self.specimen, "observables", ()), *getattr(model, "observer_names", ())}
        return bool(getattr(model, "differentiates_observers", False)) or self.quantity not in observers

    def key(self) -> dict:
        return {"specimen": self.specimen, "points": self.control_points.tolist(), "quantity": self.quantity,
                "control": self.control, "damage_threshold": self.damage_threshold}

    def sample(self, run) -> tuple:
        return interpolate(run, self.quantity, self.control_points)

    def curve(self, run) -> dict:
        """The run's own curve of the quantity: ``{"control": [mm], "values": [N or mm]}`` at every step of
        the run up to the last control point (an optional member of a kind: the report draws it, and the fit
        diagnostics judge the computed slope and peak on it rather than on the data's points)."""
        return run_curve(run, self.quantity, float(self.control_points[-1]))


__all__ = ["FORCE", "Observation", "ObservationKind", "check_control_points", "interpolate", "run_curve"]
