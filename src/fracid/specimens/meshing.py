"""Structured meshes of 8-node quadrilaterals (or 6-node triangles), graded towards the process zone and mapped to
curved shapes."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np


@dataclass(frozen=True, eq=False)
class QuadMesh:
    """Mesh of 8-node quadrilaterals (or 6-node triangles): vertices first (0..n_vertices-1), then
    mid-edge nodes.

    Attributes
    ----------
    nodes : ndarray, shape (n_nodes, 2)
        Coordinates [mm].
    cells : ndarray of int, shape (n_el, 8) or (n_el, 6)
        Corners counterclockwise, then mid-edge nodes of edges 0-1, 1-2, 2-3, 3-0 (triangles: 0-1,
        1-2, 2-0).
    n_vertices : int
    """

    nodes: np.ndarray
    cells: np.ndarray
    n_vertices: int

    def nodes_near(self, x=None, y=None, tol: float = 1e-9) -> np.ndarray:
        """Indices of the nodes with the given x and/or y coordinate (within ``tol`` mm)."""
        mask = np.ones(len(self.nodes), dtype=bool)
        if x is not None:
            mask &= np.abs(self.nodes[:, 0] - x) <= tol
        if y is not None:
            mask &= np.abs(self.nodes[:, 1] - y) <= tol
        return np.flatnonzero(mask)

    def closest_node(self, point) -> int:
        """The node nearest to ``point`` [mm]."""
        return int(np.argmin(np.sum((self.nodes - np.asarray(point, dtype=float)) ** 2, axis=1)))


def graded_lines(keypoints, size: Callable[[np.ndarray], np.ndarray], samples: int = 2000) -> np.ndarray:
    """Grid-line positions through all ``keypoints`` with a local spacing close to ``size(x)``.

    Each interval between consecutive keypoints gets n = ceil(int dx / size) elements, placed so
    that each spans the same share of int dx / size (equidistribution of the size function).

    Parameters
    ----------
    keypoints : array_like
        Increasing positions that must be grid lines (ends, notch tip, supports) [mm].
    size : callable
        Desired element size at positions x [mm], positive.
    """
    keys = _check_keys(keypoints)
    lines = [keys[:1]]
    for a, b in zip(keys[:-1], keys[1:]):
        x, cumulative, n = _equidistribution(a, b, size, samples)
        lines.append(np.interp(np.linspace(0, cumulative[-1], n + 1)[1:], cumulative, x))
        lines[-1][-1] = b
    return np.concatenate(lines)


def graded_count(keypoints, size: Callable[[np.ndarray], np.ndarray], samples: int = 2000) -> int:
    """Number of intervals :func:`graded_lines` makes with the same arguments, without making them
    (cheap even when the size function would give millions of lines)."""
    keys = _check_keys(keypoints)
    return sum(_equidistribution(a, b, size, samples)[2] for a, b in zip(keys[:-1], keys[1:]))


def _check_keys(keypoints) -> np.ndarray:
    keys = np.asarray(keypoints, dtype=float)
    if np.any(np.diff(keys) <= 0):
        raise ValueError(f"keypoints must increase strictly: {keys.tolist()}")
    return keys


def _equidistribution(a: float, b: float, size, samples: int):
    """Sample positions of [a, b], the cumulative integral of 1/size there, and the element count."""
    x = np.linspace(a, b, samples)
    density = 1.0 / np.asarray(size(x), dtype=float)
    cumulative = np.concatenate([[0.0], np.cumsum(0.5 * (density[1:] + density[:-1]) * np.diff(x))])
    return x, cumulative, max(1, int(np.ceil(cumulative[-1] - 1e-9)))


def quad8_grid_size(n_s: int, n_t: int, hole: tuple[int, int] = (0, 0)) -> tuple[int, int, int]:
    """(elements, nodes, vertices) of :func:`structured_quad8` on ``n_s`` x ``n_t`` grid cells, without
    the ``hole[0]`` x ``hole[1]`` cells at the corner s, t = first lines (e.g. a notch)."""
    a, b = hole
    vertices = (n_s + 1) * (n_t + 1) - a * b
    edges = n_s * (n_t + 1) + n_t * (n_s + 1) - 2 * a * b
    return n_s * n_t - a * b, vertices + edges, vertices


def structured_quad8(
    s_lines,
    t_lines,
    mapping: Callable | None = None,
    keep: Callable | None = None,
) -> QuadMesh:
    """Quad8 mesh of a tensor grid in reference coordinates (s, t), optionally mapped and with holes.

    Parameters
    ----------
    s_lines, t_lines : array_like
        Increasing grid lines of the reference domain.
    mapping : callable(s, t) -> (x, y), optional
        Vectorised map to physical coordinates [mm]; mid-edge nodes are mapped too, so curved
        boundaries are followed to second order. Identity when None.
    keep : callable(s_centre, t_centre) -> bool array, optional
        Which grid cells exist (e.g. to cut a notch). All when None.
    """
    ref, cells, n_vertices = _reference_quad8(s_lines, t_lines, keep)
    return QuadMesh(nodes=_mapped(ref, mapping), cells=cells, n_vertices=n_vertices)


def structured_tri6(
    s_lines,
    t_lines,
    mapping: Callable | None = None,
    keep: Callable | None = None,
) -> QuadMesh:
    """6-node triangle mesh of a tensor grid: each grid cell of :func:`structured_quad8` (same
    arguments) split along its diagonal from (s_i, t_j) to (s_i+1, t_j+1) into two triangles.

    The nodes are those of the quadrilateral mesh, then the mid-points of the diagonals (mapped from
    the reference coordinates like the other nodes).
    """
    ref, quads, n_vertices = _reference_quad8(s_lines, t_lines, keep)
    diagonal = len(ref) + np.arange(len(quads))
    ref = np.concatenate([ref, 0.5 * (ref[quads[:, 0]] + ref[quads[:, 2]])])
    c0, c1, c2, c3, m01, m12, m23, m30 = quads.T
    lower = np.stack([c0, c1, c2, m01, m12, diagonal], axis=1)
    upper = np.stack([c0, c2, c3, diagonal, m23, m30], axis=1)
    cells = np.stack([lower, upper], axis=1).reshape(-1, 6)  # the two triangles of a grid cell side by side
    return QuadMesh(nodes=_mapped(ref, mapping), cells=cells, n_vertices=n_vertices)


def _mapped(ref: np.ndarray, mapping: Callable | None) -> np.ndarray:
    return ref if mapping is None else np.column_stack(mapping(ref[:, 0], ref[:, 1]))


def _reference_quad8(s_lines, t_lines, keep):
    """Reference coordinates of the nodes, the cells and the number of vertices of :func:`structured_quad8`."""
    s = np.asarray(s_lines, dtype=float)
    t = np.asarray(t_lines, dtype=float)
    ns, nt = s.size, t.size
    I, J = np.meshgrid(np.arange(ns - 1), np.arange(nt - 1), indexing="ij")
    I, J = I.ravel(), J.ravel()
    if keep is not None:
        mask = np.asarray(keep(0.5 * (s[I] + s[I + 1]), 0.5 * (t[J] + t[J + 1])), dtype=bool)
        I, J = I[mask], J[mask]
    if I.size == 0:
        raise ValueError("the mesh has no cells")
    corners = np.stack([I * nt + J, (I + 1) * nt + J, (I + 1) * nt + J + 1, I * nt + J + 1], axis=1)
    # edges: horizontal (i, j)-(i+1, j) numbered i*nt + j; vertical (i, j)-(i, j+1) after them
    n_h = (ns - 1) * nt
    edges = np.stack([I * nt + J, n_h + (I + 1) * (nt - 1) + J, I * nt + J + 1, n_h + I * (nt - 1) + J], axis=1)
    used_v, vertex_ids = np.unique(corners, return_inverse=True)
    used_e, edge_ids = np.unique(edges, return_inverse=True)
    vi, vj = used_v // nt, used_v % nt
    sv, tv = s[vi], t[vj]
    horizontal = used_e < n_h
    ei = np.where(horizontal, used_e // nt, (used_e - n_h) // (nt - 1))
    ej = np.where(horizontal, used_e % nt, (used_e - n_h) % (nt - 1))
    se = np.where(horizontal, 0.5 * (s[np.minimum(ei, ns - 2)] + s[np.minimum(ei + 1, ns - 1)]), s[ei])
    te = np.where(horizontal, t[ej], 0.5 * (t[np.minimum(ej, nt - 2)] + t[np.minimum(ej + 1, nt - 1)]))
    ref = np.concatenate([np.column_stack([sv, tv]), np.column_stack([se, te])])
    cells = np.concatenate([vertex_ids.reshape(-1, 4), used_v.size + edge_ids.reshape(-1, 4)], axis=1)
    return ref, cells, int(used_v.size)
