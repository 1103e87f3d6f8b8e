"""Validators of the sections ``[model]``, ``[specimen]``, ``[output]``, ``[simulate]`` and ``[study]``,
and the specimen field checks the ``specimen`` overrides of ``[[experiments]]`` share.

Each validator takes the :class:`~fracid.config.checker.Checker` of the file and the raw TOML table
and returns the section's frozen dataclass (:mod:`fracid.config.schema`), or raises
:class:`~fracid.config.schema.ConfigError`.
"""

from __future__ import annotations

import dataclasses
import re
from pathlib import Path

from fracid.models.registry import DEFAULT_MODEL_TYPE
from fracid.config.checker import Checker, bytes_text, show
from fracid.config.registry import (model_of, model_types, parameter_range, specimen_class,
                                   specimen_types)
from fracid.config.schema import (
    ConfigError,
    ModelConfig,
    OutputConfig,
    SimulateConfig,
    SpecimenConfig,
    StudyConfig,
)
from fracid.config.vocabulary import (
    MODEL_KEYS,
    OUTPUT,
    OUTPUT_KEYS,
    SIMULATE_KEYS,
    SPECIMEN_KEYS,
    STUDY_KEYS,
)
from fracid.models.protocol import declared
from fracid.settings.checks import is_integer
from fracid.specimens.protocol import SectionError


def range_text(cls, name: str) -> str:
    """The valid range of parameter ``name`` of the parameter class ``cls`` in words (e.g. ``"0 < c"``,
    ``"-1 < nu < 0.5"``): from its :class:`~fracid.fem.material.ranges.ParameterRange` when it declares
    ``ranges``, else the limits of ``valid_bounds`` (the interface every model's class has)."""
    rng = getattr(cls, "ranges", {}).get(name)
    if rng is not None:
        return rng.describe(name)
    lower, upper = cls.valid_bounds([name])
    return f"{lower[0]:g} <= {name} <= {upper[0]:g}"


def _parameter_allowed(cls, name: str) -> str:
    return f"must be a number in the valid range {range_text(cls, name)} [{cls.units().get(name, '-')}]"


def valid_parameter(cls, name: str, value: float) -> bool:
    """Whether ``value`` lies in the valid range of ``name`` (its ``ParameterRange``, else the class's
    ``valid_bounds``, whose open ends are moved inside). Conditions joining several parameters are
    left to the class (see :func:`read_model`)."""
    rng = getattr(cls, "ranges", {}).get(name)
    if rng is not None:
        return rng.admits(value)
    lower, upper = cls.valid_bounds([name])
    return bool(lower[0] <= value <= upper[0])


def _model_law(ck: Checker, raw, kind: str) -> str | None:
    """``[model] law``: one of the model's laws by name (:func:`fracid.models.model_laws`), or None."""
    if "law" not in raw:
        return None
    from fracid.models import model_laws

    laws = tuple(model_laws(model_of(kind)))
    if not laws:
        ck.fail("model.law", raw["law"], f"model.type = {kind!r} takes no law by name (its law is fixed here)")
    return ck.choice("model.law", raw["law"], laws)


def read_model(ck: Checker, raw) -> ModelConfig:
    if raw is None:
        return ModelConfig()
    ck.table("model", raw, MODEL_KEYS)
    kind = ck.choice("model.type", raw.get("type", DEFAULT_MODEL_TYPE), model_types())
    law = _model_law(ck, raw, kind)
    cls = model_of(kind, law).parameters
    names = cls.names()
    params = raw.get("parameters", {})
    if not isinstance(params, dict):
        ck.fail("model.parameters", params, f"must be a table (section) with keys among {', '.join(names)}")
    values = {}
    for name, value in params.items():
        key = f"model.parameters.{name}"
        if name not in names:
            ck.fail(key, value, f"not a parameter of model.type = {kind!r} ({cls.__name__}); "
                                f"allowed keys here: {', '.join(names)}")
        values[name] = ck.number(key, value, _parameter_allowed(cls, name),
                                 lambda v, name=name: valid_parameter(cls, name, v))
    try:  # conditions joining several parameters, e.g. the area of the cohesive law over c1, c2
        cls(**values)
    except ValueError as err:
        ck.fail("model.parameters", params, f"rejected together by {cls.__name__} (model.type = {kind!r}): {err}")
    return ModelConfig(type=kind, parameters=tuple(values.items()), law=law)


