"""``[[experiments]] kind = "opening" | "fpz-width"``: local data derived from a DIC field block.

Keys (see :mod:`fracid.config.schema`): ``field`` (required: the ``name`` of a ``kind = "field"`` block of the
same configuration, whose points, values and covariance the estimate uses; give that block ``role =
"source"`` so that its measurements are not counted twice), then

- ``kind = "opening"``, the crack-opening profile (:func:`fracid.data.dic.derived.opening_profile`: virtual
  extensometers across the crack): ``heights`` [mm] (positions along the ligament, increasing), ``gauge`` [mm]
  (the half-length: the ends at this distance from the crack line), ``radius`` [mm] (of the plane fit at each
  end), ``pairs`` (optional: true, ends on both sides of the crack; false, the symmetric half, w = 2 u_n(+gauge);
  default: pairs if the field has points on both sides of the crack line);
- ``kind = "fpz-width"``, the process-zone width (:func:`fracid.data.dic.derived.process_zone_width`):
  ``heights`` [mm], ``offsets`` [mm] (the samples of each transect across the crack, signed distances from the
  crack line, increasing), ``radius`` [mm] (of the plane fit giving the strain at each sample), ``threshold``
  [-] (the strain above which a sample counts);

and ``name`` (default "opening", "fpz_width"), ``weight``, ``role``. The block's values are the estimate at
every frame of the field (frame slowest), their covariance the field's carried through the estimate.

Rigid motion: the width is free of it. An opening on a half carries the field's rigid motion, which the
model does not have: the field's covariance (``rigid_motion = true``, its default) carries it into the
opening's, so that the profile's mean and tilt at each frame are uninformative (:mod:`fracid.data.dic.derived`).

The estimate is made while the configuration is checked, from the field block read for it (the files are
not read again): every problem names its key.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, replace
from pathlib import Path

from fracid.inverse.experiments.field import FieldExperimentConfig, check_matches
from fracid.inverse.experiments.vocabulary import BLOCK_KEYS, ROLES
from fracid.settings.checks import is_number
from fracid.settings.keys import REQUIRED, Key, Said

#: the keys of each derived kind
DERIVED_KEYS = {
    "opening": ("kind", "field", "heights", "gauge", "radius", "pairs", "name", "weight", "role"),
    "fpz-width": ("kind", "field", "heights", "offsets", "radius", "threshold", "name", "weight", "role"),
}
#: the quantity of each derived kind, the default name of its block
QUANTITIES = {"opening": "opening", "fpz-width": "fpz_width"}
#: what each required key takes
_REQUIRED = {
    "field": 'the name of a kind = "field" block of this configuration (its name key, default "field")',
    "heights": "a list of increasing positions along the ligament [mm], e.g. [30, 35, 40, 45]",
    "gauge": "a number > 0 [mm]: the half-length of the virtual extensometers, beyond the band of missing points",
    "radius": "a number > 0 [mm]: the radius of the plane fits (about 1.5 DIC point spacings or more)",
    "offsets": "a list of at least 2 nonzero, increasing distances from the crack line [mm], e.g. [5, 8, 11, 14]",
    "threshold": "a number > 0 [-]: the strain above which a sample counts (a few times kappa_i)",
}
#: the keys of the derived kinds, each described (what each kind takes: :data:`DERIVED_KEYS`)
DERIVED_KEY_DOCS = {
    "kind": Key(REQUIRED, "", "a registered kind", "The kind of the block: the crack-opening profile by virtual "
                "extensometers across the crack, or the process-zone width by strain transects."),
    "field": Key(REQUIRED, "", _REQUIRED["field"], "The field block the estimate is made from; give it role = "
                 '"source" so that its measurements are not counted twice.'),
    "heights": Key(REQUIRED, "mm", "a list of increasing positions", "Positions along the ligament."),
    "gauge": Key(REQUIRED, "mm", "> 0", "The half-length of the gauges (their ends at +-gauge from the crack line), "
                 "beyond the band of missing points."),
    "radius": Key(REQUIRED, "mm", "> 0", "The radius of the plane fits (about 1.5 DIC point spacings or more)."),
    "pairs": Key(Said("true if the field has points on both sides"), "", "true | false",
                 "Gauge ends on both sides of the crack (the rigid motion cancels), or one: the symmetric half, "
                 "w = 2 u_n(+gauge) (the field's rigid-motion prior makes each frame's mean and tilt uninformative)."),
    "offsets": Key(REQUIRED, "mm", "at least 2 nonzero, increasing distances", "The samples of each transect: "
                   "signed distances from the crack line (positive on the modelled side)."),
    "threshold": Key(REQUIRED, "-", "> 0", "The strain above which a sample counts (a few times kappa_i)."),
    "name": Key(Said("the kind's quantity"), "", "a non-empty string", "The block's name in the results."),
    **BLOCK_KEYS,
}
#: the keys whose library errors begin "key = value" (:mod:`fracid.data.dic.derived`)
_STATED = ("heights", "gauge", "radius", "offsets", "threshold")


@dataclass(frozen=True)
class DerivedExperimentConfig:
    """One ``[[experiments]]`` block of a derived kind (``source``: the configuration of its field block)."""

    index: int
    kind: str  # a key of DERIVED_KEYS
    source: FieldExperimentConfig
    heights: tuple
    radius: float
    gauge: float | None = None  # "opening"
    pairs: bool | None = None  # "opening"; None: pairs if the field has points on both sides
    offsets: tuple = ()  # "fpz-width"
    threshold: float | None = None  # "fpz-width"
    n_points: int = 0  # number of values: the block's size
    name: str = "opening"
    weight: float = 1.0
    role: str = "calibration"
    specimen: tuple = ()  # no per-experiment specimen overrides
    damage_threshold: float = 0.0

    @property
    def file(self) -> Path:
        """The frame table of the field the values come from."""
        return self.source.file

    @property
    def quantity(self) -> str:
        """What the block measures (not "force": studies of force curves skip the block)."""
        return QUANTITIES[self.kind]

    measures_force = False  # lengths [mm]


def derived_block(exp: DerivedExperimentConfig, field, specimen):
    """The :class:`~fracid.data.dic.derived.DerivedBlock` of the block from the
    :class:`~fracid.data.dic.FieldBlock` ``field`` of its source, on the specimen object ``specimen``.

    Raises
    ------
    ValueError, fracid.data.DataError
        As :func:`~fracid.data.dic.derived.opening_profile` and :func:`~fracid.data.dic.derived.process_zone_width`.
    """
    from fracid.data.dic.derived import opening_profile, process_zone_width

    if exp.kind == "opening":
        return opening_profile(field, specimen, exp.heights, exp.gauge, radius=exp.radius, pairs=exp.pairs,
                               name=exp.name)
    return process_zone_width(field, specimen, exp.heights, exp.offsets, radius=exp.radius, threshold=exp.threshold,
                              name=exp.name)


def _required(ck, prefix: str, raw: dict, name: str):
    if name not in raw:
        ck.missing(f"{prefix}.{name}", _REQUIRED[name])
    return raw[name]


def _positions(ck, prefix: str, raw: dict, name: str, minimum: int = 1) -> tuple:
    """A required list of at least ``minimum`` strictly increasing numbers [mm]."""
    value = _required(ck, prefix, raw, name)
    if (not isinstance(value, list) or len(value) < minimum or not all(map(is_number, value))
            or any(b <= a for a, b in zip(value, value[1:]))):
        ck.fail(f"{prefix}.{name}", value, "must be " + _REQUIRED[name])
    return tuple(float(v) for v in value)


def _positive(ck, prefix: str, raw: dict, name: str) -> float:
    return ck.number(f"{prefix}.{name}", _required(ck, prefix, raw, name), "must be " + _REQUIRED[name],
                     lambda v: v > 0)


def _estimator_keys(ck, prefix: str, raw: dict, kind: str) -> dict:
    """The keys of the kind's estimator besides ``heights`` and ``radius``."""
    if kind == "opening":
        pairs = raw.get("pairs")
        if pairs is not None and not isinstance(pairs, bool):
            ck.fail(f"{prefix}.pairs", pairs, "must be true (gauge ends on both sides of the crack) or false (one "
                    "side: the symmetric half, w = 2 u_n(+gauge)); default: true if the field has points on both sides")
        return {"gauge": _positive(ck, prefix, raw, "gauge"), "pairs": pairs}
    return {"offsets": _positions(ck, prefix, raw, "offsets", minimum=2),
            "threshold": _positive(ck, prefix, raw, "threshold")}


