"""The configuration reference: every key a configuration accepts, with its default, unit, allowed values and
meaning (:func:`entries`), built by reading what the checker reads, when asked.

- the sections without a settings class of a kind: :mod:`fracid.config.vocabulary` (``TOP``, ``MODEL``,
  ``SPECIMEN``, ``IDENTIFY``, ``BOUNDS``, ``STUDY``, ``POSTERIOR``, ``SIMULATE``, ``OUTPUT``);
- ``[model.parameters]``: every model of :data:`fracid.models.MODEL_TYPES` and each of its laws
  (:func:`fracid.models.model_laws`) with another parameter class, from that class (its ``ranges`` and units,
  its numpydoc ``Parameters``);
- ``[specimen]``: every specimen of :data:`fracid.specimens.SPECIMENS`, from its dataclass fields and numpydoc,
  or the keys of its own section (its ``config_section.keys``);
- ``[[experiments]]``: every kind of :data:`fracid.inverse.experiments.registry.EXPERIMENTS` (its ``keys`` and
  ``key_docs``);
- ``[identify.<table>]``: every table a registered method reads
  (:func:`fracid.inverse.methods.registry.known_tables`, described by :func:`~fracid.inverse.methods.registry.
  table_keys`), and the error terms' tables (:mod:`fracid.inverse.likelihood.settings`).

A kind, specimen, model or method registered later appears here without a change. The site renders it
(``docs/_ext/fracid_config_reference.py``); ``tests/test_config_reference.py`` checks that every key the checker
accepts has an entry with a meaning.
"""

from __future__ import annotations

import dataclasses
import re
from dataclasses import dataclass

from fracid.config import vocabulary
from fracid.settings.docstrings import documented, plain
from fracid.settings.keys import REQUIRED, Key, Said, described

#: the name of the table of the file's top-level keys
TOP_TABLE = "top level"


@dataclass(frozen=True)
class Entry:
    """One key of the configuration reference.

    Parameters
    ----------
    table : str
        The table, as a heading: ``"posterior"``, ``"identify.knn"``, ``"specimen (notched-beam)"``,
        ``"model.parameters (gradient-damage)"``, ``"[[experiments]] (kind envelope)"``.
    key : str
        The key in that table.
    default : str
        Its default as written in TOML, or in words (``"required"``, ``"not set"``, ``"the specimen's"``).
    unit : str
        Its unit (empty: a word, a name, a path or a count).
    allowed : str
        The values allowed, in words.
    meaning : str
        What it sets (numpydoc text: ````literal```` and ``:role:`target``` marks kept).
    """

    table: str
    key: str
    default: str
    unit: str
    allowed: str
    meaning: str


def _entries(table: str, keys: dict) -> list:
    """The entries of ``keys`` (key -> :class:`~fracid.settings.keys.Key`) under ``table``."""
    return [Entry(table, name, key.default_text(), key.unit, key.allowed_text(), key.meaning)
            for name, key in keys.items()]


def _unit(text: str) -> str:
    """The unit a numpydoc description states in brackets (``"... [mm]."`` -> ``"mm"``), else empty."""
    found = re.findall(r"\[([^\[\]]{1,20})\]", text)
    return found[-1] if found else ""


def _field_default(field: dataclasses.Field):
    if field.default is not dataclasses.MISSING:
        return Said("derived from the others (see the meaning)") if field.default is None else field.default
    return REQUIRED


def specimen_keys(kind: str) -> dict:
    """The keys of ``[specimen]`` for the specimen ``kind``, described: ``type``, ``control`` (its controls), then
    its own section's keys, else its dataclass fields (their numpydoc entries and defaults)."""
    from fracid.config.registry import specimen_class

    cls = specimen_class(kind)
    instance = cls.default_instance()
    controls = tuple(instance.control_names) if instance is not None else ()
    common = dict(vocabulary.SPECIMEN)
    common["type"] = dataclasses.replace(common["type"], allowed=f'"{kind}"')
    if controls:
        common["control"] = dataclasses.replace(common["control"], default=controls[0],
                                                allowed=" | ".join(f'"{c}"' for c in controls))
    section = cls.config_section
    if section is not None:
        return {**common, **described(getattr(section, "keys", None) or {}, cls)}
    docs = documented(cls)
    own = {}
    for field in dataclasses.fields(cls):
        kind_text, meaning = docs.get(field.name, ("", ""))
        own[field.name] = Key(_field_default(field), _unit(meaning), kind_text, meaning)
    return {**common, **own}


