"""``[[experiments]] kind = "field"``: a DIC displacement field (frame table + point clouds) as a data block.

Keys (see :mod:`fracid.config.schema`): ``frames_file`` (the frame table, CSV: frame, file and load columns),
``control_column`` (the table's column giving each frame's control value [mm], e.g. "cmod_mm"), the point-cloud
columns ``x``, ``y``, ``u``, ``v`` (default "X", "Y", "U", "V"), ``sigma`` and ``quality`` (optional; point-data
arrays when the table lists VTU/VTK files, whose displacement array is ``displacement``),
``min_quality``, ``coordinate_unit`` ("mm" | "px"), the placement of the camera on the specimen (``scale``
[mm per camera unit], ``rotation_deg``, ``origin_camera``, ``origin_specimen``; or ``marked_camera`` and
``marked_specimen``, the same points in both frames, fitted), ``frames`` (frame numbers, default all),
``components`` ("u" | "v" | ["u", "v"]), ``std`` [mm] (else the files' sigma), ``subset_size`` [mm] (correlated
errors), ``rigid_motion`` (true, the default: the rigid motion of every frame removed from data and model by a
vague prior of std ``rigid_std`` [mm], default 1; false: the data have none), ``exclude_near`` [mm] (points
nearer the specimen's crack path dropped), ``point_spacing`` [mm] (the points thinned to one per square of this
side, :mod:`fracid.data.dic.reduction`), ``name``, ``weight``, ``role``.
The data are read while the configuration is checked: every problem names its key. Their points are located on
the specimen's mesh then (:mod:`fracid.inverse.experiments.field_on_mesh`: a few outside dropped with a warning,
more refused with the likely cause), and a frame without any valid value is dropped with a warning naming it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from fracid.data.covariance import STD_ALLOWED, usable_std
from fracid.data.dic.formats import FORMATS
from fracid.inverse.experiments.field_log import (LOG_KEY_DOCS, read_log_settings)
from fracid.inverse.experiments.vocabulary import BLOCK_KEYS, FORMAT_KEYS, ROLES, choices_text, file_format
from fracid.settings.checks import show
from fracid.settings.keys import REQUIRED, UNSET, Key, Said

_CLOUD = "A column of the point clouds (a point-data array of VTU/VTK frames)"
_PLACEMENT = "The placement of the camera on the specimen"
#: the keys of a field block, each described
FIELD_KEY_DOCS = {
    "kind": Key(REQUIRED, "", "a registered kind", "The kind of the block."),
    "frames_file": Key(REQUIRED, "", "a CSV file path", "The frame table (frame, file and load columns); relative "
                                                        "to the configuration file unless absolute."),
    "control_column": Key(Said("required without machine_log"), "", "a column name",
                          "The frame table's column of each frame's control value."),
    "x": Key("X", "", "a column name", f"{_CLOUD}: the x coordinate."),
    "y": Key("Y", "", "a column name", f"{_CLOUD}: the y coordinate."),
    "u": Key("U", "", "a column name", f"{_CLOUD}: the x displacement."),
    "v": Key("V", "", "a column name", f"{_CLOUD}: the y displacement."),
    "sigma": Key(UNSET, "", "a column name", f"{_CLOUD}: the displacement's standard deviation."),
    "quality": Key(UNSET, "", "a column name", f"{_CLOUD}: the correlation quality."),
    "displacement": Key(Said('"displacement", else "U"'), "", "a point-data array name",
                        "Frames listed as .vtu/.vtk files: their displacement array."),
    "min_quality": Key(UNSET, "", "a number; needs quality", "Points of lower quality are dropped."),
    "coordinate_unit": Key(Said("mm, or the format's unit"), "", '"mm" | "px" (needs the placement)',
                           "The unit of the clouds' coordinates."),
    "format": Key("generic", "", choices_text(FORMATS),
                  "The export's layout (fracid.data.dic.formats): its columns and unit become the defaults of the "
                  "column keys and coordinate_unit; dice drops failed subsets (SIGMA = -1) and counts them."),
    "scale": Key(UNSET, "mm per camera unit", "> 0", f"{_PLACEMENT}: its scale."),
    "rotation_deg": Key(0.0, "degrees", "a number", f"{_PLACEMENT}: the camera's rotation."),
    "origin_camera": Key(UNSET, "camera unit", "[X, Y]", f"{_PLACEMENT}: a point in the camera's frame ..."),
    "origin_specimen": Key(UNSET, "mm", "[x, y]", "... and the same point in the specimen's."),
    "marked_camera": Key(UNSET, "camera unit", "a list of [X, Y] points",
                         f"{_PLACEMENT}, fitted: marked points in the camera's frame (instead of scale, rotation_deg "
                         "and the origins); points off the specimen's mesh: up to 10 % dropped (warned), more refused."),
    "marked_specimen": Key(UNSET, "mm", "a list of [x, y] points", "The same points in the specimen's frame."),
    "frames": Key(Said("all"), "", "a list of frame numbers, control increasing",
                  "The frames used; a frame without any valid value is dropped (warned)."),
    "components": Key(["u", "v"], "", '"u" | "v" | ["u", "v"]', "The displacement components used."),
    "std": Key(Said("the files' sigma"), "mm", "> 0", "The standard deviation of every value."),
    "subset_size": Key(UNSET, "mm", "> 0", "Errors correlated over a subset of this size (a sparse covariance: "
                        "fracid.data.dic_noise; the DIC code's subset in pixels times the scale)."),
    "rigid_motion": Key(True, "", "true | false", "The rigid motion of every frame removed from data and model, by a "
                                                  "vague prior of std rigid_std (false: the data have none)."),
    "rigid_std": Key(1.0, "mm", "> 0", "The std of the rigid motion's vague prior."),
    "exclude_near": Key(UNSET, "mm", ">= 0", "Points nearer the specimen's crack path are dropped."),
    "point_spacing": Key(UNSET, "mm", "> 0", "A dense field is thinned to one point per square of this side."),
    "file_column": Key("file", "", "a column name", "The frame table's column of each frame's point-cloud file "
                       "(relative to the frame table's folder)."),
    **FORMAT_KEYS,
    **LOG_KEY_DOCS,
    "name": Key("field", "", "a non-empty string", "The block's name (the derived blocks name it as their field)."),
    **BLOCK_KEYS,
}
FIELD_KEYS = tuple(FIELD_KEY_DOCS)
#: point-cloud column keys and their defaults (those of :func:`fracid.data.dic.read_dic_frames`)
COLUMN_KEYS = {"x": "X", "y": "Y", "u": "U", "v": "V", "sigma": None, "quality": None, "displacement": None}
PLACEMENT_KEYS = ("scale", "rotation_deg", "origin_camera", "origin_specimen")


@dataclass(frozen=True)
class FieldExperimentConfig:
    """One ``[[experiments]]`` block of kind "field" (``file`` is the frame table, absolute)."""

    index: int
    file: Path
    control_column: str
    columns: tuple  # ((key, column name or None), ...) of COLUMN_KEYS
    n_points: int  # number of kept values: the block's size
    placement: object = None  # CameraPlacement or None
    min_quality: float | None = None
    coordinate_unit: str = "mm"
    format: str = "generic"  # fracid.data.dic.formats.FORMATS
    frames: tuple | None = None
    components: tuple = ("u", "v")
    std: float | None = None
    subset_size: float | None = None
    rigid_std: float | None = 1.0  # None: no rigid motion removed
    exclude_near: float | None = None
    point_spacing: float | None = None
    file_column: str = "file"
    log: object = None  # LogSettings (fracid.inverse.experiments.field_log) or None
    delimiter: str = ","
    decimal: str = "."
    name: str = "field"
    weight: float = 1.0
    role: str = "calibration"
    kind: str = "field"
    quantity: str = "displacement"  # not a curve quantity: studies of force curves skip the block
    specimen: tuple = ()  # no per-experiment specimen overrides
    damage_threshold: float = 0.0
    measures_force = False  # displacements [mm]

    def check_lines(self, specimen) -> list:
        """What ``fracid check`` prints of the block (:mod:`fracid.inverse.experiments.field_check`)."""
        from fracid.inverse.experiments.field_check import field_check_lines

        return field_check_lines(self, *placed_field_block(self, specimen), specimen)

    def view_extras(self, specimen) -> dict:
        """What the report's view adds: ``sync``, the frames synchronised with the machine log (or None), and
        ``placement``, the camera's (or None), and ``camera_unit``, the unit of the files' coordinates."""
        return {"sync": field_synchronisation(self, specimen), "placement": self.placement,
                "camera_unit": self.coordinate_unit}

    def frame_slices(self, specimen, start: int) -> tuple:
        """(labels, slices) of each frame's entries in the data, the block starting at entry ``start``."""
        from fracid.inverse.experiments.field_check import field_frame_slices

        return field_frame_slices(self, placed_field_block(self, specimen)[0], start)