def _source(ck, prefix: str, raw: dict, fields: dict) -> tuple:
    """(configuration, FieldBlock) of the field block that ``field`` names; ``fields``: name -> [(config, block)]."""
    key = f"{prefix}.field"
    name = ck.string(key, _required(ck, prefix, raw, "field"), "must be " + _REQUIRED["field"])
    if name not in fields:
        known = ", ".join(map(repr, fields)) or 'none: add a kind = "field" block'
        ck.fail(key, name, f'is not the name of a kind = "field" block of this configuration; its field blocks: '
                f"{known}")
    if len(fields[name]) > 1:
        where = ", ".join(f"experiments[{exp.index}]" for exp, _ in fields[name])
        ck.fail(key, name, f"names {len(fields[name])} field blocks ({where}); give them distinct names")
    return fields[name][0]


def _blamed(kind: str, error: Exception) -> tuple[str, str]:
    """(the key an error of the estimate is about, the reason): ``key = value`` of a library ValueError dropped
    (the checker's message names them); an estimate without enough points blamed on the radius, or with none on
    the other side of the crack on ``pairs`` (the opening) or ``offsets`` (the width)."""
    message = str(error)
    for name in _STATED:
        if message.startswith(f"{name} = "):
            cut = min((c for c in (message.find(": "), message.find("; ")) if c >= 0), default=-2)
            return name, message[cut + 2:]
    if re.search(r"offset -[^:]*: 0 DIC point", message):  # no data on the other side of the crack
        return ("pairs" if kind == "opening" else "offsets"), message
    for text, name in (("needs a symmetric half model", "pairs"), ("DIC point(s) within radius", "radius"),
                       ("straight crack path", "kind"),
                       ("has no variance", "threshold" if kind == "fpz-width" else "heights")):
        if text in message:
            return name, message
    return "field", message


