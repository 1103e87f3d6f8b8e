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
- :class:`FieldObservation`: a nodal displacement component sampled at given points (a sensor, the
  pixels a camera follows) at given control values (frames), through the point-probe operator
  :func:`~fracid.fem.mesh.probes.probe_matrix` (through :mod:`fracid.models`, the inverse code's window on the model).

A kind may also have ``probe_matrix()``: a scipy.sparse matrix (n_probes x n_u) over the nodal
displacement vector; the operator stacks those of the kinds of one run and the run applies it to the
state (and its derivatives) at the checkpoint steps only (``follow_path(probes=...)``,
``PathResult.probed``), handing each kind its rows. :class:`FieldObservation` samples that way.

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
import scipy.sparse as sp

from fracid.inverse.core.probed import describe, specimen_key


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
    values = run.force if name == "force" else run.observables[name]
    y = np.interp(points, run.control, values)
    derivative = (getattr(run, "derivatives", None) or {}).get(name)
    if derivative is None:
        return y, None
    return y, np.column_stack([np.interp(points, run.control, d) for d in np.asarray(derivative).T])


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
    quantity: str = "force"
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
        return (specimen_key(self.specimen), self.control, None if self.quantity == "force" else self.damage_threshold)

    @property
    def size(self) -> int:
        return int(self.control_points.size)

    @property
    def controls(self) -> np.ndarray:
        return self.control_points

    @property
    def observables(self) -> tuple:
        return () if self.quantity == "force" else (self.quantity,)  # observers cost time at every step

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


def _components(components) -> tuple:
    values = (components,) if isinstance(components, (int, np.integer)) else tuple(components)
    if not values or len(set(values)) != len(values) or any(c not in (0, 1) for c in values):
        raise ValueError(f"components = {components!r}; give 0 (x), 1 (y) or both, e.g. (0, 1)")
    return tuple(int(c) for c in values)


def check_points(points) -> np.ndarray:
    positions = np.asarray(points, dtype=float)
    if positions.ndim != 2 or positions.shape[1] != 2 or len(positions) == 0 or not np.all(np.isfinite(positions)):
        raise ValueError(f"points has shape {positions.shape}; give (n_points, 2) finite coordinates [mm] in the "
                         "plane of the specimen's mesh")
    return positions


def _kept(keep, shape: tuple) -> np.ndarray | None:
    """``keep`` as a flat boolean mask of ``prod(shape)`` entries (frame, component, point order), or None."""
    if keep is None:
        return None
    mask = np.asarray(keep)
    n = int(np.prod(shape))
    if mask.dtype != bool or mask.shape not in (shape, (n,)):
        raise ValueError(f"keep has dtype {mask.dtype} and shape {mask.shape}; give booleans of shape {shape} "
                         f"(frames, components, points) or ({n},), True for the entries the data have")
    if not mask.any():
        raise ValueError("keep holds no True value: the field block would be empty; keep at least one entry")
    mask = mask.reshape(-1).copy()
    mask.setflags(write=False)
    return mask


@dataclass(frozen=True, eq=False)
class FieldObservation:
    """Displacement components at given points and control values (frames): a block of size
    n_frames x n_components x n_points, in that order (frame slowest, point fastest).

    Parameters
    ----------
    specimen
        A plane specimen object (with ``describe()``) or a description.
    points : array_like, shape (n_points, 2)
        Positions [mm] in the specimen frame: in the modelled part, or, for a half modelled about its crack
        line (``Description.crack.mirrored``), in the other half too (sampled at the mirror image with the
        normal component's sign flipped: :func:`mirrored_points`).
    frames : array_like
        Increasing control values of the frames [mm].
    components : int or tuple of int
        0 (u_x), 1 (u_y) or both (default).
    control : str or None
        The specimen's control quantity (its default if None).
    name : str
        Label of the block (and prefix of its probes' names in the run).
    keep : array_like of bool, shape (n_frames, n_components, n_points) or (n_frames * n_components * n_points,), optional
        The entries the data have (NaN holes, points of low quality, a region of interest dropped): ``size``,
        ``controls``, ``coordinates()`` and ``sample`` then cover the kept entries only, in the same order.
        None (default): every entry.

    Raises
    ------
    ValueError
        For points outside the mesh (named), bad frames, components or keep.

    Notes
    -----
    The block's sparse probe matrix (:meth:`probe_matrix`: one row per component and point, the
    shape functions of the point's element as weights) is applied by the run to the nodal
    displacements and their derivatives at the frames only, so ``sample`` gives exact sensitivities
    with a model that differentiates its runs and the cost stays O(points) per frame (digital image
    correlation at thousands of points).
    """

    specimen: object
    points: np.ndarray
    frames: np.ndarray
    components: tuple = (0, 1)
    control: str | None = None
    name: str = "field"
    keep: np.ndarray | None = None

    def __post_init__(self):
        from fracid.models import probe_matrix
        from fracid.models.forward import check_specimen

        check_specimen(self.specimen)
        object.__setattr__(self, "points", check_points(self.points))
        object.__setattr__(self, "frames", check_control_points(self.frames, "frames"))
        object.__setattr__(self, "components", _components(self.components))
        shape = (len(self.frames), len(self.components), len(self.points))
        object.__setattr__(self, "keep", _kept(self.keep, shape))
        d = describe(self.specimen)
        if d.dim != 2:
            raise ValueError(f"a field observation needs a plane specimen; {type(self.specimen).__name__} is {d.dim}D")
        sampled, sign = mirrored_points(d, self.points)
        P = probe_matrix(d.nodes, d.cells, sampled).tocoo()
        rows = [sp.csr_matrix((P.data * (sign[c][P.row]), (P.row, 2 * P.col + c)), shape=(P.shape[0], 2 * P.shape[1]))
                for c in self.components]
        object.__setattr__(self, "_matrix", sp.vstack(rows, format="csr"))

    def probe_matrix(self) -> sp.csr_matrix:
        """The sparse matrix (n_components x n_points, n_u) over the nodal displacement vector (dof
        ``2 j + c`` is component c of node j) whose rows give the block's values at one frame
        (component, then point) [mm]."""
        return self._matrix

    quantity = property(lambda self: "u")  # what the block measures, as a curve kind's ``quantity``

    @property
    def run_key(self) -> tuple:
        return (specimen_key(self.specimen), self.control, None)

    def _kept_entries(self, values: np.ndarray) -> np.ndarray:
        """``values`` over all entries (first axis) restricted to the kept ones."""
        return values if self.keep is None else values[self.keep]

    @property
    def size(self) -> int:
        full = len(self.frames) * len(self.components) * len(self.points)
        return full if self.keep is None else int(np.count_nonzero(self.keep))

    @property
    def controls(self) -> np.ndarray:
        return self._kept_entries(np.repeat(self.frames, len(self.components) * len(self.points)))

    control_points = controls  # the control value of every entry, as a curve kind's

    @property
    def observables(self) -> tuple:
        return ()

    @property
    def probes(self) -> dict:
        return {}  # no dense functionals: the run applies probe_matrix() at the frames

    def coordinates(self) -> dict:
        n_c, n_p = len(self.components), len(self.points)
        frame = np.repeat(np.arange(len(self.frames)), n_c * n_p)
        component = np.tile(np.repeat(self.components, n_p), len(self.frames))
        point = np.tile(np.arange(n_p), len(self.frames) * n_c)
        full = {"control": self.frames[frame], "frame": frame, "component": component, "point": point,
                "x": self.points[point, 0], "y": self.points[point, 1]}
        return {name: self._kept_entries(values) for name, values in full.items()}

    def differentiable_with(self, model) -> bool:
        return True  # functionals of the displacements

    def key(self) -> dict:
        return {"kind": "field", "specimen": self.specimen, "points": self.points.tolist(),
                "frames": self.frames.tolist(), "components": list(self.components), "control": self.control,
                "name": self.name, "keep": None if self.keep is None else np.flatnonzero(~self.keep).tolist()}

    def sample(self, run) -> tuple:
        """``(y, S)`` from ``run.probed`` (a run with this block's probe matrix and its frames among the
        checkpoints: the frames are steps, nothing is interpolated); NaN for frames not reached; the kept
        entries only."""
        values, derivatives = run.probed_at(self.frames)  # (n_frames, n_rows), (n_frames, n_rows, p)
        y = values.ravel()  # frame-major
        S = None if derivatives is None else self._kept_entries(derivatives.reshape(y.size, -1))
        return self._kept_entries(y), S


def mirrored_points(description, points) -> tuple[np.ndarray, dict]:
    """Where the model samples ``points`` (n, 2) [mm], and the sign of each component there.

    A specimen modelled as a symmetric half (its crack on the symmetry line: ``Description.crack.mirrored``)
    computes a point of the other half as its mirror image, the normal displacement's sign flipped: a camera
    that sees both halves is compared with the model on both. Other points are sampled where they are.

    Returns
    -------
    sampled : ndarray (n, 2)
        The positions in the model [mm].
    sign : dict
        ``{component: ndarray (n,)}`` of +1 / -1 for components 0 (u_x) and 1 (u_y).
    """
    from fracid.specimens.crack_line import crack_line

    points = np.asarray(points, float)
    crack = getattr(description, "crack", None)
    other = np.zeros(len(points), dtype=bool)
    sampled = points
    if crack is not None and crack.nodes is not None and crack.mirrored:
        line = crack_line(description)
        other = line.offsets(points) < 0.0
        sampled = np.where(other[:, None], line.mirror(points), points)
    flip = {c: np.where(other & (c == getattr(crack, "normal", -1)), -1.0, 1.0) for c in (0, 1)}
    return sampled, flip


def field_observation(block, specimen, *, control: str | None = None, name: str | None = None) -> FieldObservation:
    """The :class:`FieldObservation` of a DIC data block (:func:`fracid.data.dic.field_block`: its points,
    frames as control values, components and mask of the values present) on ``specimen``."""
    return FieldObservation(specimen, block.points, block.frames, block.components, control=control,
                            name=block.data.blocks[0][0] if name is None else name, keep=block.keep)
