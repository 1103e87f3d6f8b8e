"""The user's own plane-stress specimen: a Gmsh mesh whose physical groups name the supports, the loaded
edge or point, symmetry lines and the measuring points (read with meshio, the ``vtk`` extra).

The mesh may be linear or quadratic, of triangles or quadrilaterals (one family per mesh): only the
element corners are read, and fracid adds the mid-edge nodes of its quadratic elements (T6 with linear
ebar on the corners, or Q8 with bilinear ebar) on straight edges. A group of lines or points becomes
the node set of its corners and of the mid-edge nodes of its lines. Lengths are in the mesh's unit
times ``scale`` [mm].
"""

from __future__ import annotations

import contextlib
import functools
import hashlib
import io
import os
from dataclasses import dataclass

import numpy as np

from fracid.specimens.description import CrackPath, Description, Load, Measure, Support, ZoneWidth

_COMPONENTS = {"x": 0, "y": 1}
_SURFACES = {"triangle": 3, "triangle6": 3, "triangle7": 3, "quad": 4, "quad8": 4, "quad9": 4}
_SOLIDS = ("tetra", "hexahedron", "wedge", "pyramid")


class MeshError(ValueError):
    """A mesh file that fracid cannot use; the message names the file and what to change."""


@dataclass(frozen=True)
class MeshSpecimen:
    """A plane-stress test described by a Gmsh mesh and the names of its physical groups.

    Parameters
    ----------
    path : str
        The ``.msh`` file (any format meshio reads with physical groups).
    thickness : float
        Out-of-plane thickness [mm].
    supports : tuple of (group, component)
        The ``component`` ("x" or "y") of the nodes of each group held at zero.
    loads : tuple of (group, component[, rigid[, force]])
        The load pattern: ``force`` (default 1) per unit load factor along ``component`` on the group,
        its nodes tied together (``rigid``, the default: a loading plate, or one point) or the force
        spread evenly. A half model that carries half the force has force 0.5 (-0.5 downwards), so that
        the load factor is the whole specimen's force [N].
    controls : tuple of (name, ((group, component, weight), ...))
        Named functionals: ``weight`` times the mean displacement of the group along the component,
        summed (a CMOD: the right lip's x minus the left lip's x). The first is the default control.
    symmetry : tuple of (group, component)
        Symmetry lines: the normal ``component`` of the group's nodes held at zero.
    symmetry_factor : float
        Copies of the model in the whole specimen (2 for a half model).
    scale : float
        Millimetres per unit of the mesh's coordinates (1000 for a mesh in metres).
    regions : tuple of (group, stiffness_factor, damageable)
        Physical surfaces of other materials: Young's modulus relative to the material's, and whether
        they may damage (false for steel platens or loading blocks). Elsewhere 1 and true.
    checksum : str
        SHA-256 of the mesh file, computed when the specimen is made (do not give it): it is part of
        the specimen's identity, so the run store does not reuse runs of an edited mesh.
    crack : tuple (group, component[, element_size]) or ()
        The straight line the crack runs along (its normal ``component``: "x" for a line x = const;
        ``element_size`` [mm] sets a discrete crack's penalty, default the shortest side on the line):
        the discrete cohesive crack opens there when the line is also a symmetry line of the model,
        the crack band lies on it, and the damage models record the width of their damaged zone
        across it (observable ``fpz_width``, doubled on a symmetry line).
    """

    path: str
    thickness: float
    supports: tuple
    loads: tuple
    controls: tuple
    symmetry: tuple = ()
    symmetry_factor: float = 1.0
    scale: float = 1.0
    crack: tuple = ()
    regions: tuple = ()
    checksum: str = ""

    def __post_init__(self):
        if not self.checksum and os.path.isfile(self.path):
            with open(self.path, "rb") as handle:
                object.__setattr__(self, "checksum", hashlib.sha256(handle.read()).hexdigest())
        if not (isinstance(self.thickness, (int, float)) and self.thickness > 0):
            raise ValueError(f"MeshSpecimen.thickness = {self.thickness!r} mm; it must be positive")
        if not self.controls:
            raise ValueError("MeshSpecimen.controls is empty: name at least one control (a displacement to prescribe)")
        if not self.loads:
            raise ValueError("MeshSpecimen.loads is empty: name the group the force acts on")
        for name, _ in self.controls:
            if not isinstance(name, str) or not name:
                raise ValueError(f"MeshSpecimen.controls: a control's name must be a non-empty string; got {name!r}")

    @property
    def observables(self) -> tuple:
        """The local observables its damage models record: the damaged-zone width across the crack line."""
        return ("fpz_width",) if self.crack else ()

    @property
    def default_control(self) -> str:
        return self.controls[0][0]

    @property
    def control_names(self) -> tuple:
        return tuple(name for name, _ in self.controls)

    def describe(self) -> Description:
        return self.describe_mesh(read_mesh(self.path))

    def describe_mesh(self, mesh: PlaneMesh) -> Description:
        """The description of this test on ``mesh`` (its node sets named as the groups here)."""
        groups = set(self._groups())
        missing = sorted(groups - set(mesh.node_sets))
        if missing:
            raise MeshError(f"{self.path}: no physical group {', '.join(map(repr, missing))}; the file names "
                            f"{sorted(mesh.node_sets) or 'no physical groups'}")
        self._check_rigid_loads(mesh)
        self._check_pieces(mesh)
        return Description(
            nodes=mesh.nodes * self.scale, cells=mesh.cells, n_vertices=mesh.n_vertices, section=float(self.thickness),
            node_sets=mesh.node_sets,
            supports=tuple(Support(group, _component(component, "supports")) for group, component in self.supports),
            loads=tuple(_load(item) for item in self.loads),
            symmetry=tuple((group, _component(component, "symmetry")) for group, component in self.symmetry),
            functionals={name: tuple(Measure(group, _component(component, f"controls[{name!r}]"), float(weight))
                                     for group, component, weight in terms) for name, terms in self.controls},
            symmetry_factor=float(self.symmetry_factor),
            **self._crack(mesh), **self._regions(mesh),
        )

    def _check_rigid_loads(self, mesh) -> None:
        """Raise MeshError when a rigid load group shares nodes with a support or symmetry group on the same
        component: the tied group would be held as a whole and the load could not act."""
        held = [("support", group, _component(component, "supports")) for group, component in self.supports]
        held += [("symmetry", group, _component(component, "symmetry")) for group, component in self.symmetry]
        for group, component, *rest in self.loads:
            if rest and not rest[0]:
                continue
            normal = _component(component, "loads")
            for kind, other, other_normal in held:
                if other_normal != normal:
                    continue
                shared = np.intersect1d(mesh.node_sets[group], mesh.node_sets[other]).size
                if shared:
                    raise MeshError(
                        f"{self.path}: the {kind} group {other!r} and the rigid load group {group!r} share {shared} "
                        f"node{'s' if shared > 1 else ''} along {'xy'[normal]}: the nodes of a rigid group move as "
                        f"one, so the {kind} holds the whole group and the load cannot act. Make the groups disjoint "
                        "(in Gmsh, physical groups of different lines or points) or give the load rigid = false")

    def _check_pieces(self, mesh) -> None:
        """Raise MeshError when the mesh is made of pieces that share no node and one of them holds no
        support node: that piece is free to move as a rigid body."""
        n_pieces = int(mesh.pieces.max()) + 1
        if n_pieces == 1:
            return
        supports = [group for group, _ in self.supports]
        held = np.unique(np.concatenate([mesh.pieces[mesh.node_sets[g]] for g in supports] or [np.zeros(0, int)]))
        free = np.setdiff1d(np.arange(n_pieces), held)
        if not free.size:
            return
        cell_piece = mesh.pieces[mesh.cells[:, 0]]
        described = "; ".join(_piece_text(mesh, cell_piece == k, k) for k in free[:5])
        names = ", ".join(map(repr, supports)) or "none"
        raise MeshError(
            f"{self.path}: the mesh is made of {n_pieces} pieces that share no node, and {free.size} of them "
            f"hold{'s' if free.size == 1 else ''} no support node (supports: {names}) "
            f"and would move as a rigid body: {described}. Fuse the surfaces so that they share their nodes (Gmsh: "
            "Boolean fragments of the surfaces, or Geometry > Coherence, then mesh again), or add a support in "
            "each piece")

    def _regions(self, mesh) -> dict:
        """Per-element stiffness factor and damageability of the regions."""
        if not self.regions:
            return {}
        stiffness, damageable = np.ones(len(mesh.cells)), np.ones(len(mesh.cells))
        for group, factor, damages in self.regions:
            cells = mesh.cell_sets.get(group)
            if cells is None:
                raise MeshError(f"{self.path}: region {group!r} is no physical surface (regions are groups of "
                                f"triangles or quadrilaterals; the file's are {sorted(mesh.cell_sets)})")
            if not (np.isfinite(factor) and factor > 0):
                raise ValueError(f"MeshSpecimen.regions: the stiffness factor of {group!r} is {factor!r}; it must be "
                                 "positive")
            stiffness[cells], damageable[cells] = float(factor), float(bool(damages))
        return {"stiffness_factor": stiffness, "damageable": damageable}

    def _crack(self, mesh) -> dict:
        """The crack path, the zone-width line and the symmetry plane along it (if it is one)."""
        if not self.crack:
            return {}
        group, component, *size = self.crack
        normal = _component(component, "crack")
        line = mesh.nodes[mesh.node_sets[group]] * self.scale
        coordinate = float(np.mean(line[:, normal]))
        if np.ptp(line[:, normal]) > 1e-9 * max(np.ptp(mesh.nodes) * self.scale, 1.0):
            raise MeshError(f"{self.path}: the crack group {group!r} is not a straight line "
                            f"{'xy'[normal]} = const")
        mirrored = any(g == group and _component(c, "symmetry") == normal for g, c in self.symmetry)
        along = line[:, 1 - normal]
        element_size = float(size[0]) if size else None
        return {"crack": CrackPath(group, normal=normal, mirrored=mirrored, element_size=element_size),
                "zone": ZoneWidth("fpz_width", axis=normal, mirror=mirrored, along_range=(along.min(), along.max())),
                "symmetry_planes": ((normal, coordinate),) if mirrored else ()}

    def _groups(self):
        for group, *_ in (*self.supports, *self.loads, *self.symmetry, *self.regions,
                          *([self.crack] if self.crack else [])):
            yield group
        for _, terms in self.controls:
            for group, *_ in terms:
                yield group

    def default_steps(self, target: float):
        """Adaptive steps capped at 1/60 of the target (as the notched beam), so the softening branch
        takes tens of steps."""
        from fracid.fem.path_following import StepOptions

        return StepOptions(maximum=target / 60)

    def default_target(self, scales) -> float:
        raise ValueError(f"a mesh specimen has no default target: give target= (the final {self.default_control} "
                         "[mm])")


