"""The written contract of a specimen (:class:`Specimen`) and the defaults most specimens share
(:class:`SpecimenDefaults`).

A specimen says what a test is: its :class:`~fracid.specimens.description.Description`, the named
controls (the first the default), the local observables its damage models record [mm], its default
target and steps, the field a size-effect series scales, and its limits: how fine its mesh is
(:class:`Resolution`) and how much memory a forward run needs (:class:`SizeEstimate`). The
configuration asks the specimen these things instead of branching on its type name, so a specimen
registered in :data:`fracid.specimens.SPECIMENS` (from a test file too) is read, checked and run like
the built-in ones.

The memory limits live here (measured on forward runs) and are re-exported by :mod:`fracid.config`.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Callable, ClassVar, NamedTuple, Protocol, runtime_checkable

import numpy as np

#: largest number of bar elements: about 4 kB each in a forward run (measured), so 2e5 elements
#: take about 1 GB; 1e8 elements hung the machine
MAX_BAR_ELEMENTS = 200_000

#: measured memory of a forward run of the bar per element [bytes]
BAR_BYTES_PER_ELEMENT = 4_000

#: largest number of unknowns (2 displacements per node + 1 nonlocal strain per vertex) of a 2D
#: mesh: about 6 kB each in a forward run (measured, before the sparse factorisation's own
#: memory), so 2e6 unknowns take about 12 GB, and every step factorises the matrix again
MAX_UNKNOWNS = 2_000_000

#: measured memory of a forward run of the 2D specimens per unknown [bytes]
BYTES_PER_UNKNOWN = 6_000

#: the advice of a mesh specimen whose element size is a field
_FIELD_ADVICE = "use {field} <= l/2"
_ENOUGH = "a few elements per internal length l = sqrt(2 c) are enough"


@dataclass(frozen=True)
class Resolution:
    """How fine a specimen's mesh is where the damage localises.

    Parameters
    ----------
    field : str or None
        The configuration key that sets the element size (``"h_fine"``, ``"n_elements"``, ``"file"``),
        None if no key does.
    value : object
        That key's value (a number, or the mesh file's path).
    h : float
        The element size [mm] (in the process zone, or the smallest side of a mesh).
    text : str
        The element size in words, e.g. ``"the element size h_fine = 1 mm"``.
    advice : str
        What to change to resolve an internal length (the words of a warning).
    """

    field: str | None
    value: object
    h: float
    text: str
    advice: str


class BandRoom(NamedTuple):
    """The extent of a specimen that the band of a regularised model must fit into: across the crack path where
    the crack forms through the whole section at once (a bar, a strip), else the depth of the section the crack
    runs through (a beam's depth, a dog-bone's narrowest width), whose faces cut the band's profile about the
    crack's tip.

    Attributes
    ----------
    length : float
        The extent [mm].
    text : str
        It in words, naming the key that sets it, e.g. ``"its length = 100 mm"``.
    most, most_text : float or None, str
        Where the geometry says less (a mesh: which side the crack crosses is not known), the extent beyond which no
        band can form whatever the crack's direction [mm] and it in words; None: ``length``.
    """

    length: float
    text: str
    most: float | None = None
    most_text: str = ""

    @property
    def limit(self) -> "BandRoom":
        """The room beyond which no band can form: ``most`` where given, else this one."""
        return self if self.most is None else BandRoom(self.most, self.most_text)


class SectionError(ValueError):
    """A ``[specimen]`` table refused by the specimen's own reader (:class:`SpecimenSection`): the message names
    the key and the value; the configuration prefixes it with the file's path."""


@dataclass(frozen=True)
class SpecimenSection:
    """The reader of a ``[specimen]`` table that is not the specimen's dataclass fields (a specimen class
    declares it as its ``config_section``), in the specimen's own room.

    Parameters
    ----------
    read : callable (checker, raw table, base directory, specimen class) -> (control, options)
        Validates the table (every key, the files it names) with the configuration's checker (duck-typed:
        ``table``, ``missing``, ``file``, ``number``, ``string``, ``choice``, ``fail``), raising its errors
        or :class:`SectionError`; returns the control's name and the specimen's fields (a dict).
    check : callable (specimen, mesh length, extremes) -> None
        The check joining the table with the model and the identification: ``mesh length`` is the model's
        :class:`~fracid.models.protocol.MeshLength` (when it has one), ``extremes`` ((smallest value, where),
        (largest value, where)) of its parameter; raises :class:`SectionError` (e.g. a mesh drawn in metres).
    keys : mapping
        The keys ``read`` accepts besides ``type`` and ``control``, each described (key ->
        :class:`~fracid.settings.keys.Key`; an empty meaning is the specimen class's field of the same name), for
        the configuration reference (:mod:`fracid.config.reference`).
    """

    read: Callable
    check: Callable
    keys: Mapping = field(default_factory=dict)


