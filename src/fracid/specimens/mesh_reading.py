"""Reading a Gmsh mesh into fracid's quadratic plane mesh (:class:`PlaneMesh`), with the checks of the file
itself: a file meshio cannot read, 3D or mixed elements, nodes off the plane or in no element, coincident
nodes, degenerate elements, groups whose nodes or lines are no element's.

Only the element corners are read; fracid adds the mid-edge nodes of its quadratic elements on straight
edges, and a group of lines or points becomes the node set of its corners and of the mid-edge nodes of its
lines. The size of a mesh (:func:`mesh_size`, :func:`mesh_unknowns`) is known before it is built.
"""

from __future__ import annotations

import functools
import os
from dataclasses import dataclass

import numpy as np

from fracid.fem.mesh.meshio_files import UnreadableFile, meshio_read

_SURFACES = {"triangle": 3, "triangle6": 3, "triangle7": 3, "quad": 4, "quad8": 4, "quad9": 4}
_SOLIDS = ("tetra", "hexahedron", "wedge", "pyramid")
_DIMENSION = {"vertex": 0, "line": 1, "line3": 1, **{kind: 2 for kind in _SURFACES}}


class MeshError(ValueError):
    """A mesh file that fracid cannot use; the message names the file and what to change."""


@dataclass(frozen=True, eq=False)
class PlaneMesh:
    """A plane mesh in fracid's numbering: corners first (``n_vertices``), then mid-edge nodes."""

    nodes: np.ndarray
    cells: np.ndarray
    n_vertices: int
    node_sets: dict
    cell_sets: dict  # group of surfaces -> indices of its cells
    pieces: np.ndarray  # per node: the connected piece of the mesh it belongs to (0, 1, ...)


def read_mesh(path) -> PlaneMesh:
    """The mesh of ``path`` with fracid's quadratic elements and a node set per physical group (cached
    while the file is unchanged)."""
    return _read(*_file_key(path))


def mesh_size(path) -> tuple[int, int]:
    """(corner nodes, elements) of the mesh of ``path``, counted without building it (for
    :func:`mesh_unknowns`); the file is read once for this and :func:`read_mesh`.

    Raises
    ------
    MeshError
        The file cannot be read, or its elements are no plane mesh of one family.
    """
    points, blocks, _ = _meshio_mesh(*_file_key(path))
    corners = _surface_corners(points, blocks, path)[1]
    return int(np.unique(corners).size), len(corners)


def _file_key(path) -> tuple:
    """(path, modification time, size): the key of the caches of the file's contents."""
    try:
        stat = os.stat(path)
    except OSError as err:
        raise MeshError(f"{path}: cannot read the mesh file ({err.strerror})") from None
    return os.fspath(path), stat.st_mtime_ns, stat.st_size


@functools.lru_cache(maxsize=8)
def _read(path, mtime, size) -> PlaneMesh:
    return plane_mesh(*_meshio_mesh(path, mtime, size), path)


@functools.lru_cache(maxsize=1)
def _meshio_mesh(path, mtime, size) -> tuple:
    """meshio's points, cell blocks [(type, connectivity)] and physical groups of the file, or MeshError naming
    the file and the formats to export (:func:`~fracid.fem.mesh.meshio_files.meshio_read`, the guard of meshio)."""
    try:
        raw = meshio_read(path)
    except UnreadableFile as err:
        reason = _GMSH_1 if _is_gmsh_1(path) else err.reason
        raise MeshError(f"{path}: not a mesh file fracid can read ({reason}). {_EXPORT}") from None
    return raw.points, [(block.type, block.data) for block in raw.cells], _physical_groups(raw)


_GMSH_1 = "a Gmsh 1.0 file ($NOD), a format meshio does not read"
_EXPORT = ("Save it from Gmsh in the format 2.2 or 4.1 (File > Export, format Gmsh MSH, \"Version 4 ASCII\" or "
           "\"Version 2 ASCII\"; on the command line: gmsh -2 file.geo -format msh22 -o file.msh)")


def _is_gmsh_1(path) -> bool:
    """Whether the file starts as Gmsh's old format 1.0 ($NOD, no $MeshFormat)."""
    try:
        with open(path, "rb") as handle:
            return handle.read(64).lstrip().startswith(b"$NOD")
    except OSError:
        return False