def field_block(exp: FieldExperimentConfig, specimen):
    """The :class:`~fracid.data.dic.FieldBlock` of the block on the specimen object ``specimen`` (whose crack path
    ``exclude_near`` refers to). Raises :class:`~fracid.data.DataError` for bad data."""
    return placed_field_block(exp, specimen)[0]


def placed_field_block(exp: FieldExperimentConfig, specimen) -> tuple:
    """(:func:`field_block`, its warnings), built once per process (:mod:`fracid.inverse.experiments.field_build`)."""
    from fracid.inverse.experiments.field_build import placed_field_block as placed

    return placed(exp, specimen)


def field_synchronisation(exp: FieldExperimentConfig, specimen):
    """The frames synchronised with the machine log, or None (:mod:`fracid.inverse.experiments.field_build`)."""
    from fracid.inverse.experiments.field_build import field_synchronisation as synchronisation

    return synchronisation(exp, specimen)


def _optional_number(ck, key: str, raw: dict, name: str, allowed: str, ok) -> float | None:
    return ck.number(key, raw[name], allowed, ok) if name in raw else None


def _point_list(ck, key: str, value) -> list:
    """A list of [x, y] pairs of numbers."""
    allowed = "must be a list of [x, y] points, e.g. [[0, 0], [100, 0], [0, 50]]"
    if not isinstance(value, list) or not value:
        ck.fail(key, value, allowed)
    return [ck.pair(key, point, allowed) for point in value]


