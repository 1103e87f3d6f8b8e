"""The straight crack line of a plane specimen: where a crack runs, which side is modelled, and its mirror.

A notched beam or a wedge-splitting specimen modelled as a symmetric half has its crack on the symmetry line
(``Description.crack``, ``mirrored``): a point of the other half behaves as its mirror image with the normal
displacement's sign flipped. The derived DIC data (:mod:`fracid.data.dic.derived`: virtual extensometers and
strain transects across the crack) and the field observation (points on both halves,
:class:`fracid.inverse.core.field_observations.FieldObservation`) read the line from here.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from fracid.specimens.description import described


@dataclass(frozen=True)
class CrackLine:
    """The straight crack line of a plane specimen, in the specimen frame.

    Attributes
    ----------
    normal : int
        Axis across the crack (0: x, 1: y); ``along`` is the other.
    position : float
        Coordinate x_s of the line along ``normal`` [mm].
    side : float
        +1 if the modelled part lies at x_n > x_s, -1 if below (the sign that makes an offset positive there).
    extent : (float, float)
        The crack path's range along the line [mm] (the ligament: the notch tip to the top).
    mirrored : bool
        The line is a symmetry line of the model (a half model).
    """

    normal: int
    position: float
    side: float
    extent: tuple
    mirrored: bool

    @property
    def along(self) -> int:
        """Axis along the crack line."""
        return 1 - self.normal

    def offsets(self, points) -> np.ndarray:
        """Signed distance [mm] of ``points`` (n, 2) to the line, positive on the modelled side."""
        return self.side * (np.asarray(points, float)[:, self.normal] - self.position)

    def place(self, offsets, heights) -> np.ndarray:
        """Points (n, 2) [mm] at signed ``offsets`` from the line and ``heights`` along it (broadcast)."""
        offsets, heights = np.broadcast_arrays(np.asarray(offsets, float), np.asarray(heights, float))
        points = np.empty((offsets.size, 2))
        points[:, self.normal] = self.position + self.side * offsets.ravel()
        points[:, self.along] = heights.ravel()
        return points

    def mirror(self, points) -> np.ndarray:
        """``points`` (n, 2) reflected across the line [mm]."""
        out = np.array(points, float)
        out[:, self.normal] = 2.0 * self.position - out[:, self.normal]
        return out

    def check_heights(self, heights, what: str = "heights") -> np.ndarray:
        """``heights`` [mm] as a 1-D float array within :attr:`extent`, strictly increasing, or a ValueError."""
        values = np.atleast_1d(np.asarray(heights, dtype=float))
        lo, hi = self.extent
        if values.ndim != 1 or values.size == 0 or not np.all(np.isfinite(values)):
            raise ValueError(f"{what} = {heights!r}; give finite positions [mm] along the crack line")
        outside = values[(values < lo) | (values > hi)]
        if outside.size:
            raise ValueError(f"{what} = {values.tolist()}: {outside.tolist()} mm lie outside the ligament "
                             f"[{lo:g}, {hi:g}] mm (the crack path along the line); give heights within it")
        if np.any(np.diff(values) <= 0):
            raise ValueError(f"{what} = {values.tolist()} must increase strictly")
        return values


def crack_line(specimen) -> CrackLine:
    """The :class:`CrackLine` of a plane specimen (or its description), from ``Description.crack``.

    Raises
    ------
    ValueError
        For a specimen without a straight crack path (node set) or not plane.
    """
    d = described(specimen)
    crack = d.crack
    if d.dim != 2 or crack is None or crack.nodes is None:
        raise ValueError(f"{type(specimen).__name__}: derived DIC data need a plane specimen with a straight crack "
                         "path (Description.crack with a node set); this one has none")
    line = d.nodes[d.nodes_of(crack.nodes)]
    normal = int(crack.normal)
    position = float(line[:, normal].mean())
    side = 1.0 if d.nodes[:, normal].mean() >= position else -1.0
    along = line[:, 1 - normal]
    return CrackLine(normal, position, side, (float(along.min()), float(along.max())), bool(crack.mirrored))


__all__ = ["CrackLine", "crack_line"]
