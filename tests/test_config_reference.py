"""The configuration reference (:mod:`fracid.config.reference`, issue 40): every key the checker accepts has an
entry, and every entry a key the checker accepts, with a meaning.

The keys the checker accepts are read from the checker itself, not from the declarations the reference reads:
for every table (each specimen, model and law, experiment kind, method table, error term and section, listed
from the registries), a configuration with an unknown key is loaded and the allowed keys are read from the
message. A curve kind's table allows the other curve kinds' data columns, which it then refuses: each such key
is given to a block with a real data file, and the refusal asserted.
"""

import dataclasses
import re
from typing import ClassVar

import pytest

from fracid.config import ConfigError, load_config
from fracid.config.reference import entries, tables
from fracid.config.vocabulary import PARAMETER_KEY
from fracid.settings.checks import toml_value

UNKNOWN = "zz_unknown_key"
#: a configuration that loads (a forward analysis of a bar); each probe adds a table to it
BASE = {"model": {"type": "gradient-damage"}, "specimen": {"type": "bar", "n_elements": 40}}
IDENTIFY = {"parameters": ["c"], "bounds": {"c": [1.0, 3.0]}}


def toml(config: dict) -> str:
    """``config`` as TOML: scalars and lists first, then sub-tables, then arrays of tables."""
    lines = []

    def table(prefix: str, value: dict):
        lines.extend(f"{k} = {toml_value(v)}" for k, v in value.items() if not isinstance(v, (dict, list)) or
                     (isinstance(v, list) and not (v and isinstance(v[0], dict))))
        for k, v in value.items():
            if isinstance(v, dict):
                lines.append(f"[{prefix}{k}]")
                table(f"{prefix}{k}.", v)
            elif isinstance(v, list) and v and isinstance(v[0], dict):
                for item in v:
                    lines.append(f"[[{prefix}{k}]]")
                    table(f"{prefix}{k}.", item)

    table("", config)
    return "\n".join(lines) + "\n"


def refusal(tmp_path, config: dict, purpose="simulate") -> str:
    """The ConfigError message of loading ``config`` (the test fails if it loads)."""
    path = tmp_path / "probe.toml"
    path.write_text(toml(config), encoding="utf-8")
    with pytest.raises(ConfigError) as err:
        load_config(path, purpose=purpose)
    return str(err.value)


def allowed_keys(message: str) -> set:
    """The keys a refusal of an unknown key lists (``allowed keys here: a, b, c``)."""
    found = re.search(r"allowed keys here: (.*)$", message)
    assert found, message
    return {key.strip() for key in found.group(1).split(",")}


def _with(section: str, table: dict, **more) -> dict:
    return {**BASE, **more, section: table}


def probes() -> dict:
    """Reference table -> the configuration whose loading names the keys the checker accepts there: every table
    listed from the registries (specimens, models and laws, experiment kinds, methods' tables) and the sections."""
    from fracid.inverse.experiments.registry import EXPERIMENTS
    from fracid.inverse.likelihood import settings as likelihood
    from fracid.inverse.methods.registry import known_tables
    from fracid.models import MODEL_TYPES, model_from_type, model_laws
    from fracid.specimens import SPECIMENS

    out = {"top level": {**BASE, UNKNOWN: 1}, "model": {**BASE, "model": {"type": "gradient-damage", UNKNOWN: 1}}}
    for kind in MODEL_TYPES:
        out[f"model.parameters ({kind})"] = {**BASE, "model": {"type": kind, "parameters": {UNKNOWN: 1.0}}}
        for law in model_laws(model_from_type(kind)):  # a law with the model's parameter class: that table
            same = model_from_type(kind, law).parameters is model_from_type(kind).parameters
            table = f"model.parameters ({kind})" if same else f'model.parameters ({kind}, law = "{law}")'
            out[table + (" " + law if same else "")] = {**BASE, "model": {"type": kind, "law": law,
                                                                         "parameters": {UNKNOWN: 1.0}}}
    for kind in SPECIMENS:
        out[f"specimen ({kind})"] = {**BASE, "specimen": {"type": kind, UNKNOWN: 1}}
    for name in EXPERIMENTS:
        out[f"[[experiments]] (kind {name})"] = {**BASE, "experiments": [{"kind": name, UNKNOWN: 1}]}
    out["identify"] = _with("identify", {**IDENTIFY, UNKNOWN: 1})
    out["identify.bounds"] = _with("identify", {**IDENTIFY, "bounds": {"c": [1.0, 3.0], UNKNOWN: 1}})
    for table in (*known_tables(), likelihood.DISCRETISATION_KEY, likelihood.MODEL_ERROR_KEY):
        out[f"identify.{table}"] = _with("identify", {**IDENTIFY, table: {UNKNOWN: 1}})
    for section in ("study", "posterior", "simulate", "output"):
        out[section] = _with(section, {UNKNOWN: 1})
    return out


