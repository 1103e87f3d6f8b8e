"""The estimators of local data from a DIC displacement field, applied alike to the data and to the model.

Two estimators turn the normal displacement u_n (u_x across a vertical crack) at the DIC points of one frame
into local data along the ligament:

- :class:`Extensometers`: virtual extensometers across the crack at heights along the ligament, the
  crack-opening profile w(y) [mm];
- :class:`StrainTransects`: the width [mm] of the zone where the strain normal to the crack exceeds a
  threshold, on transects across the crack at heights along the ligament (the thesis's local datum, the
  process-zone width, from a camera).

Both read u_n at a target position by a least-squares plane fit over the DIC points within ``radius`` of it
on the same side of the crack line (:func:`plane_fit_rows`): the value for an extensometer's end, the
gradient for a strain. Each gives its values and their Jacobian over u_n (``evaluate``): the data side is
:func:`fracid.data.dic.derived.derived_block`, the model side
:class:`~fracid.inverse.core.derived_observations.DerivedFieldObservation`.

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
extensometer's does; the same gauge on the model gives the same quantity. A rigid motion is linear, which
the plane fit reproduces exactly: a strain (its gradient normal to the crack) is free of it, and so is a
pair of ends at the same height; see :mod:`fracid.data.dic.derived` for a half.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from fracid.data.errors import DataError
from fracid.specimens.crack_line import CrackLine

__all__ = ["WIDTH_PER_STD", "Extensometers", "StrainTransects", "plane_fit_rows"]


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
