"""The user's own plane-stress specimen: a Gmsh mesh whose physical groups name the supports, the loaded
edge or point, symmetry lines and the measuring points (read with meshio).

The mesh may be linear or quadratic, of triangles or quadrilaterals (one family per mesh): only the
element corners are read, and fracid adds the mid-edge nodes of its quadratic elements (T6 with linear
ebar on the corners, or Q8 with bilinear ebar) on straight edges. A group of lines or points becomes
the node set of its corners and of the mid-edge nodes of its lines. Lengths are in the mesh's unit
times ``scale`` [mm].

The file is read by :mod:`fracid.specimens.mesh_reading` (import its names from there);
this module checks the groups against the mesh and writes a description's mesh as a Gmsh file
(:func:`write_gmsh`).
"""

from __future__ import annotations

import dataclasses
import hashlib
import os
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from fracid.specimens.description import CrackPath, Description, Load, Measure, Support, ZoneWidth
from fracid.specimens.mesh_section import SECTION
from fracid.specimens.mesh_reading import MeshError, PlaneMesh, mesh_size, mesh_unknowns, read_mesh
from fracid.specimens.protocol import (BYTES_PER_UNKNOWN, MAX_UNKNOWNS, Resolution, SizeEstimate, SpecimenDefaults,
                                       SpecimenSection)

__all__ = ["MeshSpecimen", "write_gmsh"]

_COMPONENTS = {"x": 0, "y": 1}


@dataclass(frozen=True)
class MeshSpecimen(SpecimenDefaults):
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

    #: ``[specimen] type = "mesh"`` is read by its own section (file, group lists), not by its fields
    config_section: ClassVar[SpecimenSection] = SECTION

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
    def control_names(self) -> tuple:
        """The names of its controls (``controls`` holds their definitions); the first is the default."""
        return tuple(name for name, _ in self.controls)

    @property
    def default_control(self) -> str:
        return self.controls[0][0]

    @classmethod
    def default_instance(cls):
        """None: a mesh specimen needs its file and group names."""
        return None

    def options_text(self, options: dict) -> str:
        """The mesh file (its groups are in the configuration)."""
        return f"file {self.path}"

    def resolution(self, internal_length: float | None = None) -> Resolution:
        """The smallest element side of the mesh [mm], set by the file."""
        return dataclasses.replace(super().resolution(internal_length), field="file", value=self.path)

    def size_estimate(self) -> SizeEstimate:
        """The unknowns once the mid-edge nodes are added, counted from the file without building the mesh."""
        n_vertices, n_cells = mesh_size(self.path)
        unknowns = mesh_unknowns(n_vertices, n_cells)
        return SizeEstimate("file", self.path, f"{n_cells:,} elements and {n_vertices:,} corner nodes, about "
                            f"{unknowns:,} unknowns once fracid adds the mid-edge nodes", unknowns, "unknown",
                            BYTES_PER_UNKNOWN, MAX_UNKNOWNS, "use a coarser mesh (small elements only where the crack "
                            "runs; a few elements per internal length l = sqrt(2 c) are enough)")

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