def _component(value, where) -> int:
    if value in (0, 1):
        return int(value)
    try:
        return _COMPONENTS[value]
    except (KeyError, TypeError):
        raise ValueError(f"MeshSpecimen.{where}: component {value!r}; use 'x' or 'y'") from None


def _load(item) -> Load:
    group, component, *rest = item
    rigid = bool(rest[0]) if rest else True
    total = float(rest[1]) if len(rest) > 1 else 1.0
    if not (np.isfinite(total) and total != 0.0):
        raise ValueError(f"MeshSpecimen.loads: the force of group {group!r} is {total!r} per unit load factor; "
                         "it must be finite and non-zero")
    return Load(group, _component(component, "loads"), total, rigid=rigid)


def _piece_text(mesh, cells, k) -> str:
    """One piece of a mesh in words: its number, elements and bounding box (mesh units)."""
    corners = mesh.nodes[np.unique(mesh.cells[cells])]
    low, high = corners.min(axis=0), corners.max(axis=0)
    return (f"piece {k + 1} ({int(cells.sum())} elements, x in [{low[0]:.6g}, {high[0]:.6g}], "
            f"y in [{low[1]:.6g}, {high[1]:.6g}])")


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
    try:
        stat = os.stat(path)
    except OSError as err:
        raise MeshError(f"{path}: cannot read the mesh file ({err.strerror})") from None
    return _read(os.fspath(path), stat.st_mtime_ns, stat.st_size)