def _covered(table: str, key: str, reference: dict) -> bool:
    """Whether the accepted ``key`` of ``table`` is in the reference: a key of that table, a table of its own
    (``[identify] knn`` is ``identify.knn``), or an identified parameter's bounds (``<parameter>``)."""
    keys = reference.get(table, {})
    return key in keys or f"{table}.{key}" in reference or (table == "identify.bounds" and PARAMETER_KEY in keys)


def _refused_columns(tmp_path, kind: str, keys: set) -> set:
    """Of ``keys``, those a block of the curve kind ``kind`` with a real data file refuses as another kind's data
    column ("not used by kind")."""
    data = tmp_path / "curve.csv"
    data.write_text("u,F\n0.1,1\n0.2,2\n0.3,1\n", encoding="utf-8")
    refused = set()
    for key in keys:
        block = {"file": data.name, "control_column": "u", "control_unit": "mm", "force_unit": "N", "kind": kind,
                 key: ["F"] if key == "force_columns" else ("F" if key.endswith("_column") else 1.0)}
        if "not used by kind" in refusal(tmp_path, {**BASE, "experiments": [block]}):
            refused.add(key)
    return refused


def missing(tmp_path) -> dict:
    """{reference table: (keys the checker accepts there without an entry, entries the checker does not accept)}
    for every table whose two sets differ."""
    from fracid.inverse.experiments.registry import EXPERIMENTS

    reference = tables()
    differ = {}
    for probe, config in probes().items():
        table = probe if probe in reference else probe.rsplit(" ", 1)[0]  # a law probed under its model's table
        accepted = allowed_keys(refusal(tmp_path, config)) - {UNKNOWN}
        if table.startswith("[[experiments]]"):
            kind = EXPERIMENTS[table.split("kind ")[1].rstrip(")")]
            extra = {key for key in accepted if key not in reference.get(table, {})}
            accepted -= _refused_columns(tmp_path, kind.name, extra) if kind.column_keys else set()
        if table == "identify.bounds":
            accepted = {PARAMETER_KEY if key in IDENTIFY["parameters"] else key for key in accepted}
        unlisted = {key for key in accepted if not _covered(table, key, reference)}
        keys = set(reference.get(table, {}))
        unaccepted = keys - accepted
        if unlisted or unaccepted:
            differ[table] = (unlisted, unaccepted)
    return differ


# ------------------------------------------------------------------------------------------------ the tests


def test_every_key_the_checker_accepts_has_an_entry_and_no_entry_more(tmp_path):
    assert missing(tmp_path) == {}


def test_every_table_of_the_reference_is_probed():
    reference = tables()
    probed = {probe if probe in reference else probe.rsplit(" ", 1)[0] for probe in probes()}
    assert probed == set(reference)


class _NewMethod:
    """A method registered later whose table's key has no description."""

    name = "new-method"
    config_tables: ClassVar[tuple] = ("new-table",)

    @classmethod
    def from_config(cls, tables, context):
        from fracid.settings import checks

        checks.table("new-table", tables["new-table"], ("alpha",))
        return cls()


def test_a_key_added_to_the_checker_without_an_entry_is_reported(tmp_path, monkeypatch):
    """The helper can fail: a key the checker accepts and the reference does not describe is named, for a section
    of the vocabulary and for a method registered later."""
    from fracid.config import sections
    from fracid.inverse.methods import registry

    monkeypatch.setattr(sections, "STUDY_KEYS", (*sections.STUDY_KEYS, "new_key"))
    monkeypatch.setitem(registry.METHODS, _NewMethod.name, _NewMethod)
    differ = missing(tmp_path)
    assert differ["study"] == ({"new_key"}, set())
    assert differ["identify.new-table"] == ({"alpha"}, set())
    assert set(differ) == {"study", "identify.new-table"}