def _placement(ck, prefix: str, raw: dict, unit: str):
    """The CameraPlacement of the keys (scale, rotation_deg, origins; or marked points fitted), or None."""
    from fracid.data import DataError
    from fracid.data.dic import CameraPlacement, fit_placement

    marked = [k for k in ("marked_camera", "marked_specimen") if k in raw]
    direct = [k for k in PLACEMENT_KEYS if k in raw]
    if marked and direct:
        ck.fail(f"{prefix}.{direct[0]}", raw[direct[0]], f"give the placement either by {', '.join(PLACEMENT_KEYS)} "
                "or by marked_camera and marked_specimen (fitted), not both")
    if marked:
        for k in ("marked_camera", "marked_specimen"):
            if k not in raw:
                ck.missing(f"{prefix}.{k}", "the marked points in the other frame, in the same order")
        camera = _point_list(ck, f"{prefix}.marked_camera", raw["marked_camera"])
        specimen = _point_list(ck, f"{prefix}.marked_specimen", raw["marked_specimen"])
        try:
            placement = fit_placement(camera, specimen)
        except DataError as err:
            ck.fail(f"{prefix}.marked_camera", raw["marked_camera"], str(err))
        for note in placement.notes:
            if note.startswith("WARNING"):
                ck.warn(f"{prefix}.marked_camera: {note}")
        return placement
    if not direct:
        if unit == "px":
            ck.missing(f"{prefix}.scale", "coordinate_unit = 'px' needs the placement: scale [mm per px] (with "
                       "rotation_deg, origin_camera, origin_specimen), or marked_camera and marked_specimen")
        return None
    if "scale" not in raw:
        ck.missing(f"{prefix}.scale", "a number > 0 [mm per camera unit] (1 if the camera data are in mm)")
    scale = ck.number(f"{prefix}.scale", raw["scale"], "must be a number > 0 [mm per camera unit]", lambda v: v > 0)
    rotation = ck.number(f"{prefix}.rotation_deg", raw.get("rotation_deg", 0.0), "must be an angle [deg]")
    origins = [ck.pair(f"{prefix}.{k}", raw.get(k, [0.0, 0.0]), "must be a point [x, y]")
               for k in ("origin_camera", "origin_specimen")]
    return CameraPlacement(scale, math.radians(rotation), tuple(origins[0]), tuple(origins[1]))


def _rigid_std(ck, prefix: str, raw: dict) -> float | None:
    """The prior std of the rigid motion [mm], or None when ``rigid_motion = false``."""
    from fracid.data.dic.rigid import RIGID_STD

    removed = raw.get("rigid_motion", True)
    if not isinstance(removed, bool):
        ck.fail(f"{prefix}.rigid_motion", removed, "must be true (the rigid motion of every frame removed from data "
                "and model, the default) or false (the data have none: the camera is fixed to the supports)")
    if not removed:
        if "rigid_std" in raw:
            ck.fail(f"{prefix}.rigid_std", raw["rigid_std"], "is the prior std of the rigid motion removed: it needs "
                    "rigid_motion = true")
        return None
    return ck.number(f"{prefix}.rigid_std", raw.get("rigid_std", RIGID_STD),
                     f"must be a number {STD_ALLOWED} [mm], larger than the rigid motion (e.g. 1)", usable_std)


