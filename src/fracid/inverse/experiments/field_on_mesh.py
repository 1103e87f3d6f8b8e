"""Where the points of a DIC field fall on the specimen's mesh, found while the configuration is checked.

The model samples a field at its points through the mesh's elements (the probe matrix of
:class:`~fracid.inverse.core.field_observations.FieldObservation`); a point outside the mesh cannot be sampled.
:func:`points_on_mesh` locates the points with the probes' own element search (a symmetric half's other half at
its mirror image, as the observation samples it) and decides:

- a few points outside (at most :data:`MAX_OUTSIDE_FRACTION` of them): dropped with a warning. They are the
  subsets at the specimen's free edges, in the notch's slot or at a rounded corner, whose centres a pixel of
  placement error puts outside the modelled geometry: the rest of the field is usable and its placement right;
- more: refused. So many points off the specimen mean the placement is wrong (units, origin, a mirrored axis),
  and the points left inside would be compared with the model at the wrong places. The message gives both
  bounding boxes and, when every point is outside, the likely cause.
"""

from __future__ import annotations

import numpy as np

from fracid.data import DataError
from fracid.inverse.core.field_observations import points_outside
from fracid.inverse.core.probed import describe

#: the largest fraction of a field's points outside the mesh that is dropped (with a warning) rather than refused:
#: one row of points along one edge of a field of n points is about 1/sqrt(n) of them (6 % of 300 points, 3 % of
#: 1000); more than 10 % outside is a placement error, not edge subsets
MAX_OUTSIDE_FRACTION = 0.10
#: how many times the mesh's size the points' extent may be before the units are blamed
SIZE_FACTOR = 1.5


def box_text(points: np.ndarray) -> str:
    """The bounding box of ``points`` (n, 2) [mm] in words."""
    low, high = points.min(axis=0), points.max(axis=0)
    return f"x {low[0]:.4g} to {high[0]:.4g}, y {low[1]:.4g} to {high[1]:.4g} mm"


def _mirrored_inside(specimen, points: np.ndarray, origin) -> str | None:
    """The axis (``"x"`` or ``"y"``) about which the points mirrored through ``origin`` [mm] mostly fall inside
    the mesh, or None."""
    for axis in (1, 0):
        mirrored = points.copy()
        mirrored[:, axis] = 2.0 * origin[axis] - mirrored[:, axis]
        if np.mean(~points_outside(specimen, mirrored)) > 0.5:
            return "xy"[axis]
    return None


def likely_cause(specimen, points: np.ndarray, nodes: np.ndarray, placement) -> str:
    """Why every point of a field may be outside the mesh (``nodes`` (n, 2) [mm]): the units when the points
    span more than :data:`SIZE_FACTOR` times the mesh, else a mirrored axis when the mirror image falls inside,
    else the origin (the offset of the boxes' centres)."""
    ratio = float(np.ptp(points, axis=0).max() / max(np.ptp(nodes, axis=0).max(), 1e-300))
    if ratio > SIZE_FACTOR:
        scale = "no scale" if placement is None else f"scale = {placement.scale:.6g} mm per camera unit"
        return (f"the points span {ratio:.3g} times the specimen's size: check the units (coordinate_unit, and "
                f"{scale}: e.g. px read as mm, or a scale in px per mm)")
    origin = (0.0, 0.0) if placement is None else placement.origin_specimen
    axis = _mirrored_inside(specimen, points, origin)
    if axis is not None:
        return (f"the points mirrored about the line {axis} = {origin['xy'.index(axis)]:.4g} mm "
                f"fall inside: a mirrored axis (a camera whose {axis.upper()} axis points the other way); negate the "
                f"camera's {axis.upper()} column")
    shift = 0.5 * (points.min(axis=0) + points.max(axis=0) - nodes.min(axis=0) - nodes.max(axis=0))
    return (f"the points' box is offset by ({shift[0]:.4g}, {shift[1]:.4g}) mm from the specimen's: check the "
            "origin (origin_camera and origin_specimen: the same point in the camera and on the specimen, e.g. "
            "the notch mouth at (0, 0) mm), or the marked points")


def points_on_mesh(specimen, points, placement=None) -> tuple[np.ndarray, str | None]:
    """The mask of the field's points (n, 2) [mm] inside the specimen's mesh and the warning of those dropped
    (None when all are inside); DataError when more than :data:`MAX_OUTSIDE_FRACTION` are outside.

    ``placement``: the field's :class:`~fracid.data.dic.CameraPlacement` (or None), named in the hints."""
    points = np.asarray(points, dtype=float)
    d = describe(specimen)
    if getattr(d, "dim", 2) != 2 or len(points) == 0:
        return np.ones(len(points), dtype=bool), None  # the observation refuses a solid specimen itself
    outside = points_outside(d, points)
    n_out, n = int(outside.sum()), len(points)
    if n_out == 0:
        return ~outside, None
    nodes = np.asarray(d.nodes, dtype=float)[:, :2]
    where = (f"{n_out} of {n} points of the field fall outside the specimen's mesh; the points span "
             f"{box_text(points)}, the mesh {box_text(nodes)}")
    if n_out == n:
        raise DataError(f"{where}: every point is outside; {likely_cause(d, points, nodes, placement)}")
    listed = ", ".join(f"({x:.4g}, {y:.4g})" for x, y in points[outside][:5]) + (" ..." if n_out > 5 else "")
    if n_out > MAX_OUTSIDE_FRACTION * n:
        raise DataError(f"{where}; more than {MAX_OUTSIDE_FRACTION:.0%} outside is a placement error, not edge "
                        f"subsets: check the units, the origin and the axes' directions (outside: {listed} mm)")
    beyond = float(np.max(np.maximum(nodes.min(axis=0) - points[outside], points[outside] - nodes.max(axis=0))))
    return ~outside, (f"{where}: those {n_out} ({n_out / n:.1%} of the points; more than {MAX_OUTSIDE_FRACTION:.0%} "
                      f"is refused as a placement error) are dropped: {listed} mm, up to {max(beyond, 0.0):.3g} mm "
                      "beyond the mesh's box; if the placement is off by that much, correct it (origin, scale) "
                      "rather than lose them")


__all__ = ["MAX_OUTSIDE_FRACTION", "box_text", "likely_cause", "points_on_mesh"]