def _physical_groups(raw) -> dict:
    """{group: {cell type: cell indices}} from Gmsh's physical tags (field_data name -> (tag, dim)),
    or meshio's cell sets when the file has no tags."""
    physical = raw.cell_data.get("gmsh:physical")
    if physical is None or not raw.field_data:
        return raw.cell_sets_dict
    groups = {}
    for name, (tag, dim) in ((n, tuple(int(v) for v in value[:2])) for n, value in raw.field_data.items()):
        members, offset = {}, {}  # indices into the concatenation of the blocks of a type
        for block, tags in zip(raw.cells, physical):
            start = offset.get(block.type, 0)
            offset[block.type] = start + len(block.data)
            if _DIMENSION.get(block.type) == dim:
                chosen = np.flatnonzero(np.asarray(tags) == tag)
                if chosen.size:
                    members.setdefault(block.type, []).append(start + chosen)
        groups[name] = {kind: np.concatenate(parts) for kind, parts in members.items()}
    return groups


def plane_mesh(points, blocks, cell_sets, path="mesh") -> PlaneMesh:
    """fracid's quadratic plane mesh from meshio's ``points``, cell ``blocks`` [(type, connectivity)]
    and ``cell_sets`` {group: {type: cell indices}} (see :func:`read_mesh`)."""
    points = np.asarray(points, dtype=float)
    surfaces, corners = _surface_corners(points, blocks, path)
    _check_unused(path, points, surfaces)
    vertex_ids = np.unique(corners)
    renumber = np.full(len(points), -1)
    renumber[vertex_ids] = np.arange(vertex_ids.size)
    vertices = points[vertex_ids, :2]
    cells = renumber[corners]
    _check_coincident(path, vertices, cells)
    cells = _counterclockwise(vertices, cells, path)
    edges, mid = _mid_edges(cells)
    nodes = np.vstack([vertices, 0.5 * (vertices[edges[:, 0]] + vertices[edges[:, 1]])])
    quadratic = np.hstack([cells, vertex_ids.size + mid])
    node_sets = _node_sets(blocks, cell_sets, renumber, edges, vertex_ids.size, path)
    return PlaneMesh(nodes, quadratic, int(vertex_ids.size), node_sets, _cell_sets(surfaces, cell_sets),
                     _pieces(vertex_ids.size, edges))


def _surface_corners(points, blocks, path) -> tuple:
    """The blocks of triangles or quadrilaterals and the corners of their cells, or MeshError for 3D
    elements, nodes off the plane z = 0, no surface elements or both families."""
    solids = sorted({kind for kind, _ in blocks if kind in _SOLIDS})
    if solids:
        raise MeshError(f"{path}: 3D elements ({', '.join(solids)}): fracid runs plane-stress meshes; mesh the "
                        "surface only (Gmsh: 2D mesh)")
    if points.shape[1] > 2 and np.any(np.abs(points[:, 2:]) > 1e-9 * max(np.ptp(points[:, :2]), 1.0)):
        raise MeshError(f"{path}: nodes off the plane z = 0: a plane-stress mesh lies in the x-y plane")
    surfaces = [(kind, data) for kind, data in blocks if kind in _SURFACES]
    families = {_SURFACES[kind] for kind, _ in surfaces}
    if not families:
        raise MeshError(f"{path}: no triangles or quadrilaterals (cell types {sorted({k for k, _ in blocks})})")
    if len(families) > 1:
        raise MeshError(f"{path}: triangles and quadrilaterals together; mesh with one family (Gmsh: "
                        "Mesh.RecombineAll = 1 for quadrilaterals only, 0 for triangles)")
    n_corners = families.pop()
    return surfaces, np.concatenate([data[:, :n_corners] for _, data in surfaces])


def _check_unused(path, points, surfaces) -> None:
    """Raise MeshError when nodes belong to no surface element (Gmsh saved the geometry's points too)."""
    used = np.unique(np.concatenate([data.ravel() for _, data in surfaces]))
    unused = np.setdiff1d(np.arange(len(points)), used)
    if unused.size:
        node = unused[0]
        count = f"{unused.size} nodes belong" if unused.size > 1 else "1 node belongs"
        raise MeshError(f"{path}: {count} to no triangle or quadrilateral (node {node} at "
                        f"{points[node, :2].tolist()}); save only the meshed surfaces (Gmsh: Mesh.SaveAll = 0 with "
                        "physical surfaces)")


def mesh_unknowns(n_vertices: int, n_cells: int) -> int:
    """The unknowns of fracid's quadratic mesh built on a linear one.

    Parameters
    ----------
    n_vertices, n_cells : int
        Element corners and elements (triangles or quadrilaterals) of the mesh read.

    Returns
    -------
    int
        2 displacements per corner and per mid-edge node, and the nonlocal strain on the corners; the
        edges counted by Euler's formula for one piece without holes, E = V + F - 1 (each hole adds one).
    """
    n_edges = n_vertices + n_cells - 1
    return 2 * (n_vertices + n_edges) + n_vertices