def _frames(ck, key: str, raw: dict) -> tuple | None:
    if "frames" not in raw:
        return None
    value = raw["frames"]
    if (not isinstance(value, list) or not value or any(isinstance(v, bool) or not isinstance(v, int) for v in value)
            or len(set(value)) != len(value)):
        ck.fail(key, value, "must be a list of distinct frame numbers (integers) of the frame table, e.g. [1, 2, 4]")
    return tuple(value)


def _components(ck, key: str, raw: dict) -> tuple:
    value = raw.get("components", ["u", "v"])
    values = [value] if isinstance(value, str) else value
    if (not isinstance(values, list) or not values or len(set(map(str, values))) != len(values)
            or any(v not in ("u", "v") for v in values)):
        ck.fail(key, value, 'must be "u" (x), "v" (y) or ["u", "v"] (both, the default)')
    return tuple(values)


def _columns(ck, prefix: str, raw: dict, defaults: dict) -> tuple:
    """((key, column), ...) of COLUMN_KEYS: the given names, else the ``format``'s (``defaults``), else fracid's."""
    columns = tuple((k, ck.string(f"{prefix}.{k}", raw[k], "must be a column name (string)") if k in raw
                     else defaults.get(k, d)) for k, d in COLUMN_KEYS.items())
    if "min_quality" in raw and "quality" not in raw:
        ck.fail(f"{prefix}.min_quality", raw["min_quality"], "needs quality = the point clouds' quality column")
    return columns


def _blamed_key(exp: FieldExperimentConfig, message: str) -> str:
    """The key a DataError of the reader or of field_block is about (a column, the frames, the std ...)."""
    if message.startswith(("frames", "control column")):
        return "frames"
    for name, column in (("control_column", exp.control_column), ("file_column", exp.file_column), *exp.columns):
        if column is not None and f"column {show(column)}" in message:
            return name
    for name in ("std", "subset_size", "rigid_std"):
        if message.startswith(f"{name} "):
            return name
    if "per-point sigma" in message:
        return "sigma"
    for name, what in (("displacement", "(the displacements)"), ("sigma", "(the displacement std)"),
                       ("quality", "(the correlation quality)")):
        if what in message:  # a VTU/VTK frame without the point-data array
            return name
    return "exclude_near" if "no value left" in message and exp.exclude_near is not None else "frames_file"