def parameter_keys(cls) -> dict:
    """The keys of ``[model.parameters]`` for the parameter class ``cls``: every parameter with its default, unit,
    valid range (:func:`fracid.config.sections.range_text`) and numpydoc meaning."""
    from fracid.config.sections import range_text

    docs, units = documented(cls), cls.units()
    return {f.name: Key(f.default, units.get(f.name, "-"), range_text(cls, f.name), docs.get(f.name, ("", ""))[1])
            for f in dataclasses.fields(cls)}


def parameter_tables() -> dict:
    """Table heading -> parameter class, for every model type and each of its laws whose parameter class is not
    the model's default one."""
    from fracid.config.registry import model_of, model_types
    from fracid.models import model_laws

    tables = {}
    for kind in model_types():
        default = model_of(kind).parameters
        tables[f"model.parameters ({kind})"] = default
        for law in model_laws(model_of(kind)):
            cls = model_of(kind, law).parameters
            if cls is not default:
                tables[f'model.parameters ({kind}, law = "{law}")'] = cls
    return tables


def experiment_keys(kind) -> dict:
    """The keys of an ``[[experiments]]`` block of the kind object ``kind``, described: its ``keys`` less the data
    columns of the other kinds where it has data columns itself (a curve kind refuses the others'), its ``kind`` key
    allowing its own name."""
    from fracid.inverse.experiments.registry import column_keys

    others = {key for name, keys in column_keys().items() if name != kind.name for key in keys} if kind.column_keys else set()
    docs = getattr(kind, "key_docs", None) or {}
    out = {name: docs.get(name, Key()) for name in kind.keys if name not in others or name in kind.column_keys}
    if "kind" in out:
        out["kind"] = dataclasses.replace(out["kind"], allowed=f'"{kind.name}"')
    return out


def identify_tables() -> dict:
    """Table heading -> keys of ``[identify]``, ``[identify.bounds]``, every method's table and the error terms'."""
    from fracid.inverse.likelihood import settings as likelihood
    from fracid.inverse.methods import registry

    tables = {"identify": vocabulary.IDENTIFY, "identify.bounds": vocabulary.BOUNDS}
    tables.update({f"identify.{table}": registry.table_keys(table) or {} for table in registry.known_tables()})
    tables[f"identify.{likelihood.DISCRETISATION_KEY}"] = likelihood.DISCRETISATION_KEY_DOCS
    tables[f"identify.{likelihood.MODEL_ERROR_KEY}"] = likelihood.MODEL_ERROR_KEY_DOCS
    return tables


def tables() -> dict:
    """Table heading -> keys (key -> :class:`~fracid.settings.keys.Key`), in the order of a configuration file."""
    from fracid.config.registry import specimen_types
    from fracid.inverse.experiments.registry import EXPERIMENTS

    out = {TOP_TABLE: vocabulary.TOP, "model": vocabulary.MODEL}
    out.update({name: parameter_keys(cls) for name, cls in parameter_tables().items()})
    out.update({f"specimen ({kind})": specimen_keys(kind) for kind in specimen_types()})
    out.update({f"[[experiments]] (kind {name})": experiment_keys(kind) for name, kind in EXPERIMENTS.items()})
    out.update(identify_tables())
    out.update({"study": vocabulary.STUDY, "posterior": vocabulary.POSTERIOR, "simulate": vocabulary.SIMULATE,
                "output": vocabulary.OUTPUT})
    return out


def entries() -> tuple:
    """Every key of the configuration as an :class:`Entry`, table by table (:func:`tables`), read from the
    registries and classes the checker reads at the time of the call."""
    return tuple(entry for table, keys in tables().items() for entry in _entries(table, keys))


def comment(key: Key) -> str:
    """The comment of a key in a written configuration (``fracid init``): its allowed values, unit and meaning,
    in plain text."""
    allowed = key.allowed_text() + (f" [{key.unit}]" if key.unit else "")
    return f"{allowed} - {plain(key.meaning)}" if allowed else plain(key.meaning)


__all__ = ["Entry", "TOP_TABLE", "comment", "entries", "experiment_keys", "identify_tables", "parameter_keys",
           "parameter_tables", "specimen_keys", "tables"]
