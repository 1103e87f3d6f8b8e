"""Validation of the ``[identify]`` section: identified parameters, their bounds and log flags, the inverse
method, and the tables of its settings ``[identify.<table>]``, which the configuration does not know: every table
a registered method declares is allowed (:func:`fracid.inverse.methods.registry.known_tables`), and the chosen
method reads and checks its own by its ``from_config`` (:func:`method_from_config`); a table the chosen method
does not read is checked by a method that reads it and warned about."""

from __future__ import annotations

from fracid.config.checker import Checker
from fracid.config.registry import model_of, specimen_class
from fracid.config.schema import IdentifyConfig, ModelConfig, SpecimenConfig
from fracid.config.sections import range_text, valid_parameter
from fracid.config.vocabulary import BOUNDS_KEYS, DEFAULT_INVERSE_METHOD, IDENTIFY_KEYS
from fracid.settings.checks import SettingError, SettingsContext
from fracid.inverse.methods import registry


def _check_plausible(ck: Checker, key: str, pair, name: str, bounds, units: dict) -> None:
    """Refuse a bound of ``name`` far outside its usual range (:func:`fracid.models.implausible`): the
    message names the parameter, the bound and the usual range, before any data are read (a kappa_i
    1000 times too large would otherwise make the data look 1000 times too short)."""
    from fracid.models import implausible, implausible_text

    for which, value in zip(("lower", "upper"), bounds):
        reason = implausible(name, value, units)
        if reason is not None:
            ck.fail(key, pair, f"the {which} bound is {implausible_text(reason)}")


def read_identify(ck: Checker, raw, n_y: int | None, needed: bool, model: ModelConfig) -> IdentifyConfig | None:
    """The validated ``[identify]`` (``raw``, None when absent: an error if ``needed``); ``n_y``, the data
    values calibrated on, bounds the settings that count them (e.g. groups of observations)."""
    if raw is None:
        if needed:
            ck.missing("identify", "an [identify] section with parameters and [identify.bounds]")
        return None
    ck.table("identify", raw, (*IDENTIFY_KEYS, *(t for t in registry.known_tables() if t not in IDENTIFY_KEYS)))
    cls = model_of(model.type, model.law).parameters
    names = _identified(ck, raw, cls, model)
    inverse = ck.choice("identify.method", raw.get("method", DEFAULT_INVERSE_METHOD), tuple(registry.METHODS))
    lower, upper, log = _bounds(ck, raw, cls, names)
    tables = {name: value for name, value in raw.items() if name not in IDENTIFY_KEYS}
    identify = IdentifyConfig(parameters=names, lower=lower, upper=upper, log=log, method=inverse, tables=tables,
                              **_error_terms(ck, raw))
    context = SettingsContext(n_y=n_y, parameters=names)
    _checked(ck, raw, inverse, tables, context, inverse)
    read = registry.config_tables(registry.METHODS[inverse])
    for table in (table for table in tables if table not in read):
        reader = registry.table_readers(table)[0]
        _checked(ck, raw, reader, {table: tables[table]}, context, table)
        _warn_unread(ck, table, inverse)
    return identify


def _error_terms(ck: Checker, raw) -> dict:
    """``discretisation_error`` and ``model_error`` of ``[identify]``, each a word or a table
    (:mod:`fracid.inverse.likelihood.settings`), as the :class:`IdentifyConfig` fields (None: off)."""
    from fracid.inverse.likelihood import settings

    out = {}
    for key, read in ((settings.DISCRETISATION_KEY, settings.discretisation_from_config),
                      (settings.MODEL_ERROR_KEY, settings.model_error_from_config)):
        try:
            out[key] = read(raw.get(key))
        except SettingError as err:
            ck.fail(f"identify.{err.key}", err.value, err.allowed)
    return out


def check_refinable(ck: Checker, specimen: SpecimenConfig, experiments, identify: IdentifyConfig | None) -> None:
    """With ``discretisation_error``: every calibration specimen (``[specimen]`` with an experiment's overrides)
    must have a refined mesh (:func:`fracid.specimens.protocol.refined`) within the size limits (and a coarser one
    when the order is observed); the error names the key and why not."""
    settings = None if identify is None else identify.discretisation_error
    if settings is None:
        return
    from fracid.specimens.protocol import refined

    key, cls = "identify.discretisation_error", specimen_class(specimen.type)
    variants = [{}] + [dict(e.specimen) for e in experiments if e.role == "calibration" and e.specimen]
    factors = (settings.refinement, 1.0 / settings.refinement) if settings.observed_order else (settings.refinement,)
    for options in variants:
        for factor in factors:
            try:
                size = refined(cls(**{**dict(specimen.options), **options}), factor).size_estimate()
            except ValueError as err:
                ck.fail(key, settings.kind, f"needs a mesh of the specimen {factor:g} times finer, but {err}")
            if size.too_large:
                ck.fail(key, settings.kind, f"the mesh {factor:g} times finer would hold {size.summary}, beyond "
                                            f"the limit of {size.limit:,} {size.unit}s; {size.advice}")