def check_model_runs_on(ck: Checker, model: ModelConfig, specimen) -> None:
    """Refuse a model that does not run on the specimen, with its reason and the specimen types it runs on."""
    from fracid.models import runs_on

    made = model_of(model.type, model.law)
    built = specimen_class(specimen.type)(**dict(specimen.options))
    if runs_on(made, built):
        return
    fits = []
    for kind in specimen_types():
        instance = specimen_class(kind).default_instance()
        if instance is not None and runs_on(made, instance):
            fits.append(repr(kind))
    ck.fail("specimen.type", specimen.type, f"model.type = {model.type!r} does not run on it ({made.why_not(built)}); "
            "it runs on " + (", ".join(fits) or "no built-in specimen"))


def _field_kind(field: dataclasses.Field) -> str:
    text = field.type if isinstance(field.type, str) else getattr(field.type, "__name__", str(field.type))
    return text.replace("| None", "").replace("Optional[", "").replace("]", "").strip()


def specimen_error_key(err: Exception, fields, given) -> str | None:
    """The specimen field an error of its validation is about: of the fields the error names (its
    ``names``, a :class:`~fracid.settings.field_error.FieldError`), the first the user gave, else the first.
    An error without ``names`` (a specimen class of another package) is searched for field names."""
    names = getattr(err, "names", None)
    if names is None:  # fallback: the field names in the message, in their order there
        message = str(err)
        found = sorted((match.start(), name) for name in fields
                       if (match := re.search(rf"(?<![A-Za-z0-9_]){re.escape(name)}(?![A-Za-z0-9_])", message)))
        names = [name for _, name in found]
    names = [name for name in names if name in fields]
    return next((name for name in names if name in given), names[0] if names else None)


def specimen_options(ck: Checker, prefix: str, raw: dict, cls) -> dict:
    """Type-check specimen fields (``raw`` holds field names only)."""
    fields = {f.name: f for f in dataclasses.fields(cls)}
    options = {}
    for name, value in raw.items():
        key, ftype = f"{prefix}.{name}", _field_kind(fields[name])
        if ftype == "float":
            options[name] = ck.number(key, value, f"must be a number (field {name} of {cls.__name__})")
        elif ftype == "int":
            options[name] = ck.integer(key, value, f"must be an integer (field {name} of {cls.__name__})")
        elif ftype == "str":
            options[name] = ck.string(key, value, f"must be a string (field {name} of {cls.__name__})")
        else:
            options[name] = value
    return options


def check_specimen(ck: Checker, prefix: str, kind: str, cls, options: dict, given: dict) -> None:
    """Build the specimen once so its own validation runs; errors name the key under ``prefix``."""
    try:
        cls(**options)
    except (TypeError, ValueError) as err:
        fields = {f.name: f for f in dataclasses.fields(cls)}
        name = specimen_error_key(err, fields, options)
        if name is None:
            raise ConfigError(f"{ck.path}: {prefix} ({kind}) is invalid: {err}") from None
        value = options.get(name, getattr(cls, name, None))
        where = f"{prefix}.{name}" if name in given else f"specimen.{name}"
        default = "" if name in options else " (default)"
        raise ConfigError(f"{ck.path}: {where} = {show(value)}{default}: {err}") from None


def value_text(value) -> str:
    """A specimen field's value in a message: a float as ``%g`` (2, 0.01), anything else as TOML shows it."""
    if isinstance(value, float):
        return f"{value:g}"
    return show(value)