def read_field_experiment(ck, i: int, raw: dict, context) -> tuple:
    """The validated field block ``i`` of ``[[experiments]]`` and its :class:`~fracid.data.dic.FieldBlock`, read
    while checking (the data's size is ``n_points``; the blocks derived from it reuse the FieldBlock);
    ``context``: a :class:`~fracid.inverse.experiments.registry.ReadContext`."""
    from fracid.data import DataError

    prefix = f"experiments[{i}]"
    ck.table(prefix, raw, FIELD_KEYS)
    if "frames_file" not in raw:
        ck.missing(f"{prefix}.frames_file", "the frame table (CSV with frame, file and load columns), relative to "
                   "the config file")
    file = ck.file(f"{prefix}.frames_file", raw["frames_file"], context.base)
    log = read_log_settings(ck, prefix, raw, context.base)
    if log is None and "control_column" not in raw:
        ck.missing(f"{prefix}.control_column", "the frame table's column of the control value [mm], e.g. 'cmod_mm' "
                   "(or machine_log, the testing machine's log)")
    control_column = log.control_name if log is not None else ck.string(f"{prefix}.control_column",
                                                                        raw["control_column"],
                                                                        "must be a column name (string)")
    layout = FORMATS[ck.choice(f"{prefix}.format", raw.get("format", "generic"), tuple(FORMATS))]
    columns = _columns(ck, prefix, raw, layout.columns)
    min_quality = _optional_number(ck, f"{prefix}.min_quality", raw, "min_quality", "must be a number", lambda v: True)
    unit = ck.choice(f"{prefix}.coordinate_unit", raw.get("coordinate_unit", layout.unit or "mm"), ("mm", "px"))
    if layout.unit is not None and unit != layout.unit:
        ck.fail(f"{prefix}.coordinate_unit", unit, f"format = {layout.name!r} writes {layout.unit}: leave "
                "coordinate_unit out (the placement's scale converts them to mm)")
    delimiter, decimal = file_format(ck, prefix, raw)
    positive = "must be a number > 0 [mm]"
    exp = FieldExperimentConfig(
        index=i, file=file, control_column=control_column, columns=columns, n_points=0,
        placement=_placement(ck, prefix, raw, unit), min_quality=min_quality, coordinate_unit=unit, format=layout.name,
        frames=_frames(ck, f"{prefix}.frames", raw), components=_components(ck, f"{prefix}.components", raw),
        std=_optional_number(ck, f"{prefix}.std", raw, "std", f"must be a number {STD_ALLOWED} [mm]", usable_std),
        subset_size=_optional_number(ck, f"{prefix}.subset_size", raw, "subset_size", positive, lambda v: v > 0),
        rigid_std=_rigid_std(ck, prefix, raw),
        exclude_near=_optional_number(ck, f"{prefix}.exclude_near", raw, "exclude_near", "must be a number >= 0 [mm]",
                                      lambda v: v >= 0),
        point_spacing=_optional_number(ck, f"{prefix}.point_spacing", raw, "point_spacing", positive, lambda v: v > 0),
        file_column=ck.string(f"{prefix}.file_column", raw.get("file_column", "file"), "must be a column name (string)"),
        log=log,
        delimiter=delimiter, decimal=decimal,
        name=ck.string(f"{prefix}.name", raw.get("name", "field"), "must be a non-empty string"),
        weight=ck.number(f"{prefix}.weight", raw.get("weight", 1.0), "must be a number > 0", lambda v: v > 0),
        role=ck.choice(f"{prefix}.role", raw.get("role", "calibration"), ROLES))
    try:
        block, warnings = placed_field_block(exp, context.specimen())
    except DataError as err:
        key = getattr(err, "key", None) or _blamed_key(exp, str(err))
        ck.fail(f"{prefix}.{key}", raw.get(key, COLUMN_KEYS.get(key)), str(err))
    except ValueError as err:
        ck.fail(f"{prefix}.exclude_near", raw.get("exclude_near"), str(err))
    for warning in warnings:
        ck.warn(f"{prefix}.frames_file: {warning}")
    return replace(exp, n_points=block.data.n_y), block


def check_matches(observation, control, file) -> None:
    """Refuse an observation of a field (or of a block derived from one) whose values are not those of its
    block of the data (``control`` [mm]): the data were not built from this configuration."""
    if observation.size != len(control) or not np.array_equal(observation.controls, control):
        raise ValueError(f"the data's block {observation.name!r} does not match the field of {file} ({len(control)} "
                         f"values, the field {observation.size}); build the data with build_data(cfg)")


@dataclass(frozen=True)
class FieldKind:
    """``kind = "field"``: a DIC displacement field; its blocks are sources of the derived kinds."""

    name: str = "field"
    keys: tuple = FIELD_KEYS
    column_keys: tuple = ()
    source: str | None = None
    view: str | None = "displacement-field"  # the report's maps and per-frame fit

    @property
    def key_docs(self) -> dict:
        """Key -> :class:`~fracid.settings.keys.Key` of the block's keys."""
        return FIELD_KEY_DOCS

    def read(self, ck, index: int, raw: dict, context) -> tuple:
        """(the validated :class:`FieldExperimentConfig`, its FieldBlock)."""
        return read_field_experiment(ck, index, raw, context)

    def block(self, exp: FieldExperimentConfig, context):
        """The :class:`~fracid.data.dic.FieldBlock` of the block on ``context.specimen``."""
        return field_block(exp, context.specimen)

    def data(self, exp: FieldExperimentConfig, context):
        return self.block(exp, context).data

    def observation(self, exp: FieldExperimentConfig, context, name: str, control):
        """The :class:`~fracid.inverse.core.field_observations.FieldObservation` of the block, checked against its block
        of the data (``control`` [mm])."""
        from fracid.inverse.core.field_observations import field_observation

        observation = field_observation(self.block(exp, context), context.specimen, control=context.control, name=name)
        check_matches(observation, control, exp.file)
        return observation


FIELD = FieldKind()

__all__ = ["COLUMN_KEYS", "FIELD", "FIELD_KEYS", "FIELD_KEY_DOCS", "PLACEMENT_KEYS", "FieldExperimentConfig", "FieldKind",
           "check_matches", "field_block", "placed_field_block", "read_field_experiment"]
