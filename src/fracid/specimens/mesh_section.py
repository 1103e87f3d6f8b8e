"""``[specimen] type = "mesh"``: the user's own plane-stress test from a Gmsh mesh and the names of its
physical groups (:class:`fracid.specimens.mesh.MeshSpecimen`), read and checked here, in the specimen's room:
the configuration passes its checker in (``table``, ``missing``, ``file``, ``number``, ``string``, ``choice``,
``fail``: duck-typed, no import of :mod:`fracid.config`) and turns a :class:`~fracid.specimens.protocol.SectionError`
into its own error, prefixed with the file's path.

.. code-block:: toml

    [specimen]
    type = "mesh"
    file = "beam.msh"                  # relative to the configuration file
    thickness = 50.0                   # [mm]
    scale = 1.0                        # mm per unit of the mesh (1000 for a mesh in metres)
    symmetry_factor = 2.0              # a half model
    control = "cmod"                   # default: the first control
    supports = [{group = "support", component = "y"}]
    loads = [{group = "plate", component = "y", force = -0.5, rigid = true}]
    symmetry = [{group = "ligament", component = "x"}]
    regions = [{group = "platen", stiffness_factor = 5.8, damageable = false}]  # a steel platen
    crack = {group = "ligament", component = "x"}   # the crack line (x = const), the FPZ width across it;
                                                    # element_size = 2.0 sets a cohesive crack's penalty
    [specimen.controls]
    cmod = [{group = "mouth", component = "x", weight = 2.0}]
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from fracid.settings.checks import bytes_text
from fracid.settings.keys import REQUIRED, UNSET, Key
from fracid.specimens import protocol
from fracid.specimens.mesh_reading import MeshError, mesh_size, mesh_unknowns
from fracid.specimens.protocol import SectionError, SpecimenSection, element_sides

_GROUPS = "a list of {group, component}"
#: the keys of the section besides ``type`` and ``control`` (the configuration's), described; an empty meaning is
#: that of the :class:`~fracid.specimens.mesh.MeshSpecimen` field of the same name
KEYS = {
    "file": Key(REQUIRED, "", "a Gmsh .msh file with physical groups", "The mesh file, relative to the "
                "configuration file unless absolute (any format meshio reads with physical groups)."),
    "thickness": Key(REQUIRED, "mm", "> 0"),
    "scale": Key(1.0, "mm per mesh unit", "> 0"),
    "symmetry_factor": Key(1.0, "-", ">= 1"),
    "supports": Key(REQUIRED, "", _GROUPS),
    "loads": Key(REQUIRED, "", "a list of {group, component, force = 1.0, rigid = true}"),
    "symmetry": Key([], "", _GROUPS),
    "controls": Key(REQUIRED, "", "a table of named lists of {group, component, weight = 1.0} (e.g. cmod = [...])"),
    "crack": Key(UNSET, "", "{group, component, element_size}"),
    "regions": Key([], "", "a list of {group, stiffness_factor, damageable}"),
}
_KEYS = ("type", "control", *KEYS)
_COMPONENT = "must be 'x' or 'y'"
#: an element side this many times the largest length the mesh must resolve is taken for a unit mistake
_COARSEST = 100.0
#: a mesh whose extent is below this many units is probably drawn in metres
_METRES = 5.0


def mesh_specimen(ck, raw: dict, base: Path, cls) -> tuple:
    """The validated ``[specimen]`` table of a mesh: (control, options of ``cls``, the specimen class); the file
    is read and every group named is checked.

    Parameters
    ----------
    ck : checker
        The configuration's checker (duck-typed: ``table``, ``missing``, ``file``, ``number``, ``string``,
        ``choice``, ``fail``), whose errors name the key and the value.
    raw : dict
        The ``[specimen]`` table.
    base : Path
        The directory relative file names start from.
    cls : type
        The specimen class (:class:`~fracid.specimens.mesh.MeshSpecimen` or a subclass).
    """
    ck.table("specimen", raw, _KEYS)
    for key in ("file", "thickness", "supports", "loads", "controls"):
        if key not in raw:
            ck.missing(f"specimen.{key}", _ALLOWED[key])
    options = {
        "path": str(ck.file("specimen.file", raw["file"], base)),
        "thickness": ck.number("specimen.thickness", raw["thickness"], "must be a number > 0 [mm]", lambda v: v > 0),
        "scale": ck.number("specimen.scale", raw.get("scale", 1.0), "must be a number > 0 (mm per mesh unit)",
                           lambda v: v > 0),
        "symmetry_factor": ck.number("specimen.symmetry_factor", raw.get("symmetry_factor", 1.0),
                                     "must be a number >= 1 (copies of the model in the specimen)", lambda v: v >= 1),
        "supports": _group_list(ck, "specimen.supports", raw["supports"]),
        "loads": _loads(ck, raw["loads"]),
        "symmetry": _group_list(ck, "specimen.symmetry", raw.get("symmetry", [])),
        "controls": _controls(ck, raw["controls"]),
        "crack": _crack(ck, raw["crack"]) if "crack" in raw else (),
        "regions": _regions(ck, raw.get("regions", [])),
    }
    names = tuple(name for name, _ in options["controls"])
    control = ck.choice("specimen.control", raw.get("control", names[0]), names)
    _check_mesh(cls, options)
    return control, options


_ALLOWED = {
    "file": "a Gmsh .msh file with physical groups, relative to the config file",
    "thickness": "the out-of-plane thickness [mm]",
    "supports": f"{_GROUPS}: the nodes held at zero",
    "loads": KEYS["loads"].allowed,
    "controls": KEYS["controls"].allowed,
}


def _items(ck, key, value, allowed):
    if not isinstance(value, list) or not all(isinstance(item, dict) for item in value):
        ck.fail(key, value, f"must be a list of tables {allowed}")
    return value


def _group_component(ck, where, item, extra=()) -> tuple:
    """(group, component) of one table ``{group, component, *extra}``."""
    ck.table(where, item, ("group", "component", *extra))
    for name in ("group", "component"):
        if name not in item:
            ck.missing(f"{where}.{name}", "a physical group name" if name == "group" else _COMPONENT)
    return (ck.string(f"{where}.group", item["group"], "must be a physical group name"),
            ck.choice(f"{where}.component", item["component"], ("x", "y")))


def _group_list(ck, key, value) -> tuple:
    return tuple(_group_component(ck, f"{key}[{i}]", item)
                 for i, item in enumerate(_items(ck, key, value, "{group, component}")))


def _loads(ck, value) -> tuple:
    key = "specimen.loads"
    if not _items(ck, key, value, "{group, component, force, rigid}"):
        ck.fail(key, value, "must name at least one group the force acts on")
    out = []
    for i, item in enumerate(value):
        where = f"{key}[{i}]"
        group, component = _group_component(ck, where, item, ("force", "rigid"))
        force = ck.number(f"{where}.force", item.get("force", 1.0), "must be a non-zero number [N per unit load factor]",
                          lambda v: v != 0)
        rigid = item.get("rigid", True)
        if not isinstance(rigid, bool):
            ck.fail(f"{where}.rigid", rigid, "must be true (the group's nodes move together) or false (force spread)")
        out.append((group, component, rigid, force))
    return tuple(out)


def _controls(ck, value) -> tuple:
    key = "specimen.controls"
    if not isinstance(value, dict) or not value:
        ck.fail(key, value, "must be a table of named controls, e.g. cmod = [{group = 'mouth', component = 'x'}]")
    out = []
    for name, terms in value.items():
        where = f"{key}.{name}"
        if not _items(ck, where, terms, "{group, component, weight}"):
            ck.fail(where, terms, "must list at least one {group, component, weight}")
        measured = []
        for i, item in enumerate(terms):
            group, component = _group_component(ck, f"{where}[{i}]", item, ("weight",))
            weight = ck.number(f"{where}[{i}].weight", item.get("weight", 1.0), "must be a non-zero number",
                               lambda v: v != 0)
            measured.append((group, component, weight))
        out.append((name, tuple(measured)))
    return tuple(out)


def _crack(ck, value) -> tuple:
    group, component = _group_component(ck, "specimen.crack", value, ("element_size",))
    if "element_size" not in value:
        return group, component
    size = ck.number("specimen.crack.element_size", value["element_size"], "must be a number > 0 [mm]",
                     lambda v: v > 0)
    return group, component, size


def _regions(ck, value) -> tuple:
    key = "specimen.regions"
    out = []
    for i, item in enumerate(_items(ck, key, value, "{group, stiffness_factor, damageable}")):
        where = f"{key}[{i}]"
        ck.table(where, item, ("group", "stiffness_factor", "damageable"))
        if "group" not in item:
            ck.missing(f"{where}.group", "a physical surface's name")
        group = ck.string(f"{where}.group", item["group"], "must be a physical surface's name")
        factor = ck.number(f"{where}.stiffness_factor", item.get("stiffness_factor", 1.0),
                           "must be a number > 0 (Young's modulus relative to the material's)", lambda v: v > 0)
        damageable = item.get("damageable", True)
        if not isinstance(damageable, bool):
            ck.fail(f"{where}.damageable", damageable, "must be true or false (false: stays elastic, e.g. steel)")
        out.append((group, factor, damageable))
    return tuple(out)


def _check_mesh(cls, options: dict) -> None:
    """Count the mesh's unknowns, then read the mesh and describe the specimen once: a bad mesh, one too
    large or a group it lacks is a :class:`SectionError`."""
    try:
        check_mesh_size(options["path"])
        cls(**options).describe()
    except ImportError as err:
        raise SectionError(f"specimen.file: {err}") from None
    except ValueError as err:
        text = str(err).removeprefix(f"{options['path']}: ")  # the file is named once
        raise SectionError(f"specimen.file = {options['path']!r}: {text}") from None


def check_mesh_size(path: str) -> None:
    """Raise MeshError, before the mesh is built, when its unknowns exceed
    :data:`~fracid.specimens.protocol.MAX_UNKNOWNS` (the limit of the built-in specimens' meshes)."""
    n_vertices, n_cells = mesh_size(path)
    unknowns = mesh_unknowns(n_vertices, n_cells)
    if unknowns > protocol.MAX_UNKNOWNS:
        raise MeshError(
            f"{path}: {n_cells:,} elements and {n_vertices:,} corner nodes make about {unknowns:,} unknowns once "
            f"fracid adds the mid-edge nodes, needing about {bytes_text(unknowns * protocol.BYTES_PER_UNKNOWN)} of memory "
            f"in a forward run ({protocol.BYTES_PER_UNKNOWN:,} bytes per unknown, measured); at most "
            f"{protocol.MAX_UNKNOWNS:,} unknowns are allowed: use a coarser mesh (small elements only where the crack "
            "runs; a few elements per internal length l = sqrt(2 c) are enough)")


def check_mesh_units(specimen, mesh_length, extremes) -> None:
    """Refuse a mesh whose size is implausible against the length the model's mesh must resolve, a sign of a
    unit mistake (a mesh drawn in metres without ``scale = 1000``, or in micrometres): that length larger than
    the whole mesh for the smallest parameter value considered, or the smallest element side more than
    :data:`_COARSEST` times it for the largest.

    Parameters
    ----------
    specimen : MeshSpecimen
        The specimen of the validated ``[specimen]`` table.
    mesh_length : MeshLength
        The model's (:class:`~fracid.models.protocol.MeshLength`: its ``parameter``, ``unit``, ``length`` and
        ``text``), e.g. the internal length l = sqrt(2 c) of a gradient damage model.
    extremes : tuple
        ((smallest value, where), (largest value, where)) of its parameter, given or default and the bounds of
        an identified one, ``where`` in words.

    Raises
    ------
    SectionError
        Naming the file, the mesh's extent in its units and in mm, ``specimen.scale``, the parameter and the length.
    """
    description = specimen.describe()
    scale, name, unit = specimen.scale, mesh_length.parameter, mesh_length.unit
    extent = np.ptp(description.nodes, axis=0) / scale  # mesh units
    size = (f"specimen.file = {specimen.path!r}: the mesh spans {extent[0]:.6g} x {extent[1]:.6g} units of its own, "
            f"{extent[0] * scale:.6g} x {extent[1] * scale:.6g} mm with specimen.scale = {scale:g} (mm per unit)")
    (small, small_where), (large, large_where) = extremes
    length = mesh_length.length(small)
    if length > extent.max() * scale:
        hint = ("is the mesh drawn in metres? then set scale = 1000 under [specimen] (mm per mesh unit)"
                if extent.max() < _METRES else f"check specimen.scale (mm per mesh unit) and that {name} is in {unit}")
        raise SectionError(f"{size}, smaller than {mesh_length.text} = {length:.3g} mm (with {small_where}): {hint}")
    length, side = mesh_length.length(large), element_sides(description)[0]
    if side > _COARSEST * length:
        hint = ("is the mesh drawn in mm? then leave scale out (1, the default)" if scale > 1 else
                "scale = 0.001 for a mesh drawn in micrometres")
        raise SectionError(f"{size}; its smallest element side, {side:.6g} mm, is more than {_COARSEST:g} times "
                           f"{mesh_length.text} = {length:.3g} mm (with {large_where}): check specimen.scale ({hint}) "
                           f"and that {name} is in {unit}")


#: the ``[specimen]`` table of :class:`~fracid.specimens.mesh.MeshSpecimen` (its ``config_section``)
SECTION = SpecimenSection(read=mesh_specimen, check=check_mesh_units, keys=KEYS)