def field_key(prefix: str, name: str, options: dict, given: dict) -> tuple[str, str]:
    """The dotted key of specimen field ``name`` (under ``prefix`` if given there, else ``specimen``)
    and " (default)" when it was not given at all."""
    return (f"{prefix}.{name}" if name in given else f"specimen.{name}"), ("" if name in options else " (default)")


def specimen_variants(specimen: SpecimenConfig, experiments) -> list:
    """The specimens a configuration runs, as (key prefix, options, the options given under that prefix): ``[specimen]``
    and every ``[[experiments]]`` entry that overrides its fields (``experiments[i].specimen``)."""
    base = dict(specimen.options)
    return [("specimen", base, base)] + [(f"experiments[{e.index}].specimen", {**base, **dict(e.specimen)},
                                          dict(e.specimen)) for e in experiments if e.specimen]


def check_specimen_size(ck: Checker, prefix: str, kind: str, cls, options: dict, given: dict) -> None:
    """Refuse a problem beyond the specimen's limit (bar elements, unknowns of a plane mesh), estimated by
    the specimen from its geometry without building the mesh (the specimen is valid: :func:`check_specimen`
    ran first)."""
    size = cls(**options).size_estimate()
    if not size.too_large:
        return
    key, default = field_key(prefix, size.field or "type", options, given)
    if prefix != "specimen" and size.field not in given:  # the experiment's overrides make the problem too large
        default += f" with {prefix} = {{" + ", ".join(f"{k} = {show(v)}" for k, v in given.items()) + "}"
    shape = ", ".join(f"{name} = {value:g}" for name, value in options.items()
                      if isinstance(value, float) and name != size.field)
    raise ConfigError(
        f"{ck.path}: {key} = {value_text(size.value)}{default}: the mesh of this {kind} would have {size.summary} "
        f"(estimated from the geometry{': ' + shape if shape else ''}), needing about {bytes_text(size.memory)} of "
        f"memory in a forward run ({size.bytes_per:,} bytes per {size.unit}, measured); at most {size.limit:,} "
        f"{size.unit}s are allowed: {size.advice}")


def read_specimen(ck: Checker, raw, base=None) -> SpecimenConfig:
    """The validated ``[specimen]``: its type among :data:`fracid.specimens.SPECIMENS`, read by the
    specimen's own section reader if it declares one (a mesh file), else by its dataclass fields."""
    types = specimen_types()
    if raw is None:
        ck.missing("specimen", "a [specimen] section with type = " + " | ".join(repr(t) for t in types))
    if not isinstance(raw, dict):
        ck.fail("specimen", raw, "must be a table (section)")
    if "type" not in raw:
        ck.missing("specimen.type", "one of " + ", ".join(repr(t) for t in types))
    kind = ck.choice("specimen.type", raw["type"], types)
    cls = specimen_class(kind)
    reader = cls.config_section
    if reader is not None:
        try:
            control, options = reader.read(ck, raw, base if base is not None else ck.path.parent, cls)
        except SectionError as err:
            raise ConfigError(f"{ck.path}: {err}") from None
        return SpecimenConfig(type=kind, control=control, options=tuple(options.items()))
    fields = {f.name: f for f in dataclasses.fields(cls)}
    ck.table("specimen", raw, (*SPECIMEN_KEYS, *fields))
    options = specimen_options(ck, "specimen", {k: v for k, v in raw.items() if k not in SPECIMEN_KEYS}, cls)
    check_specimen(ck, "specimen", kind, cls, options, options)
    controls = cls(**options).control_names
    control = ck.choice("specimen.control", raw.get("control", controls[0]), controls)
    check_specimen_size(ck, "specimen", kind, cls, options, options)
    return SpecimenConfig(type=kind, control=control, options=tuple(options.items()))