@functools.lru_cache(maxsize=8)
def _read(path, mtime, size) -> PlaneMesh:
    try:
        import meshio
    except ImportError as err:
        raise ImportError(f"reading {path} needs meshio: pip install 'fracid[vtk]' ({err})") from err
    raw = _meshio_read(meshio, path)
    return plane_mesh(raw.points, [(block.type, block.data) for block in raw.cells], _physical_groups(raw), path)


def _meshio_read(meshio, path):
    """meshio's mesh of ``path``, or MeshError naming the file and the formats to export: meshio may
    raise any exception, or print an error and call ``sys.exit``, on a file it cannot read."""
    said = io.StringIO()
    try:
        with contextlib.redirect_stderr(said), contextlib.redirect_stdout(said):
            return meshio.read(path)
    except MemoryError:
        raise
    except (SystemExit, Exception) as err:  # noqa: BLE001 -- every failure of the reader is a bad file
        reason = " ".join(said.getvalue().split()).removeprefix("Error: ") or f"{type(err).__name__}: {err}"
        raise MeshError(f"{path}: not a mesh file fracid can read ({_GMSH_1 if _is_gmsh_1(path) else reason}). "
                        f"{_EXPORT}") from None


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


_DIMENSION = {"vertex": 0, "line": 1, "line3": 1, **{kind: 2 for kind in _SURFACES}}


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
    corners = np.concatenate([data[:, :n_corners] for _, data in surfaces])
    vertex_ids = np.unique(corners)
    _check_size(path, vertex_ids.size, len(corners))
    used = np.unique(np.concatenate([data.ravel() for _, data in surfaces]))
    unused = np.setdiff1d(np.arange(len(points)), used)
    if unused.size:
        node = unused[0]
        count = f"{unused.size} nodes belong" if unused.size > 1 else "1 node belongs"
        raise MeshError(f"{path}: {count} to no triangle or quadrilateral (node {node} at "
                        f"{points[node, :2].tolist()}); save only the meshed surfaces (Gmsh: Mesh.SaveAll = 0 with "
                        "physical surfaces)")
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