def test_a_registered_kind_appears_without_editing_the_reference(monkeypatch):
    from fracid.inverse.experiments.registry import EXPERIMENTS
    from fracid.specimens import SPECIMENS

    envelope = next(kind for kind in EXPERIMENTS.values() if "mean_column" in kind.column_keys)
    monkeypatch.setitem(EXPERIMENTS, "envelope-2", dataclasses.replace(envelope, name="envelope-2"))
    bar = next(cls for cls in SPECIMENS.values() if "weak_zone_width" in {f.name for f in dataclasses.fields(cls)})
    monkeypatch.setitem(SPECIMENS, "bar-2", bar)
    found = {(e.table, e.key): e for e in entries()}
    assert found[("[[experiments]] (kind envelope-2)", "kind")].allowed == '"envelope-2"'
    assert ("[[experiments]] (kind envelope-2)", "mean_column") in found
    assert found[("specimen (bar-2)", "weak_zone_width")].unit == "mm"


def undescribed(found) -> list:
    """(table, key) of the entries without a meaning or a default."""
    return [(e.table, e.key) for e in found if not (e.meaning.strip() and e.default.strip())]


def test_every_entry_has_a_meaning_a_default_and_is_immutable():
    found = entries()
    assert isinstance(found, tuple) and len(found) > 200
    assert undescribed(found) == []
    with pytest.raises(dataclasses.FrozenInstanceError):
        found[0].meaning = "changed"
    assert len({(e.table, e.key) for e in found}) == len(found)


@dataclasses.dataclass(frozen=True)
class _BareKind:
    """An experiment kind registered later that declares its keys but describes none."""

    name: str = "bare"
    keys: tuple = ("kind", "file", "gain")
    column_keys: tuple = ()
    source: str | None = None
    view: str | None = None


def test_a_kind_without_descriptions_is_reported(monkeypatch):
    from fracid.inverse.experiments.registry import EXPERIMENTS

    monkeypatch.setitem(EXPERIMENTS, "bare", _BareKind())
    assert undescribed(entries()) == [("[[experiments]] (kind bare)", key) for key in ("kind", "file", "gain")]


def test_entries_read_the_classes_defaults_units_and_ranges():
    from fracid.inverse.methods.knn_settings import DEFAULT_SCREENING
    from fracid.inverse.sampling.posterior import PosteriorSettings
    from fracid.models import MODEL_TYPES

    found = {(e.table, e.key): e for e in entries()}
    posterior = found[("posterior", "samples_per_round")]
    assert posterior.default == str(PosteriorSettings().samples_per_round) and "Forward runs per round" in posterior.meaning
    assert found[("identify.knn", "screening")].default == repr(DEFAULT_SCREENING)  # the table's, not the class's 1.0
    assert found[("identify", "method")].allowed.count("|") >= 1
    kind = next(iter(MODEL_TYPES))
    cls = MODEL_TYPES[kind]().parameters
    name, rng = next(iter(cls.ranges.items()))
    entry = found[(f"model.parameters ({kind})", name)]
    assert entry.unit == rng.unit and entry.allowed == rng.describe(name)
    assert found[("specimen (bar)", "type")].default == "required" and found[("specimen (bar)", "type")].allowed == '"bar"'


def test_init_comments_carry_the_meanings():
    """``fracid init``'s data block and tail read the same descriptions as the reference."""
    from fracid.cli.init import DEMO_PAIR, config_text
    from fracid.inverse.experiments.registry import EXPERIMENTS
    from fracid.settings.docstrings import plain

    text = config_text(*DEMO_PAIR)
    block = re.search(r"^# kind = \"([^\"]+)\"", text, re.M).group(1)
    found = {(e.table, e.key): e for e in entries()}
    keys = re.findall(r"^# ([a-z_]+) = .*# (.*)$", text[text.index("[[experiments]]"):text.index("[identify]")], re.M)
    assert len(keys) >= 8
    for key, comment in keys:
        meaning = plain(found[(f"[[experiments]] (kind {block})", key)].meaning)
        assert meaning in comment, key
    assert EXPERIMENTS[block].key_docs["n_points"].allowed in text
    for table, key in (("simulate", "stop_force_fraction"), ("output", "directory")):
        assert plain(found[(table, key)].meaning) in text