def _check_twice(ck, prefix: str, exp: DerivedExperimentConfig) -> None:
    """Warn when the block and its field are both calibration data: the same measurements counted twice."""
    source = exp.source
    if exp.role == "calibration" and source.role == "calibration":
        ck.warn(f"{prefix} ({exp.kind} {exp.name!r}) is derived from experiments[{source.index}] (field "
                f"{source.name!r}) and both have role = 'calibration': the same DIC measurements are counted twice, "
                f"as if their errors were independent; set role = \"source\" in experiments[{source.index}] "
                "(or in this block)")


def read_derived_experiment(ck, i: int, raw: dict, context):
    """The validated derived block ``i`` of ``[[experiments]]``, its values estimated (their size is ``n_points``).

    ``context.sources`` maps each field block's name to its ``[(FieldExperimentConfig, FieldBlock), ...]`` as
    read while checking (:func:`~fracid.inverse.experiments.field.read_field_experiment`).
    """
    fields = context.sources
    prefix = f"experiments[{i}]"
    kind = raw["kind"]
    ck.table(prefix, raw, DERIVED_KEYS[kind])
    source, field = _source(ck, prefix, raw, fields)
    exp = DerivedExperimentConfig(
        index=i, kind=kind, source=source, heights=_positions(ck, prefix, raw, "heights"),
        radius=_positive(ck, prefix, raw, "radius"), **_estimator_keys(ck, prefix, raw, kind),
        name=ck.string(f"{prefix}.name", raw.get("name", QUANTITIES[kind]), "must be a non-empty string"),
        weight=ck.number(f"{prefix}.weight", raw.get("weight", 1.0), "must be a number > 0", lambda v: v > 0),
        role=ck.choice(f"{prefix}.role", raw.get("role", "calibration"), ROLES))
    try:
        block = derived_block(exp, field, context.specimen())
    except ValueError as err:  # a DataError too
        key, reason = _blamed(kind, err)
        ck.fail(f"{prefix}.{key}", raw.get(key), reason)
    _check_twice(ck, prefix, exp)
    return replace(exp, n_points=block.data.n_y)


@dataclass(frozen=True)
class DerivedKind:
    """A kind of local data derived from the blocks of the kind ``source``."""

    name: str
    keys: tuple
    column_keys: tuple = ()
    source: str | None = "field"
    view: str | None = None  # drawn in the fit figure, against the control

    @property
    def key_docs(self) -> dict:
        """Key -> :class:`~fracid.settings.keys.Key` of the kind's keys."""
        return {key: DERIVED_KEY_DOCS[key] for key in self.keys if key in DERIVED_KEY_DOCS}

    def read(self, ck, index: int, raw: dict, context) -> tuple:
        """(the validated :class:`DerivedExperimentConfig`, None)."""
        return read_derived_experiment(ck, index, raw, context), None

    def block(self, exp: DerivedExperimentConfig, context):
        """The :class:`~fracid.data.dic.derived.DerivedBlock` of the block, from its source's block."""
        return derived_block(exp, context.source_block(exp.source), context.specimen)

    def data(self, exp: DerivedExperimentConfig, context):
        return self.block(exp, context).data

    def observation(self, exp: DerivedExperimentConfig, context, name: str, control):
        """The :class:`~fracid.inverse.core.derived_observations.DerivedFieldObservation` of the block, checked
        against its block of the data (``control`` [mm])."""
        from fracid.inverse.core.derived_observations import derived_observation

        observation = derived_observation(self.block(exp, context), context.specimen, control=context.control,
                                          name=name)
        check_matches(observation, control, exp.file)
        return observation


OPENING = DerivedKind("opening", DERIVED_KEYS["opening"])
FPZ_WIDTH = DerivedKind("fpz-width", DERIVED_KEYS["fpz-width"])

__all__ = ["DERIVED_KEYS", "DERIVED_KEY_DOCS", "FPZ_WIDTH", "OPENING", "QUANTITIES", "DerivedExperimentConfig", "DerivedKind",
           "derived_block", "read_derived_experiment"]