@dataclass(frozen=True)
class SizeEstimate:
    """The size of a forward run's problem, estimated from the geometry without building the mesh.

    Parameters
    ----------
    field : str or None
        The configuration key that sets the size (``"h_fine"``, ``"n_elements"``), None if none.
    value : object
        That key's value.
    summary : str
        The size in words, e.g. ``"about 1,200 elements and 9,800 unknowns"``.
    count : int
        The number of the limited items (bar elements or unknowns).
    unit : str
        Their name in the singular (``"element"``, ``"unknown"``).
    bytes_per : int
        Measured memory of a forward run per item [bytes].
    limit : int
        The largest count a configuration accepts.
    advice : str
        What to change to make the problem smaller.
    """

    field: str | None
    value: object
    summary: str
    count: int
    unit: str
    bytes_per: int
    limit: int
    advice: str

    @property
    def memory(self) -> float:
        """Estimated memory of a forward run [bytes]."""
        return float(self.count) * self.bytes_per

    @property
    def too_large(self) -> bool:
        return self.count > self.limit


@runtime_checkable
class Specimen(Protocol):
    """What every specimen of :data:`fracid.specimens.SPECIMENS` provides (a test checks each).

    ``control_names`` are the names of its controls (the first is ``default_control``; a mesh
    specimen's ``controls`` field holds their definitions), ``observables`` the local observables its
    damage models record [mm], ``size_field`` the field a size-effect series scales (None: no series).
    ``config_section`` reads and checks its ``[specimen]`` section when that is not its dataclass fields
    (a :class:`SpecimenSection`; None: the fields are the keys). ``snap_back_control`` is the control that
    grows through a snap-back (an opening across the crack; None: none is known).
    ``band_room()`` is the extent the band of a regularised model must fit into (:class:`BandRoom`).
    ``refined(factor)`` is the same specimen with its element size where it localises divided by ``factor``
    (the discretisation error's finer mesh). ``default_instance()`` is the specimen with its defaults (None when
    it needs the user's input).
    """

    size_field: str | None
    config_section: SpecimenSection | None
    snap_back_control: str | None

    @property
    def control_names(self) -> tuple: ...

    @property
    def observables(self) -> tuple: ...

    @property
    def default_control(self) -> str: ...

    def describe(self): ...

    def default_target(self, scales) -> float: ...

    def default_steps(self, target: float): ...

    def resolution(self, internal_length: float | None = None) -> Resolution: ...

    def size_estimate(self) -> SizeEstimate: ...

    def band_room(self) -> BandRoom: ...

    def refined(self, factor: float): ...

    def options_text(self, options: dict) -> str: ...

    @classmethod
    def default_instance(cls): ...


def element_sides(description) -> tuple:
    """(smallest, largest) element side of a description [mm]: corner to corner (2D), element length (bar)."""
    cells = description.cells
    if description.dim == 1:  # vertex i is node 2 i
        lengths = np.abs(np.diff(description.nodes[2 * cells][..., 0], axis=1))
    else:
        corners = description.nodes[description.corners]
        lengths = np.linalg.norm(corners - np.roll(corners, -1, axis=1), axis=-1)
    return float(lengths.min()), float(lengths.max())


def bounding_room(nodes, symmetry_planes=(), which=min) -> float:
    """The smallest (``which=max``: largest) side of the bounding box of ``nodes`` (n, dim) [mm], a half or quarter
    model mirrored about its ``symmetry_planes`` ((axis, coordinate), ...) so that the side is the whole specimen's."""
    nodes = np.asarray(nodes, dtype=float)
    sides = np.ptp(nodes, axis=0)
    for axis, coordinate in symmetry_planes:
        sides[axis] = 2.0 * np.max(np.abs(nodes[:, axis] - coordinate))
    return float(which(sides))


def plane_estimate(field: str | None, value, elements: int, nodes: int, vertices: int, advice: str) -> SizeEstimate:
    """The :class:`SizeEstimate` of a plane mesh of ``elements`` 8-node (or 6-node) elements, ``nodes``
    nodes and ``vertices`` corner nodes: 2 displacements per node + 1 nonlocal strain per vertex."""
    unknowns = 2 * int(nodes) + int(vertices)
    return SizeEstimate(field, value, f"about {int(elements):,} elements and {unknowns:,} unknowns", unknowns,
                        "unknown", BYTES_PER_UNKNOWN, MAX_UNKNOWNS, advice)


