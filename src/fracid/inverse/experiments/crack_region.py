"""The region of a DIC field away from the specimen's crack path: the distance of points to the straight crack
line of a specimen's description, and the region function that keeps the points at least a distance from it
(``[[experiments]] kind = "field"``, ``exclude_near``; the synthetic twins of :mod:`fracid.inverse.studies.dic_twin`).

Imports :mod:`fracid.specimens` only.
"""

from __future__ import annotations

import numpy as np

from fracid.specimens.description import Description


def crack_distance(description: Description, points, span=None) -> np.ndarray:
    """Distance [mm] of each point to the segment of the specimen's crack line over ``span``.

    Parameters
    ----------
    description : Description
        The specimen's; its ``crack`` names the node set on the straight crack line.
    points : array_like, shape (n, 2)
        Specimen coordinates [mm].
    span : (float, float), optional
        Range of the crack line's along coordinate [mm]; by default from the mesh's edge (the notch's
        mouth) to the middle of the crack path's node set (the notch and the lower half of the ligament).
    """
    crack = description.crack
    if crack is None or crack.nodes is None:
        raise ValueError("holes near the crack need a specimen with a crack path (Description.crack); "
                         "this one has none: give holes=None")
    line = description.nodes[description.nodes_of(crack.nodes)]
    normal, along = crack.normal, 1 - crack.normal
    if span is None:
        span = (description.nodes[:, along].min(), 0.5 * (line[:, along].min() + line[:, along].max()))
    lo, hi = sorted(float(s) for s in span)
    points = np.asarray(points, float)
    return np.hypot(points[:, normal] - line[:, normal].mean(), points[:, along] - np.clip(points[:, along], lo, hi))


def away_from_crack(specimen, distance):
    """None, or the region function keeping the points at least ``distance`` [mm] from the crack path (the
    straight crack line of the specimen's description, from the mesh's edge to its end)."""
    if distance is None:
        return None
    d = specimen.describe()
    if d.crack is None or d.crack.nodes is None:
        raise ValueError(f"the specimen {type(specimen).__name__} has no straight crack path (Description.crack)")
    along = 1 - d.crack.normal
    line = d.nodes[d.nodes_of(d.crack.nodes)]
    span = (float(d.nodes[:, along].min()), float(line[:, along].max()))
    return lambda points: crack_distance(d, points, span) >= distance


__all__ = ["away_from_crack", "crack_distance"]
