"""Local data derived from a DIC displacement field: the crack-opening profile and the process-zone width.

Two estimators turn the normal displacement u_n (u_x across a vertical crack) at the DIC points of one frame
into local data along the ligament:

- :class:`Extensometers`: virtual extensometers across the crack at heights along the ligament, the
  crack-opening profile w(y) [mm];
- :class:`StrainTransects`: the width [mm] of the zone where the strain normal to the crack exceeds a
  threshold, on transects across the crack at heights along the ligament (the thesis's local datum, the
  process-zone width, from a camera).

Both read u_n at a target position by a least-squares plane fit over the DIC points within ``radius`` of it
on the same side of the crack line (:func:`plane_fit_rows`): the value for an extensometer's end, the
gradient for a strain. The same estimator is applied to the data here (:func:`derived_block`: the values,
their covariance J C J^T, J the estimator's Jacobian over the field's entries and C the field's covariance)
and to the model's displacements at the same points by
:class:`~fracid.inverse.core.derived_observations.DerivedFieldObservation` (exact sensitivities by the chain
rule), so data and model are processed identically: the estimator's smoothing biases neither.

Conventions
-----------
The crack line is the specimen's (``Description.crack``: a straight node set, ``normal`` the axis across
it, at x_n = x_s). Offsets across the line are signed distances [mm], positive on the side of the modelled
part of a symmetric half model (the demo beam: the half x >= 0, the crack on x = 0 from the notch tip
y = 25 mm to the top y = 50 mm; offset d is x = d). An extensometer of half-length ``gauge`` d at height y
measures

- with points on both sides of the line (``pairs``): w = u_n(+d) - u_n(-d) (times the side's sign: the
  opening is positive);
- on a symmetric half (the model's, and data covering that half only): w = 2 u_n(+d), since by symmetry
  u_n(-d) = -u_n(+d) (and u_n = 0 on the line).

The opening includes the elastic stretch of the 2 d of material the gauge spans, as a physical
extensometer's does; the same gauge on the model gives the same quantity.

Rigid motion: a rigid motion u = t + theta (-y, x) is a linear field, which the plane fit reproduces
exactly. A strain is its gradient normal to the crack: 0 for every rigid motion, so the width is free of
it. A pair of ends at the same height sees the same u_n = t_x - theta y: the difference removes it
exactly. On a half, 2 u_n(+d) carries 2 (t_x - theta y) of the data's rigid motion, which the model
(fixed supports) does not have: give ``rigid_motion`` (per frame, e.g. from :func:`frame_rigid_motions`
of a field residual, subtracted from the data's displacements before the estimate, taken as exact), or
build the field block with ``rigid_std`` (its covariance then carries the rigid motion, and so does the
opening's W C W^T: the profile's mean and tilt in y become uninformative at each frame), or state that the
data have none (the camera referenced to the supports).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from fracid.data.arguments import numeric_array
from fracid.data.covariance_matrix import Dense
from fracid.data.dataset import ExperimentalData
from fracid.data.dic.field import FieldBlock
from fracid.data.dic.rigid import fit_rigid_motion, rigid_modes
from fracid.data.errors import DataError
from fracid.specimens.crack_line import CrackLine, crack_line

#: factor from the standard deviation of a zone's profile about the crack line to its width: a uniform
#: band of width b has std b / sqrt(12) about its centre
WIDTH_PER_STD = 2.0 * np.sqrt(3.0)


def _positive(value, what: str, unit: str = "mm") -> float:
    number = float(value)
    if not (np.isfinite(number) and number > 0):
        raise ValueError(f"{what} = {value!r} [{unit}]; give a finite number > 0")
    return number


def plane_fit_rows(points, present, target, radius: float, *, offsets=None, what: str = "target") -> tuple:
    """The least-squares plane fit of a field over the points near ``target``, as weights.

    The fit u ~ c0 + c1 (x - x_t) + c2 (y - y_t) over the present points within ``radius`` of the target
    (and, with ``offsets``, on the target's side of the crack line) is linear in the values: (c0, c1, c2)
    = R u, R = pinv(X).

    Parameters
    ----------
    points : ndarray (n, 2)
        The DIC points [mm].
    present : ndarray of bool (n,)
        Points with a value at this frame.
    target : ndarray (2,)
        Where the field is estimated [mm].
    radius : float
        Radius of the window [mm].
    offsets : (ndarray (n,), float), optional
        The points' signed offsets from the crack line and the target's [mm]: only the points on the
        target's side are used (the fit never spans the crack).
    what : str
        The target's description for the error message.

    Returns
    -------
    index : ndarray of int (k,)
        The points used.
    rows : ndarray (3, k)
        Weights of the value at the target [mm / mm] and of the gradient d/dx, d/dy [1/mm].

    Raises
    ------
    DataError
        With fewer than 3 points, or points on a line, in the window.
    """
    near = present & (np.hypot(*(points - target).T) <= radius)
    if offsets is not None:
        point_offsets, target_offset = offsets
        near &= np.sign(point_offsets) == np.sign(target_offset)
    index = np.flatnonzero(near)
    X = np.column_stack([np.ones(index.size), points[index] - target])
    if index.size < 3 or np.linalg.matrix_rank(X, tol=1e-6 * radius) < 3:
        raise DataError(f"{what} at ({target[0]:.4g}, {target[1]:.4g}) mm: {index.size} DIC point(s) within "
                        f"radius = {radius:g} mm on its side of the crack, not enough for a plane fit (3 not on a "
                        "line); give a larger radius, or a position where the data have points")
    return index, np.linalg.pinv(X)


def _matrix(entries, n_rows: int, n_points: int) -> np.ndarray:
    """A dense (n_rows, n_points) matrix from ``[(row, index, weights), ...]`` (weights summed)."""
    out = np.zeros((n_rows, n_points))
    for row, index, weights in entries:
        np.add.at(out[row], index, weights)
    return out


@dataclass(frozen=True)
class Extensometers:
    """Virtual extensometers across the crack: the crack-opening profile w [mm] at heights along the ligament.

    Parameters
    ----------
    line : CrackLine
        The specimen's crack line (:func:`crack_line`).
    heights : array_like
        Positions along the line [mm], within the ligament, increasing.
    gauge : float
        Half-length d of every gauge [mm]: the ends at offsets +d (and -d) from the line, larger than the
        band of missing points along the crack.
    radius : float
        Radius of the plane fit around each end [mm] (about 1.5 DIC point spacings or more).
    pairs : bool
        True: w = u_n(+d) - u_n(-d) (data on both sides of the crack; removes the rigid motion). False:
        w = 2 u_n(+d), the symmetric half (see the module's conventions).

    The estimate is linear, w = A u_n (:meth:`evaluate`), per frame.
    """

    line: CrackLine
    heights: np.ndarray
    gauge: float
    radius: float
    pairs: bool = False

    def __post_init__(self):
        object.__setattr__(self, "heights", self.line.check_heights(self.heights))
        object.__setattr__(self, "gauge", _positive(self.gauge, "gauge"))
        object.__setattr__(self, "radius", _positive(self.radius, "radius"))
        if not self.pairs and not self.line.mirrored:
            raise ValueError("pairs = False needs a symmetric half model (the crack line a symmetry line); this "
                             "crack line is not one: give pairs=True and data on both sides of the crack")

    @property
    def size(self) -> int:
        """Values per frame."""
        return int(self.heights.size)

    def ends(self) -> tuple:
        """((end points (n, 2), signed offset, weight of u_n there), ...) [mm]: one or two per gauge."""
        side = self.line.side
        if self.pairs:
            return ((self.line.place(self.gauge, self.heights), self.gauge, side),
                    (self.line.place(-self.gauge, self.heights), -self.gauge, -side))
        return ((self.line.place(self.gauge, self.heights), self.gauge, 2.0 * side),)

    def matrix(self, points, present) -> np.ndarray:
        """A (n_heights, n_points): w = A u_n at one frame [mm], the points ``present`` only."""
        offsets = self.line.offsets(points)
        entries = []
        for targets, offset, factor in self.ends():
            for i, target in enumerate(targets):
                what = f"gauge end at height {self.heights[i]:g} mm, offset {offset:+g} mm (gauge = {self.gauge:g})"
                index, rows = plane_fit_rows(points, present, target, self.radius, offsets=(offsets, offset),
                                             what=what)
                entries.append((i, index, factor * rows[0]))
        return _matrix(entries, self.size, len(points))

    def evaluate(self, points, present, values) -> tuple:
        """(w (n_heights,) [mm], dw/du_n (n_heights, n_points)) from u_n at the points (missing ones ignored)."""
        A = self.matrix(points, present)
        return A @ np.where(present, values, 0.0), A

    def coordinates(self) -> dict:
        """``{"height": (n_heights,)}`` [mm]."""
        return {"height": self.heights}

    def key(self) -> dict:
        return {"estimator": "extensometers", "heights": self.heights.tolist(), "gauge": self.gauge,
                "radius": self.radius, "pairs": self.pairs}


@dataclass(frozen=True)
class StrainTransects:
    """The process-zone width [mm] from the strain normal to the crack, on transects across it.

    Parameters
    ----------
    line : CrackLine
        The specimen's crack line.
    heights : array_like
        Positions along the line [mm], within the ligament, increasing: one width each.
    offsets : array_like
        Signed distances of the transect's samples from the line [mm] (positive on the modelled side, negative
        only with data on the other side), nonzero, increasing, evenly spaced for the sums to be integrals.
    radius : float
        Radius of the plane fit giving the strain at each sample [mm].
    threshold : float
        Strain above which a sample counts [-] (e.g. a few times the strain at damage onset kappa_i).

    Notes
    -----
    At each sample the strain eps = d u_n / d x_n is the gradient of the plane fit (linear in u_n: the
    rigid motion has none). Its excess e = max(eps - threshold, 0)^2 (differentiable) weighs the samples;
    the width is 2 sqrt(3) times their standard deviation about the crack line,
    w = 2 sqrt(3) sqrt(sum o_i^2 e_i / sum e_i), so that a uniform band of width b gives b. No excess on a
    transect gives w = 0 (and a zero derivative).
    """

    line: CrackLine
    heights: np.ndarray
    offsets: np.ndarray
    radius: float
    threshold: float

    def __post_init__(self):
        object.__setattr__(self, "heights", self.line.check_heights(self.heights))
        offsets = np.atleast_1d(np.asarray(self.offsets, dtype=float))
        if offsets.ndim != 1 or offsets.size < 2 or not np.all(np.isfinite(offsets)) or np.any(offsets == 0) or np.any(
                np.diff(offsets) <= 0):
            raise ValueError(f"offsets = {self.offsets!r}; give at least 2 nonzero, strictly increasing distances "
                             "from the crack line [mm] (positive on the modelled side)")
        object.__setattr__(self, "offsets", offsets)
        object.__setattr__(self, "radius", _positive(self.radius, "radius"))
        threshold = float(self.threshold)
        if not np.isfinite(threshold):
            raise ValueError(f"threshold = {self.threshold!r}; give a finite strain [-]")
        object.__setattr__(self, "threshold", threshold)

    @property
    def size(self) -> int:
        """Values per frame."""
        return int(self.heights.size)

    def strain_matrix(self, points, present) -> np.ndarray:
        """G (n_heights * n_offsets, n_points): the strains eps = G u_n [-] at the samples (height slowest)."""
        point_offsets = self.line.offsets(points)
        entries = []
        for i, height in enumerate(self.heights):
            for j, (offset, target) in enumerate(zip(self.offsets, self.line.place(self.offsets, height))):
                what = f"strain sample at height {height:g} mm, offset {offset:+g} mm"
                index, rows = plane_fit_rows(points, present, target, self.radius, offsets=(point_offsets, offset),
                                             what=what)
                entries.append((i * self.offsets.size + j, index, rows[1 + self.line.normal]))
        return _matrix(entries, self.size * self.offsets.size, len(points))

    def widths(self, strains) -> tuple:
        """(w (n_heights,) [mm], dw/deps (n_heights, n_heights * n_offsets)) from the samples' strains."""
        eps = np.asarray(strains, float).reshape(self.size, self.offsets.size)
        excess = np.maximum(eps - self.threshold, 0.0)
        e, de = excess**2, 2.0 * excess
        total = e.sum(axis=1)
        moment = e @ self.offsets**2
        width = np.zeros(self.size)
        J = np.zeros((self.size, eps.size))
        for i in np.flatnonzero(total > 0):
            variance = moment[i] / total[i]
            width[i] = WIDTH_PER_STD * np.sqrt(variance)
            dw_de = WIDTH_PER_STD * (self.offsets**2 - variance) / (2.0 * np.sqrt(variance) * total[i])
            J[i, i * self.offsets.size:(i + 1) * self.offsets.size] = dw_de * de[i]
        width[np.isnan(total)] = np.nan  # a frame not reached
        return width, J

    def evaluate(self, points, present, values) -> tuple:
        """(w (n_heights,) [mm], dw/du_n (n_heights, n_points) [mm/mm]) from u_n at the points."""
        G = self.strain_matrix(points, present)
        width, J = self.widths(G @ np.where(present, values, 0.0))
        return width, J @ G

    def coordinates(self) -> dict:
        """``{"height": (n_heights,)}`` [mm]."""
        return {"height": self.heights}

    def key(self) -> dict:
        return {"estimator": "strain-transects", "heights": self.heights.tolist(), "offsets": self.offsets.tolist(),
                "radius": self.radius, "threshold": self.threshold}


@dataclass(frozen=True, eq=False)
class DerivedBlock:
    """A derived data block and what its model-side observation needs.

    Attributes
    ----------
    data : ExperimentalData
        One block of n_frames x estimator.size values (frame slowest, height fastest), their covariance
        J C J^T and the frame's control value of every entry [mm].
    estimator : Extensometers or StrainTransects
        The estimator applied to u_n at the points.
    points : ndarray (n_points, 2)
        The field's DIC points [mm] (specimen frame).
    frames : ndarray (n_frames,)
        Control value of each frame [mm].
    present : ndarray of bool (n_frames, n_points)
        The points with a u_n value at each frame (the estimator used these only).
    jacobian : ndarray (n_y, field.data.n_y)
        d y / d (the field's values) at the data: the estimate's weights W for the opening profile (y = W u),
        the linearisation J for the width; the covariance is J C J^T.
    """

    data: ExperimentalData
    estimator: object
    points: np.ndarray
    frames: np.ndarray
    present: np.ndarray
    jacobian: np.ndarray


def field_normals(field: FieldBlock, normal: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The normal component u_n of a field block per frame.

    Returns
    -------
    values : ndarray (n_frames, n_points)
        u_n [mm], NaN where missing.
    present : ndarray of bool (n_frames, n_points)
    entry : ndarray of int (n_frames, n_points)
        Position of each value in ``field.data.y`` (-1 where missing).
    """
    if normal not in field.components:
        raise DataError(f"the field block has components {list(field.components)}; the crack's normal "
                        f"displacement (component {normal}: {'uv'[normal]}) is needed: include {'uv'[normal]!r}")
    shape = (len(field.frames), len(field.components), len(field.points))
    entry = np.full(field.keep.size, -1)
    entry[field.keep] = np.arange(int(field.keep.sum()))
    entry = entry.reshape(shape)[:, field.components.index(normal)]
    present = entry >= 0
    values = np.where(present, field.data.y[np.maximum(entry, 0)], np.nan)
    return values, present, entry


def _rigid_per_frame(rigid_motion, n_frames: int) -> np.ndarray:
    """``rigid_motion`` ((3,) or (n_frames, 3)) broadcast to one finite row per frame, or a DataError."""
    motion = numeric_array(rigid_motion, "rigid_motion")
    if motion.shape not in ((3,), (n_frames, 3)) or not np.all(np.isfinite(motion)):
        raise DataError(f"rigid_motion has shape {motion.shape}; give (t_x [mm], t_y [mm], theta [rad]) or one such "
                        f"row per frame, shape ({n_frames}, 3), finite")
    return np.broadcast_to(motion, (n_frames, 3))


def derived_block(field: FieldBlock, estimator, *, name: str, rigid_motion=None, notes=()) -> DerivedBlock:
    """The data block of ``estimator`` applied to a DIC field block, with its covariance by linearisation.

    Parameters
    ----------
    field : FieldBlock
        From :func:`fracid.data.dic.field_block` (with the crack's normal component).
    estimator : Extensometers or StrainTransects
        What is derived from u_n at each frame.
    name : str
        Name of the block.
    rigid_motion : array_like, shape (3,) or (n_frames, 3), optional
        (t_x [mm], t_y [mm], theta [rad]) of every frame, subtracted from the data's u_n first (taken as
        exact); None: none subtracted.
    notes : sequence of str
        What to record about the estimator.

    Returns
    -------
    DerivedBlock
        y = f(u_n) per frame; covariance J C J^T [mm^2] with J = d f / d u over the field's entries and C
        the field's covariance (exact for a linear f: the opening profile).

    Raises
    ------
    DataError
        A field without the normal component, too few points near an estimate, a bad ``rigid_motion``, or
        a value with no variance (a width with no strain above the threshold at a frame).
    """
    line = estimator.line
    values, present, entry = field_normals(field, line.normal)
    n_frames, m = len(field.frames), estimator.size
    applied = ()
    if rigid_motion is not None:
        motion = _rigid_per_frame(rigid_motion, n_frames)
        values = values - motion @ rigid_modes(field.points, [line.normal]).T
        applied = (f"rigid motion subtracted from u_{'xy'[line.normal]} at every frame: "
                   f"{np.round(motion, 8).tolist()} (t_x mm, t_y mm, theta rad)",)
    y = np.empty(n_frames * m)
    W = np.zeros((n_frames * m, field.data.n_y))
    for k in range(n_frames):
        try:
            y[k * m:(k + 1) * m], J = estimator.evaluate(field.points, present[k], values[k])
        except DataError as error:
            raise DataError(f"{name!r}, frame at control {field.frames[k]:.6g} mm: {error}") from None
        W[k * m:(k + 1) * m, entry[k, present[k]]] = J[:, present[k]]
    used = np.flatnonzero(np.any(W != 0.0, axis=0))
    covariance = (W[:, used] @ field.data.covariance.take(used).dense() @ W[:, used].T if used.size
                  else np.zeros((y.size, y.size)))
    covariance = 0.5 * (covariance + covariance.T)  # symmetric to rounding (a large rigid-motion prior breaks it)
    variance = np.diag(covariance)
    if np.any(variance <= 0):
        i = int(np.argmax(variance <= 0))
        raise DataError(f"{name!r}: the value at height {estimator.heights[i % m]:g} mm, frame at control "
                        f"{field.frames[i // m]:.6g} mm has no variance (it does not depend on the data: e.g. a width "
                        "with at most one sample above the threshold); leave that frame out or lower the threshold")
    data = ExperimentalData(control=np.repeat(field.frames, m), y=y, covariance=Dense(covariance),
                            blocks=((name, 0, y.size),),
                            notes=(*field.data.notes, *notes, *applied,
                                   f"{name!r}: covariance J C J^T from the field's covariance over the {used.size} "
                                   "values the estimates use"))
    W.setflags(write=False)
    return DerivedBlock(data, estimator, field.points, field.frames, present, W)


def _sides(field: FieldBlock, line: CrackLine, pairs) -> bool:
    """``pairs`` or, if None, whether the field has points on both sides of the crack line."""
    if pairs is not None:
        return bool(pairs)
    return bool(np.any(line.offsets(field.points) < 0))


def opening_profile(field: FieldBlock, specimen, heights, gauge: float, *, radius: float, pairs: bool | None = None,
                    rigid_motion=None, name: str = "opening") -> DerivedBlock:
    """The crack-opening profile of a DIC field: virtual extensometers across the crack along the ligament.

    Parameters
    ----------
    field : FieldBlock
        The DIC field block (:func:`fracid.data.dic.field_block`, with u: the crack's normal component).
    specimen
        The specimen (or its description): its crack line (:func:`crack_line`).
    heights : array_like
        Positions of the gauges along the ligament [mm], increasing, within the crack path.
    gauge : float
        Half-length d of the gauges [mm], larger than the band of missing points near the crack.
    radius : float
        Radius of the plane fit around each gauge end [mm].
    pairs : bool, optional
        Ends on both sides (w = u_n(+d) - u_n(-d), rigid motion removed) or one (w = 2 u_n(+d), the symmetric
        half); None: pairs if the field has points on both sides of the crack line.
    rigid_motion : array_like, shape (3,) or (n_frames, 3), optional
        Rigid motion subtracted from the data first (on a half: see the module's conventions).
    name : str
        Name of the block.

    Returns
    -------
    DerivedBlock
        w [mm] at every frame and height (frame slowest), covariance W C W^T [mm^2].

    Raises
    ------
    ValueError
        Heights outside the ligament, gauge or radius <= 0 (named); DataError: no points near a gauge end
        (the end named), no normal component.
    """
    line = crack_line(specimen)
    estimator = Extensometers(line, heights, gauge, radius, _sides(field, line, pairs))
    form = ("u_n(+d) - u_n(-d) (both sides: the rigid motion cancels)" if estimator.pairs else
            "2 u_n(+d) (symmetric half: the data's rigid motion adds 2 (t_x - theta y), unless subtracted with "
            "rigid_motion; a field covariance with rigid_std carries it into W C W^T)")
    note = (f"{name!r}: crack-opening profile by virtual extensometers of half-length {estimator.gauge:g} mm at "
            f"heights {estimator.heights.tolist()} mm, w = {form}, u_n at each end by a plane fit over the points "
            f"within {estimator.radius:g} mm")
    return derived_block(field, estimator, name=name, rigid_motion=rigid_motion, notes=(note,))


def process_zone_width(field: FieldBlock, specimen, heights, offsets, *, radius: float, threshold: float,
                       name: str = "fpz_width") -> DerivedBlock:
    """The process-zone width of a DIC field: the spread of the strain above ``threshold`` across the crack.

    Parameters
    ----------
    field : FieldBlock
        The DIC field block (with the crack's normal component).
    specimen
        The specimen (or its description).
    heights : array_like
        Positions of the transects along the ligament [mm].
    offsets : array_like
        Signed distances of each transect's samples from the crack line [mm] (:class:`StrainTransects`).
    radius : float
        Radius of the plane fit giving the strain at each sample [mm].
    threshold : float
        Strain above which a sample counts [-].
    name : str
        Name of the block.

    Returns
    -------
    DerivedBlock
        w [mm] at every frame and height; covariance J C J^T [mm^2] by linearisation at the data.

    Raises
    ------
    ValueError, DataError
        As :func:`opening_profile`; a frame where no sample exceeds the threshold (no variance).
    """
    estimator = StrainTransects(crack_line(specimen), heights, offsets, radius, threshold)
    note = (f"{name!r}: process-zone width 2 sqrt(3) std of max(eps - {estimator.threshold:g}, 0)^2 over offsets "
            f"{estimator.offsets.tolist()} mm at heights {estimator.heights.tolist()} mm, eps = du_n/dx_n by a plane "
            f"fit over the points within {estimator.radius:g} mm; covariance linearised at the data")
    return derived_block(field, estimator, name=name, notes=(note,))


def frame_rigid_motions(field: FieldBlock, model) -> np.ndarray:
    """The rigid motion of every frame of a field block's residual (data minus ``model``), by generalised
    least squares (:func:`fracid.data.dic.rigid.fit_rigid_motion` with the frame's covariance).

    Parameters
    ----------
    field : FieldBlock
    model : array_like, shape (field.data.n_y,)
        The model's values of the block's entries [mm] (e.g. the field observation's at an estimate).

    Returns
    -------
    ndarray (n_frames, 3)
        (t_x [mm], t_y [mm], theta [rad]) of every frame, for ``rigid_motion`` of :func:`opening_profile`.
    """
    model = np.asarray(model, float)
    if model.shape != field.data.y.shape:
        raise DataError(f"model has shape {model.shape}; give the model's value of every entry of the field block, "
                        f"shape {field.data.y.shape}")
    n = len(field.components) * len(field.points)
    residual = np.full(field.keep.size, np.nan)
    residual[field.keep] = field.data.y - model
    position = np.cumsum(field.keep) - 1  # entry of each kept value
    motions = []
    for k in range(len(field.frames)):
        kept = field.keep[k * n:(k + 1) * n]
        covariance = field.data.covariance.take(position[k * n:(k + 1) * n][kept])
        motions.append(fit_rigid_motion(field.points, field.components, residual[k * n:(k + 1) * n], covariance)[0])
    return np.array(motions)


__all__ = ["CrackLine", "DerivedBlock", "Extensometers", "StrainTransects", "crack_line", "derived_block",
           "field_normals", "frame_rigid_motions", "opening_profile", "plane_fit_rows", "process_zone_width"]