def check_specimen_section(ck: Checker, model: ModelConfig, specimen: SpecimenConfig, identify) -> None:
    """The check of a specimen's own ``[specimen]`` reader (its ``config_section``; e.g.
    a mesh's units) against the length the model's mesh must resolve (its
    :class:`~fracid.models.protocol.MeshLength`; none: nothing to check) over the values of its parameter given
    and identified (:func:`~fracid.config.registry.parameter_range`)."""
    cls = specimen_class(specimen.type)
    reader = cls.config_section
    mesh_length = declared(model_of(model.type, model.law)).mesh_length
    if reader is None or mesh_length is None:
        return
    extremes = parameter_range(model, identify, mesh_length.parameter, mesh_length.unit)
    try:
        reader.check(cls(**dict(specimen.options)), mesh_length, extremes)
    except SectionError as err:
        raise ConfigError(f"{ck.path}: {err}") from None


def read_output(ck: Checker, raw, base: Path) -> OutputConfig:
    raw = ck.table("output", {} if raw is None else raw, OUTPUT_KEYS)
    path = ck.location("output.directory", raw.get("directory", OUTPUT["directory"].default), base, "must be a directory path (string)")
    steps = raw.get("vtk_steps", [])
    allowed = "must be a list of step numbers (integers >= 0)"
    if not isinstance(steps, list) or not all(is_integer(step) and step >= 0 for step in steps):
        ck.fail("output.vtk_steps", steps, allowed)
    return OutputConfig(directory=path, vtk_steps=tuple(sorted(set(steps))))


def read_simulate(ck: Checker, raw) -> SimulateConfig:
    raw = ck.table("simulate", {} if raw is None else raw, SIMULATE_KEYS)
    default = SimulateConfig()
    target = None
    if "target" in raw:
        target = ck.number("simulate.target", raw["target"], "must be a number > 0 [mm] (final control value)",
                           lambda v: v > 0)
    return SimulateConfig(
        target=target,
        stop_force_fraction=ck.number("simulate.stop_force_fraction",
                                      raw.get("stop_force_fraction", default.stop_force_fraction),
                                      "must be a number with 0 < f < 1 (fraction of the peak force)",
                                      lambda v: 0 < v < 1),
        damage_threshold=ck.number("simulate.damage_threshold", raw.get("damage_threshold", default.damage_threshold),
                                   "must be a number with 0 <= t < 1 (damage)", lambda v: 0 <= v < 1),
    )


def read_study(ck: Checker, raw) -> StudyConfig:
    raw = ck.table("study", {} if raw is None else raw, STUDY_KEYS)
    default = StudyConfig()

    def given(name):
        return raw.get(name, getattr(default, name))

    return StudyConfig(
        starts=ck.integer("study.starts", given("starts"), "must be an integer >= 0 (0 or 1: no multi-start check)",
                          lambda v: v >= 0),
        replicates=ck.integer("study.replicates", given("replicates"),
                              "must be 0 (no stability check) or an integer >= 2", lambda v: v == 0 or v >= 2),
        seed=ck.integer("study.seed", given("seed"), "must be an integer >= 0", lambda v: v >= 0),
        tolerance=ck.number("study.tolerance", given("tolerance"),
                            "must be a number with 0 < t < 1 (largest relative std called identified)",
                            lambda v: 0 < v < 1),
        # "knn" is the former name of "search", still read
        prior="search" if raw.get("prior") == "knn" else ck.choice("study.prior", given("prior"),
                                                                   ("search", "bounds")),
        posterior=_flag(ck, "study.posterior", given("posterior"),
                        "must be true (fracid study also samples the posterior with the [posterior] settings, and "
                        "the verdict reads its credible intervals) or false (the default: the Gaussian std only)"),
    )


def _flag(ck: Checker, key: str, value, allowed: str) -> bool:
    """A TOML boolean (true or false; not 1, 0 or a string)."""
    if not isinstance(value, bool):
        ck.fail(key, value, allowed)
    return value
