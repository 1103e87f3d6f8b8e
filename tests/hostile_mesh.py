"""Hostile-input cases (Gmsh meshes: disconnected, duplicate nodes, overlapping groups, unreadable formats, size
and unit plausibility); run by tests/test_hostile_inputs.py. Also the mesh writers and the strip's config of
tests/test_mesh_specimen.py.

Every case is ``fracid simulate`` of a strip meshed with triangles (groups ``left``, ``right`` and a point
``origin``), changed so that the mesh or its groups are what a user may really hand in; each ends while the
configuration is loaded (exit status 2) with a message naming the file and what to change.
"""

from __future__ import annotations

import numpy as np

from hostile import IDENTIFY, OUT, case  # noqa: F401

L, H = 30.0, 6.0  # the strip [mesh units]


def grid(nx, ny, triangles, length=L, height=H, x0=0.0):
    """Corners of a ``length`` x ``height`` strip from x = ``x0``, cells (linear triangles or quadrilaterals),
    its left and right edges (lines) and the corner (x0, 0) (a point)."""
    x, y = np.meshgrid(np.linspace(x0, x0 + length, nx + 1), np.linspace(0.0, height, ny + 1), indexing="ij")
    points = np.column_stack([x.ravel(), y.ravel(), np.zeros(x.size)])
    first = (np.arange(nx)[:, None] * (ny + 1) + np.arange(ny)[None, :]).ravel()
    quads = np.column_stack([first, first + ny + 1, first + ny + 2, first + 1])
    cells = np.vstack([quads[:, [0, 1, 2]], quads[:, [0, 2, 3]]]) if triangles else quads
    left = np.column_stack([np.arange(ny), np.arange(1, ny + 1)])
    return points, cells, left, left + nx * (ny + 1), np.array([[0]])


def write_msh(path, points, cells, left, right, corner, kind, clockwise=False, binary=False):
    """A Gmsh 2.2 file of the strip: the surface ``domain`` and the groups ``left``, ``right``, ``origin``."""
    import meshio

    cells = cells[:, ::-1] if clockwise else cells
    blocks = [(kind, cells), ("line", np.vstack([left, right])), ("vertex", corner)]
    physical = [np.full(len(cells), 1), np.r_[np.full(len(left), 2), np.full(len(right), 3)], np.full(len(corner), 4)]
    mesh = meshio.Mesh(points, blocks, cell_data={"gmsh:physical": physical, "gmsh:geometrical": physical},
                       field_data={"domain": np.array([1, 2]), "left": np.array([2, 1]), "right": np.array([3, 1]),
                                   "origin": np.array([4, 0])})
    meshio.write(path, mesh, file_format="gmsh22", binary=binary)
    return path


def two_halves(gap=0.0):
    """The strip as two halves meshed apart (their own nodes on x = L/2, or a ``gap`` between them): the
    points, cells, left and right edges and the origin."""
    a, b = grid(3, 2, True, L / 2), grid(3, 2, True, L / 2, x0=L / 2 + gap)
    shift = len(a[0])
    return np.vstack([a[0], b[0]]), np.vstack([a[1], b[1] + shift]), a[2], b[3] + shift, a[4]


CONFIG = """\
[model]
type = "gradient-damage"
parameters = {{E = 30000.0, kappa_i = 1e-4, beta = 300.0, c = 4.0}}

[specimen]
type = "mesh"
file = "strip.msh"
thickness = 5.0
{scale}
supports = {supports}
loads = [{{group = "right", component = "{load}", rigid = true}}]
[specimen.controls]
elongation = [{{group = "right", component = "{load}"}}]

[simulate]
target = 0.01
"""

SUPPORTS = '[{group = "left", component = "x"}, {group = "origin", component = "y"}]'


def strip_config(*, scale="", supports=SUPPORTS, load="x") -> str:
    """The simulation config of the strip in ``strip.msh``, pulled along ``load`` ("x" or "y")."""
    return CONFIG.format(scale=scale, supports=supports, load=load)


def mesh_case(words, mesh, *, scale="", supports=SUPPORTS, load="x", status=2):
    """``fracid simulate`` of the strip config whose ``strip.msh`` is written by ``mesh(path)``."""
    config = strip_config(scale=scale, supports=supports, load=load)
    return case(status, words, config=config, csv=None, args=("simulate", "cfg.toml", "--quiet"),
                files=lambda d: mesh(d / "strip.msh"))


def _strip(length=L, height=H, nx=6, ny=2):
    return lambda path: write_msh(path, *grid(nx, ny, True, length, height), "triangle")


def _halves(gap):
    return lambda path: write_msh(path, *two_halves(gap), "triangle")


def _corner_on_the_right(path):
    """The strip whose point group ``origin`` is the corner (L, 0), on the loaded edge."""
    points, cells, left, right, _ = grid(6, 2, True)
    write_msh(path, points, cells, left, right, right[:1, :1], "triangle")


def _text(content: str):
    return lambda path: path.write_text(content)


GMSH_1 = """$NOD
4
1 0 0 0
2 30 0 0
3 30 6 0
4 0 6 0
$ENDNOD
$ELM
2
1 2 1 1 3 1 2 3
2 2 1 1 3 1 3 4
$ENDELM
"""

CASES = {
    "mesh-duplicate-nodes": mesh_case(("strip.msh", "nodes lie on another node", "e.g. two at [15.0, ", "Coherence"),
                                      _halves(0.0)),
    "mesh-two-pieces": mesh_case(("strip.msh", "2 pieces", "piece 2 (12 elements, x in [15.5, 30.5]",
                                  "Boolean fragments", "add a support"), _halves(0.5)),
    "mesh-support-overlaps-rigid-load": mesh_case(
        ("strip.msh", "support group 'origin'", "rigid load group 'right'", "share 1 node", "rigid = false"),
        _corner_on_the_right, load="y"),
    "mesh-gmsh-1.0-file": mesh_case(("strip.msh", "Gmsh 1.0", "2.2", "4.1", "Export"), _text(GMSH_1)),
    "mesh-text-file-named-msh": mesh_case(("strip.msh", "not a mesh file", "2.2", "4.1"),
                                          _text("node x y\n1 0.0 0.0\n2 30.0 0.0\n")),
    "mesh-binary-garbage-named-msh": mesh_case(("strip.msh", "not a mesh file", "2.2"),
                                               lambda path: path.write_bytes(b"\x89PNG\r\n\x1a\n\xff\xfe" * 64)),
    "mesh-too-large": mesh_case(("strip.msh", "unknowns", "memory", "2,000,000", "coarser mesh"),
                                lambda path: write_msh(path, *grid(500, 500, True), "triangle", binary=True)),
    "mesh-in-metres-without-scale": mesh_case(("strip.msh", "0.03 x 0.006 units of its own", "l = sqrt(2 c) = 2.83 mm",
                                               "scale = 1000"), _strip(L / 1000, H / 1000)),
    "mesh-in-micrometres-without-scale": mesh_case(("strip.msh", "more than 100 times", "scale = 0.001"),
                                                   _strip(L * 1000, H * 1000)),
    "mesh-scale-1000-on-a-mesh-in-mm": mesh_case(("strip.msh", "specimen.scale = 1000", "more than 100 times",
                                                  "leave scale out"),
                                                 _strip(), scale="scale = 1000.0"),
}