def _check_size(path, n_vertices: int, n_cells: int) -> None:
    """Raise MeshError, before the mesh is built, when its unknowns exceed
    :data:`fracid.config.schema.MAX_UNKNOWNS` (the limit of the built-in specimens' meshes)."""
    from fracid.config.checker import _bytes
    from fracid.config.schema import BYTES_PER_UNKNOWN, MAX_UNKNOWNS

    unknowns = mesh_unknowns(n_vertices, n_cells)
    if unknowns > MAX_UNKNOWNS:
        raise MeshError(
            f"{path}: {n_cells:,} elements and {n_vertices:,} corner nodes make about {unknowns:,} unknowns once "
            f"fracid adds the mid-edge nodes, needing about {_bytes(unknowns * BYTES_PER_UNKNOWN)} of memory in a "
            f"forward run ({BYTES_PER_UNKNOWN:,} bytes per unknown, measured); at most {MAX_UNKNOWNS:,} unknowns "
            "are allowed: use a coarser mesh (small elements only where the crack runs; a few elements per "
            "internal length l = sqrt(2 c) are enough)")


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


def write_gmsh(description: Description, path, triangles: bool = False) -> None:
    """Write a plane description's mesh as a linear Gmsh 2.2 file whose physical groups are its node sets,
    to start one's own specimen from a built-in one (and to check the mesh reader against it).

    The cells are the corners of the quadrilaterals, or each split in two triangles along its diagonal
    0-2 (``triangles``). A node set becomes a group of the element sides whose three nodes it holds
    (dimension 1), its other corners a group of points named ``<set>_points`` (or ``<set>`` when it
    has no side: a point set).
    """
    import meshio

    d = description
    corners = d.corners
    if corners.shape[1] != 4 or d.cells.shape[1] != 8:
        raise ValueError("write_gmsh writes the meshes of 8-node quadrilaterals")
    sides = np.stack([corners, np.roll(corners, -1, axis=1), d.cells[:, 4:]], axis=-1).reshape(-1, 3)
    cells = np.vstack([corners[:, [0, 1, 2]], corners[:, [0, 2, 3]]]) if triangles else corners
    blocks, physical, names = [("triangle" if triangles else "quad", cells)], [np.full(len(cells), 1)], {}
    for name in sorted(d.node_sets):
        members = np.zeros(len(d.nodes), dtype=bool)
        members[d.nodes_of(name)] = True
        lines = sides[members[sides].all(axis=1)][:, :2]
        alone = np.setdiff1d(np.flatnonzero(members[:d.n_vertices]), lines)
        for kind, data, dim, label in (("line", lines, 1, name), ("vertex", alone[:, None], 0,
                                                                   name if not len(lines) else f"{name}_points")):
            if len(data):
                tag = len(names) + 2
                blocks.append((kind, data))
                physical.append(np.full(len(data), tag))
                names[label] = [tag, dim]
    points = np.column_stack([d.nodes[:d.n_vertices], np.zeros(d.n_vertices)])
    mesh = meshio.Mesh(points, blocks, cell_data={"gmsh:physical": physical, "gmsh:geometrical": physical},
                       field_data={"domain": np.array([1, 2]), **{k: np.array(v) for k, v in names.items()}})
    meshio.write(path, mesh, file_format="gmsh22", binary=False)