def _check_coincident(path, vertices, cells) -> None:
    """Raise MeshError when corners lie on one another (within 1e-6 of the median element side): Gmsh left
    duplicate nodes unmerged, and the elements on either side are not connected."""
    from scipy.spatial import cKDTree

    sides = np.linalg.norm(vertices[cells[:, 1]] - vertices[cells[:, 0]], axis=1)
    tolerance = 1e-6 * float(np.median(sides))
    pairs = cKDTree(vertices).query_pairs(tolerance, output_type="ndarray")
    if not len(pairs):
        return
    count = np.unique(pairs).size
    raise MeshError(
        f"{path}: {count} nodes lie on another node (closer than {tolerance:.3g} mesh units), e.g. two at "
        f"{vertices[pairs[0, 0]].tolist()}: duplicate nodes that were not merged leave the elements on either side "
        "unconnected. Merge them in Gmsh: Geometry > Coherence (or a larger Geometry.Tolerance) before meshing, or "
        "\"Coherence Mesh;\" to merge the duplicate nodes of the mesh, then save it again")


def _pieces(n_vertices: int, edges) -> np.ndarray:
    """The connected piece (0, 1, ...) of every node: corners, then the mid-edge node of each edge."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    graph = coo_matrix((np.ones(len(edges)), (edges[:, 0], edges[:, 1])), shape=(n_vertices, n_vertices))
    _, labels = connected_components(graph, directed=False)
    return np.concatenate([labels, labels[edges[:, 0]]])


def _cell_sets(surfaces, groups) -> dict:
    """{group: indices of its cells in the order of ``surfaces``} for the groups of surfaces."""
    positions, start = {}, 0
    for kind, data in surfaces:
        positions.setdefault(kind, []).append(np.arange(start, start + len(data)))
        start += len(data)
    positions = {kind: np.concatenate(parts) for kind, parts in positions.items()}
    return {group: np.unique(np.concatenate([positions[kind][np.asarray(idx, dtype=int)]
                                             for kind, idx in members.items() if kind in positions]))
            for group, members in groups.items() if any(kind in positions for kind in members)}


def _counterclockwise(vertices, cells, path):
    """Cells with their corners counterclockwise (Gmsh orders them by the surface's normal)."""
    x, y = vertices[cells, 0], vertices[cells, 1]
    area = 0.5 * np.sum(x * np.roll(y, -1, axis=1) - np.roll(x, -1, axis=1) * y, axis=1)
    size = np.ptp(vertices, axis=0).max()
    degenerate = np.flatnonzero(np.abs(area) <= 1e-12 * size * size)
    if degenerate.size:
        raise MeshError(f"{path}: degenerate elements (zero area): {degenerate[:10].tolist()}")
    out = cells.copy()
    flip = area < 0
    out[flip] = out[flip][:, ::-1]
    return out


def _mid_edges(cells):
    """Unique edges (sorted vertex pairs) and, per cell, the edge of each side (0-1, 1-2, ...)."""
    n = cells.shape[1]
    sides = np.stack([cells, np.roll(cells, -1, axis=1)], axis=-1).reshape(-1, 2)
    edges, index = np.unique(np.sort(sides, axis=1), axis=0, return_inverse=True)
    return edges, index.reshape(-1, n)


def _node_sets(blocks, cell_sets, renumber, edges, n_vertices, path) -> dict:
    """Node set per physical group: the corners of its cells and the mid-edge nodes of its edges."""
    by_type = {}
    for kind, data in blocks:
        by_type.setdefault(kind, []).append(data)
    edge_id = {tuple(edge): k for k, edge in enumerate(edges.tolist())}
    sets = {}
    for group, members in cell_sets.items():
        if group.startswith("gmsh:"):
            continue
        nodes = []
        for kind, indices in members.items():
            data = np.concatenate(by_type.get(kind, [np.zeros((0, 1), dtype=int)]))[np.asarray(indices, dtype=int)]
            n_corners = 1 if kind == "vertex" else 2 if kind.startswith("line") else _SURFACES.get(kind)
            if n_corners is None:
                continue
            ids = renumber[data[:, :n_corners]]
            if np.any(ids < 0):
                raise MeshError(f"{path}: physical group {group!r} has nodes that are no element corner")
            nodes.append(ids.ravel())
            if n_corners >= 2:
                sides = np.stack([ids, np.roll(ids, -1, axis=1)], axis=-1).reshape(-1, 2) if n_corners > 2 else ids
                for a, b in np.sort(sides, axis=1).tolist():
                    k = edge_id.get((a, b))
                    if k is None:
                        raise MeshError(f"{path}: physical group {group!r} has a line that is no element side")
                    nodes.append(np.array([n_vertices + k]))
        if nodes:
            sets[group] = np.unique(np.concatenate(nodes))
    return sets

