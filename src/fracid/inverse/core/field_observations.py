"""The observation kind of a displacement field: :class:`FieldObservation`, nodal displacement components sampled
at given points (a sensor, the pixels a camera follows) at given control values (frames), through the sparse
point-probe operator :func:`~fracid.fem.mesh.probes.probe_matrix` (through :mod:`fracid.models`, the inverse
code's window on the model), applied by the run at the frames only (:mod:`fracid.inverse.core.observations`).
A specimen modelled as a symmetric half samples the points of the other half at their mirror image
(:func:`mirrored_points`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from fracid.inverse.core.observations import check_control_points
from fracid.inverse.core.probed import describe, specimen_key


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
    measures_force = False  # displacements [mm]

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

    def view_extras(self) -> dict:
        """What the report's view needs besides the coordinates: ``crack``, the specimen's straight crack line
        (:func:`~fracid.specimens.crack_line.crack_line`; None when it has none), for the opening profile and
        the process-zone width."""
        from fracid.specimens.crack_line import crack_line

        try:
            return {"crack": crack_line(self.specimen)}
        except ValueError:
            return {"crack": None}

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


def points_outside(specimen, points) -> np.ndarray:
    """True for the points (n, 2) [mm] that a :class:`FieldObservation` on ``specimen`` cannot sample: outside
    its mesh (a symmetric half's other half taken at its mirror image, as the observation samples it), found by
    the probes' element search."""
    from fracid.models import find_elements

    d = describe(specimen)
    sampled, _ = mirrored_points(d, check_points(points))
    return find_elements(d.nodes, d.cells, sampled)[0] < 0


def field_observation(block, specimen, *, control: str | None = None, name: str | None = None) -> FieldObservation:
    """The :class:`FieldObservation` of a DIC data block (:func:`fracid.data.dic.field_block`: its points,
    frames as control values, components and mask of the values present) on ``specimen``."""
    return FieldObservation(specimen, block.points, block.frames, block.components, control=control,
                            name=block.data.blocks[0][0] if name is None else name, keep=block.keep)


__all__ = ["FieldObservation", "check_points", "field_observation", "mirrored_points", "points_outside"]