def _checked(ck: Checker, raw, name: str, tables: dict, context: SettingsContext, key: str) -> None:
    """Build the registered method ``name`` from ``tables`` (:func:`~fracid.inverse.methods.registry.
    method_from_tables`): a refused setting is this file's error, named ``identify.<key>`` (a
    :class:`~fracid.settings.checks.SettingError`'s own key, else ``identify.<key>`` with the table)."""
    try:
        registry.method_from_tables(registry.METHODS[name], tables, context)
    except SettingError as err:
        ck.fail(f"identify.{err.key}", err.value, err.allowed)
    except (TypeError, ValueError) as err:
        ck.fail(f"identify.{key}", raw.get(key, key), str(err))


def _warn_unread(ck: Checker, table: str, inverse: str) -> None:
    """Warn that ``[identify.<table>]`` is given but the chosen method ``inverse`` does not read it, naming
    the registered method(s) that do."""
    readers = " or ".join(f'"{name}"' for name in registry.table_readers(table))
    ck.warn(f"[identify.{table}] is given but identify.method = {inverse!r}: its settings are not used "
            f"(set method = {readers} to use them)")


def _identified(ck: Checker, raw, cls, model: ModelConfig) -> tuple:
    """``identify.parameters``: a non-empty list of distinct parameters of the model's class."""
    names_all = cls.names()
    if "parameters" not in raw:
        ck.missing("identify.parameters", "a list of model parameters among " + ", ".join(names_all))
    value = raw["parameters"]
    if not isinstance(value, list) or not value or not all(isinstance(v, str) for v in value):
        ck.fail("identify.parameters", value, "must be a non-empty list of model parameters among " + ", ".join(names_all))
    for name in value:
        if name not in names_all:
            ck.fail("identify.parameters", value, f"{name!r} is not a model parameter of model.type = {model.type!r} "
                                                  f"({cls.__name__}); allowed: {', '.join(names_all)}")
    duplicates = sorted({v for v in value if value.count(v) > 1})
    if duplicates:
        ck.fail("identify.parameters", value, f"duplicate parameter {', '.join(map(repr, duplicates))}; list each once")
    return tuple(value)


def _bounds(ck: Checker, raw, cls, names: tuple) -> tuple[tuple, tuple, tuple]:
    """``[identify.bounds]``: (lower, upper, log) of the identified parameters."""
    if "bounds" not in raw:
        ck.missing("identify.bounds", "a table with [lower, upper] for " + ", ".join(names))
    bounds = ck.table("identify.bounds", raw["bounds"], (*names, *BOUNDS_KEYS))
    lower, upper = [], []
    for name in names:
        lo, hi = _bound_pair(ck, bounds, cls, name)
        lower.append(lo)
        upper.append(hi)
    log = ()
    if "log" in bounds:
        log = ck.strings("identify.bounds.log", bounds["log"], "identified parameters")
        for name in log:
            if name not in names:
                ck.fail("identify.bounds.log", bounds["log"],
                        f"{name!r} is not an identified parameter; allowed: {', '.join(names)}")
            lo = lower[names.index(name)]
            if not lo > 0:
                ck.fail("identify.bounds.log", bounds["log"],
                        f"log scale for {name!r} needs a lower bound > 0, but identify.bounds.{name} has lower = {lo:g}")
    return tuple(lower), tuple(upper), log


def _bound_pair(ck: Checker, bounds: dict, cls, name: str) -> tuple[float, float]:
    key = f"identify.bounds.{name}"
    unit = cls.units().get(name, "-")
    allowed = f"must be [lower, upper] with lower < upper, both in the valid range {range_text(cls, name)} [{unit}]"
    if name not in bounds:
        ck.missing(key, f"[lower, upper] bounds of the identified parameter {name} [{unit}]")
    pair = bounds[name]
    lo, hi = ck.pair(key, pair, allowed)
    if not lo < hi:
        ck.fail(key, pair, f"lower = {lo:g} must be below upper = {hi:g} ({allowed})")
    for which, v in (("lower", lo), ("upper", hi)):
        if not valid_parameter(cls, name, v):
            ck.fail(key, pair, f"the {which} bound {v:g} is outside the valid range {range_text(cls, name)} [{unit}]")
    _check_plausible(ck, key, pair, name, (lo, hi), cls.units())
    return lo, hi


def method_from_config(identify: IdentifyConfig, n_y: int | None):
    """The inverse method of a validated ``[identify]``: the class ``identify.method`` names in
    :data:`~fracid.inverse.methods.registry.METHODS`, built from the tables ``identify.tables`` it reads
    (:func:`~fracid.inverse.methods.registry.method_from_tables`); ``n_y`` is the data's size.

    Raises
    ------
    ValueError, TypeError
        The method's refusal of its settings (a :class:`~fracid.settings.checks.SettingError` names the
        setting and what is allowed).
    """
    context = SettingsContext(n_y=n_y, parameters=identify.parameters)
    return registry.method_from_tables(registry.METHODS[identify.method], identify.tables, context)
