"""Fields of a damage analysis as a VTK unstructured grid (.vtu) for ParaView.

meshio (a core dependency) is imported when writing.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

# Cell types (meshio names, VTK node order): number of corner nodes, and the corners that each
# higher-order node lies between (its value of a corner-node field is their mean).
_CELL_TYPES = {
    "line": (2, {}),
    "line3": (2, {2: (0, 1)}),
    "triangle": (3, {}),
    "triangle6": (3, {3: (0, 1), 4: (1, 2), 5: (2, 0)}),
    "quad": (4, {}),
    "quad8": (4, {4: (0, 1), 5: (1, 2), 6: (2, 3), 7: (3, 0)}),
    "quad9": (4, {4: (0, 1), 5: (1, 2), 6: (2, 3), 7: (3, 0), 8: (0, 1, 2, 3)}),
}


def corner_to_nodes(values, cells, cell_type: str, n_nodes: int, corner_nodes=None) -> np.ndarray:
    """Extend a field known at the corner nodes to all nodes (higher-order nodes: mean of their corners).

    Parameters
    ----------
    values : ndarray, shape (n_corners,) or (n_nodes,)
        Already nodal if its length is ``n_nodes``.
    cells, cell_type, n_nodes
        The mesh.
    corner_nodes : ndarray of int, shape (n_corners,), optional
        Node of each value; by default the corner nodes of the mesh in increasing order (right
        both for meshes numbering the vertices first and for the bar, whose vertex i is node 2 i).
    """
    values = np.asarray(values, dtype=float)
    if values.shape == (n_nodes,):
        return values
    n_corners, mids = _CELL_TYPES[cell_type]
    if corner_nodes is None:
        corner_nodes = np.unique(cells[:, :n_corners])
    corner_nodes = np.asarray(corner_nodes, dtype=int)
    if values.shape != corner_nodes.shape:
        raise ValueError(f"{values.size} corner values for {corner_nodes.size} corner nodes (and {n_nodes} nodes)")
    out = np.full(n_nodes, np.nan)
    out[corner_nodes] = values
    for local, corners in mids.items():
        out[cells[:, local]] = out[cells[:, list(corners)]].mean(axis=1)
    if np.isnan(out).any():
        raise ValueError("some nodes are neither corner nodes nor between corners of a cell")
    return out


def write_vtk(
    path,
    nodes,
    cells,
    cell_type: str,
    fields: dict,
    *,
    n_u_components: int | None = None,
    ebar_nodes=None,
    point_data_extra: dict | None = None,
    cell_data_extra: dict | None = None,
) -> Path:
    """Write the fields of one state (:meth:`DamageProblem.fields`) as a VTK unstructured grid.

    Parameters
    ----------
    path : str or Path
        Output file, written in the .vtu format whatever its suffix.
    nodes : ndarray, shape (n_nodes, dim) or (n_nodes,)
        Node coordinates [mm], dim <= 3 (padded with zeros to 3).
    cells : ndarray of int, shape (n_el, nodes per cell)
        Node numbers of each cell in VTK order (corners first), one row per element of the
        discretisation (the rows of ``fields["omega"]``).
    cell_type : str
        meshio cell type: "line", "line3", "triangle", "triangle6", "quad", "quad8" or "quad9".
    fields : dict
        ``u`` (nodal displacements ordered node by node: dof = n_u_components * node + component)
        [mm], ``kappa`` and ``omega`` at the integration points, shape (n_el, n_q), and optionally
        ``ebar`` at the corner nodes or at all nodes.
    n_u_components : int, optional
        Displacement components per node; by default ``len(u) / n_nodes``.
    ebar_nodes : ndarray of int, optional
        Node of each ebar value (see :func:`corner_to_nodes` for the default).
    point_data_extra, cell_data_extra : dict {name: ndarray}, optional
        More arrays, shape (n_nodes, ...) and (n_el, ...).

    Point data: ``displacement`` (3 components), ``ebar`` (mid-side nodes: mean of the cell corners).
    Cell data: ``damage_max``, ``damage_mean`` (unweighted mean over the integration points) and
    ``kappa_max``.

    Returns
    -------
    Path
        The file written.
    """
    try:
        import meshio
    except ImportError as err:
        raise ImportError("writing VTK files needs meshio, a dependency of fracid: pip install meshio") from err
    nodes, cells = _checked_mesh(nodes, cells, cell_type)
    n_nodes, dim = nodes.shape
    omega, kappa = _checked_point_fields(fields, len(cells))
    point_data = {"displacement": _displacement(fields["u"], n_nodes, n_u_components)}
    if fields.get("ebar") is not None:
        point_data["ebar"] = corner_to_nodes(fields["ebar"], cells, cell_type, n_nodes, ebar_nodes)
    cell_data = {"damage_max": omega.max(axis=1), "damage_mean": omega.mean(axis=1), "kappa_max": kappa.max(axis=1)}
    _add_extra(point_data, point_data_extra, n_nodes)
    _add_extra(cell_data, cell_data_extra, len(cells))

    points = np.zeros((n_nodes, 3))
    points[:, :dim] = nodes
    mesh = meshio.Mesh(
        points,
        [(cell_type, cells.astype(np.int64))],
        point_data=point_data,
        cell_data={name: [values] for name, values in cell_data.items()},
    )
    path = Path(path)
    meshio.write(path, mesh, file_format="vtu")
    return path


def _checked_mesh(nodes, cells, cell_type: str) -> tuple[np.ndarray, np.ndarray]:
    """``nodes`` as an (n_nodes, dim) float array and ``cells`` as an array, checked against each other and
    ``cell_type`` (ValueError naming the defect)."""
    if cell_type not in _CELL_TYPES:
        raise ValueError(f"cell_type = {cell_type!r}; supported: {sorted(_CELL_TYPES)}")
    nodes = np.asarray(nodes, dtype=float)
    nodes = nodes[:, None] if nodes.ndim == 1 else nodes
    n_nodes, dim = nodes.shape
    if not 1 <= dim <= 3:
        raise ValueError(f"nodes must have 1 to 3 coordinates; got shape {nodes.shape}")
    cells = np.asarray(cells)
    n_per_cell = _CELL_TYPES[cell_type][0] + len(_CELL_TYPES[cell_type][1])
    if cells.ndim != 2 or cells.shape[1] != n_per_cell or not np.issubdtype(cells.dtype, np.integer):
        raise ValueError(f"{cell_type!r} cells must be integers of shape (n_el, {n_per_cell}); got {cells.dtype} {cells.shape}")
    if cells.size and (cells.min() < 0 or cells.max() >= n_nodes):
        raise ValueError(f"cell node numbers must be in [0, {n_nodes})")
    return nodes, cells


def _checked_point_fields(fields: dict, n_el: int) -> tuple[np.ndarray, np.ndarray]:
    """``omega`` and ``kappa`` of ``fields`` at the integration points, both of shape (n_el, n_q)."""
    omega, kappa = np.asarray(fields["omega"], dtype=float), np.asarray(fields["kappa"], dtype=float)
    if omega.ndim != 2 or omega.shape[0] != n_el or kappa.shape != omega.shape:
        raise ValueError(f"omega {omega.shape} and kappa {kappa.shape} must have shape (n_el = {n_el}, n_q)")
    return omega, kappa


def _displacement(u, n_nodes: int, n_u_components: int | None) -> np.ndarray:
    """The nodal displacements ``u`` (node by node) as (n_nodes, 3), padded with zeros.

    Parameters
    ----------
    u : array_like, shape (n_nodes * n_u_components,)
    n_nodes : int
    n_u_components : int or None
        Components per node; None: ``len(u) / n_nodes``.
    """
    u = np.asarray(u, dtype=float)
    if n_u_components is None:
        n_u_components = u.size // n_nodes
    if not 1 <= n_u_components <= 3 or u.size != n_nodes * n_u_components:
        raise ValueError(f"{u.size} displacement dofs do not make {n_u_components} (1 to 3) components at {n_nodes} nodes")
    displacement = np.zeros((n_nodes, 3))
    displacement[:, :n_u_components] = u.reshape(n_nodes, n_u_components)
    return displacement


def _add_extra(data: dict, extra: dict | None, n_rows: int) -> None:
    """Add the arrays of ``extra`` to ``data``, each checked to have ``n_rows`` rows."""
    for name, values in (extra or {}).items():
        values = np.asarray(values)
        if values.shape[:1] != (n_rows,):
            raise ValueError(f"extra array {name!r} of shape {values.shape} needs {n_rows} rows")
        data[name] = values


def write_result_vtk(directory, specimen, result, stem: str = "step") -> list:
    """Write every stored step of a forward run as ``<directory>/<stem>_<step>.vtu``.

    Parameters
    ----------
    directory : str or Path
        Created if missing.
    specimen
        The specimen the result comes from (its description provides ``output_mesh()``).
    result : PathResult
        Steps written are those in ``result.fields`` (see ``field_steps`` of ``simulate``).

    Returns
    -------
    list of Path
        The files written, in step order.
    """
    from pathlib import Path

    directory = Path(directory)
    directory.mkdir(parents=True, exist_ok=True)
    nodes, cells, cell_type = specimen.describe().output_mesh()
    return [
        write_vtk(directory / f"{stem}_{step:04d}.vtu", nodes, cells, cell_type, result.fields[step])
        for step in sorted(result.fields)
    ]