class SpecimenDefaults:
    """Defaults of the :class:`Specimen` members for a specimen class to inherit.

    ``controls`` (a class attribute of names) gives ``control_names`` and ``default_control``;
    ``steps_per_target`` the default steps (at most ``target / steps_per_target``; None: the path
    follower's defaults); the resolution and size are those of the described mesh (a specimen whose
    element size is a field says so by overriding :meth:`resolution` and :meth:`size_estimate`).
    """

    size_field: ClassVar[str | None] = None
    config_section: ClassVar[SpecimenSection | None] = None
    snap_back_control: ClassVar[str | None] = None
    steps_per_target: ClassVar[float | None] = 60.0
    observables: ClassVar[tuple] = ()

    @property
    def control_names(self) -> tuple:
        return tuple(self.controls)

    @property
    def default_control(self) -> str:
        return self.control_names[0]

    def default_steps(self, target: float):
        """Adaptive steps capped at ``target / steps_per_target``, so the softening branch takes tens of steps."""
        from fracid.fem.path.path_following import StepOptions

        return StepOptions() if self.steps_per_target is None else StepOptions(maximum=target / self.steps_per_target)

    def resolution(self, internal_length: float | None = None) -> Resolution:
        """The smallest element side of the described mesh [mm] (no field sets it)."""
        h = element_sides(self.describe())[0]
        return Resolution(None, None, h, f"its smallest element side, {h:.3g} mm,",
                          "refine the mesh where the crack runs to sides <= l/2")

    def size_estimate(self) -> SizeEstimate:
        """The size of the described mesh (built once: override for a large mesh)."""
        d = self.describe()
        return plane_estimate(None, None, len(d.cells), len(d.nodes), d.n_vertices, f"use a coarser mesh ({_ENOUGH})")

    def band_room(self) -> BandRoom:
        """The smallest side of the described specimen's bounding box, mirrored about its symmetry planes [mm]: the
        crack may cross it (a beam's depth) and cut the band. Which side it crosses is not known (a strip's band lies
        along its largest side), so no band forms only beyond the largest side (``most``)."""
        d = self.describe()
        smallest, largest = bounding_room(d.nodes, d.symmetry_planes), bounding_room(d.nodes, d.symmetry_planes, max)
        return BandRoom(smallest, f"the smallest side of its bounding box, {smallest:.4g} mm", largest,
                        f"the largest side of its bounding box, {largest:.4g} mm")

    def options_text(self, options: dict) -> str:
        """The options given in ``[specimen]`` in words: ``"depth = 100, h_fine = 2"``, or ``"defaults"``."""
        return ", ".join(f"{k} = {v}" for k, v in options.items()) or "defaults"

    def refined(self, factor: float):
        """The same specimen with its element size where it localises divided by ``factor`` (< 1: coarser).

        Through the field :meth:`resolution` names: an element size (``h_fine``) divided by ``factor``, an element
        count (``n_elements``) multiplied by it and rounded (the actual ratio is the two resolutions' ``h``).

        Raises
        ------
        ValueError
            When no field sets the element size (a mesh file, a fixed mesh), naming the specimen.
        """
        resolution = self.resolution()
        if resolution.field == "n_elements":
            count = max(3, int(round(self.n_elements * factor)))
            try:
                return dataclasses.replace(self, n_elements=count)
            except ValueError:  # a count it refuses (the tension strip's is odd): the next one
                return dataclasses.replace(self, n_elements=count + 1)
        if resolution.field is not None and isinstance(resolution.value, (int, float)):
            return dataclasses.replace(self, **{resolution.field: resolution.value / factor})
        raise ValueError(f"{type(self).__name__}: no field sets its element size ({resolution.text}), so fracid "
                         "cannot make a refined mesh of it; give meshes of two sizes yourself")

    @classmethod
    def default_instance(cls):
        """The specimen with its default fields (None for one that needs the user's input, e.g. a file)."""
        return cls()


class FineSizeDefaults(SpecimenDefaults):
    """The resolution and size of a plane specimen meshed with ``h_fine`` in its process zone and a
    ``mesh_size()`` method that counts its mesh from the geometry."""

    def resolution(self, internal_length: float | None = None) -> Resolution:
        h = float(self.h_fine)
        return Resolution("h_fine", self.h_fine, h, f"the element size h_fine = {h:g} mm",
                          _FIELD_ADVICE.format(field="h_fine"))

    def size_estimate(self) -> SizeEstimate:
        return plane_estimate("h_fine", self.h_fine, *self.mesh_size(), f"use a larger h_fine ({_ENOUGH})")


def bar_resolution(length: float, n_elements: int, internal_length: float | None) -> Resolution:
    """The :class:`Resolution` of a uniform mesh of ``n_elements`` along ``length`` [mm]: the advice is
    the element count that gives h <= l/2 (or says it is beyond :data:`MAX_BAR_ELEMENTS`)."""
    h = length / n_elements
    advice = "use n_elements >= 2 length / l (h <= l/2)"
    if internal_length is not None:
        needed = 2.0 * length / internal_length
        advice = (f"use n_elements >= {int(np.ceil(needed))} (h <= l/2)" if needed <= MAX_BAR_ELEMENTS else
                  f"that needs {needed:.3g} elements, beyond the limit {MAX_BAR_ELEMENTS}: is c in mm^2?")
    return Resolution("n_elements", n_elements, h, f"the element size length / n_elements = {h:.3g} mm", advice)


def refined(specimen, factor: float):
    """The same specimen with its element size where it localises divided by ``factor`` (< 1: coarser).

    The specimen's declared :meth:`~Specimen.refined` (:meth:`SpecimenDefaults.refined`: through the field its
    resolution names; the notched beam and the dog-bone have their own).

    Raises
    ------
    ValueError
        When no field sets the element size (a mesh file, a fixed mesh), naming the specimen.
    """
    return specimen.refined(factor)
