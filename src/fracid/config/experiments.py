"""Validation of the ``[[experiments]]`` blocks: keys, units, the data file's header and columns
(read with the block's delimiter and decimal mark). The number of data values is not capped: the
covariance of the data is not held as an n x n matrix."""

from __future__ import annotations

import dataclasses
from pathlib import Path

from fracid.config.checker import Checker
from fracid.config.derived_experiments import read_derived_experiment
from fracid.config.field_experiments import read_field_experiment
from fracid.config.registry import section_reader, specimen_class, specimen_observables
from fracid.config.schema import (
    ExperimentConfig,
    SpecimenConfig,
)
from fracid.config.sections import check_specimen, check_specimen_size, specimen_options
from fracid.config.vocabulary import (
    CONTROL_UNITS,
    DECIMALS,
    DELIMITERS,
    DERIVED_KINDS,
    EXPERIMENT_KEYS,
    FORCE_UNITS,
    KIND_KEYS,
    KINDS,
    LOCAL_UNITS,
    ROLES,
)
from fracid.data.sampling import SAMPLINGS


def _csv_table(ck: Checker, key: str, value, path: Path, delimiter: str, decimal: str, columns):
    """The header and rows of a data file as the reader finds them (:func:`fracid.data.table.read_table`,
    ``columns`` the configured column names); a header that is one cell holding another separator, or a
    first data row with decimal commas read with ``decimal = "."``, is named as such (instead of a missing
    column or a cell that is not a number)."""
    from fracid.data.cells import decimal_comma_hint
    from fracid.data.errors import DataError
    from fracid.data.table import delimiter_hint, read_table

    try:
        table = read_table(str(path), delimiter, decimal, columns)
    except DataError as err:
        ck.fail(key, value, str(err))
    header = table.header
    guess = delimiter_hint(header, delimiter)
    if guess is not None:
        given = _toml_text(delimiter) + (" (the default)" if delimiter == "," else "")
        ck.fail(key, value, f"the header is one cell {header[0]!r} when split by delimiter = {given}: the file seems "
                            f"to be separated by {guess!r}; set delimiter = {_toml_text(guess)} (and decimal = \",\" "
                            "for decimal commas)")
    first = table.rows[0][1] if table.rows else None
    hint = first is not None and decimal_comma_hint(first, delimiter, decimal, len(header))
    if hint:
        row = ", ".join(repr(cell.strip()) for cell in first)
        ck.fail(key, value, f"the first data row ({row}) cannot be read with delimiter = {_toml_text(delimiter)} and "
                            f"decimal = {_toml_text(decimal)}: {hint}")
    return table


def _toml_text(text: str) -> str:
    """A string as written in TOML: ``";"``, ``"\\t"``."""
    return '"' + text.replace("\\", "\\\\").replace('"', '\\"').replace("\t", "\\t") + '"'


def _experiment(ck: Checker, i: int, raw, base: Path, specimen: SpecimenConfig) -> ExperimentConfig:
    """The validated ``[[experiments]]`` block ``i``; its keys are checked in a fixed order (the first
    problem is the one reported): units and kind, then the file's format and columns, then the rest."""
    prefix = f"experiments[{i}]"
    ck.table(prefix, raw, EXPERIMENT_KEYS)
    observables = specimen_observables(specimen)
    quantity = ck.choice(f"{prefix}.quantity", raw.get("quantity", "force"), ("force", *observables))
    file = ck.file(f"{prefix}.file", _required(ck, prefix, raw, "file"), base)
    control_column = ck.string(f"{prefix}.control_column", _required(ck, prefix, raw, "control_column"),
                               "must be a column name")
    control_unit = ck.choice(f"{prefix}.control_unit", _required(ck, prefix, raw, "control_unit"),
                             tuple(CONTROL_UNITS))
    force_unit = _force_unit(ck, prefix, raw, quantity)
    kind = _kind(ck, prefix, raw)
    n_points = ck.integer(f"{prefix}.n_points", _required(ck, prefix, raw, "n_points"), "must be an integer >= 3",
                          lambda v: v >= 3)
    sampling = ck.choice(f"{prefix}.sampling", raw.get("sampling", SAMPLINGS[0]), SAMPLINGS)
    delimiter, decimal = _file_format(ck, prefix, raw)
    backtrack = _backtrack_tolerance(ck, prefix, raw, control_unit)
    options, columns = _data_columns(ck, prefix, raw, kind)
    _check_columns(ck, prefix, raw, file, delimiter, decimal,
                   {f"{prefix}.control_column": (control_column, [control_column]), **columns})
    if kind == "single":
        options.update(_single_std(ck, prefix, raw, force_unit))
    control_range = _control_range(ck, prefix, raw, control_unit)
    default_name = "global" if quantity == "force" else quantity
    name = ck.string(f"{prefix}.name", raw.get("name", default_name), "must be a non-empty string")
    overrides = _overrides(ck, prefix, raw, specimen)
    weight = ck.number(f"{prefix}.weight", raw.get("weight", 1.0), "must be a number > 0 (p in f = sum p_b f_b)",
                       lambda v: v > 0)
    threshold = _damage_threshold(ck, prefix, raw, quantity)
    role = ck.choice(f"{prefix}.role", raw.get("role", "calibration"), ROLES)
    negate = _negated(ck, f"{prefix}.negate", raw.get("negate", []))
    return ExperimentConfig(index=i, file=file, control_column=control_column, control_unit=control_unit,
                            force_unit=force_unit, kind=kind, n_points=n_points, control_range=control_range,
                            quantity=quantity, name=name, specimen=overrides, weight=weight,
                            damage_threshold=threshold, role=role, delimiter=delimiter, decimal=decimal,
                            backtrack_tolerance=backtrack, negate=negate, sampling=sampling, **options)


def _required(ck: Checker, prefix: str, raw: dict, name: str):
    """The value of the required key ``name`` of the block (missing: the message says what it takes)."""
    if name not in raw:
        ck.missing(f"{prefix}.{name}", _REQUIRED_TEXT[name])
    return raw[name]


def _force_unit(ck: Checker, prefix: str, raw: dict, quantity: str) -> str:
    """``force_unit``: a force's unit (N, kN, MN), or a local quantity's (a length)."""
    units = FORCE_UNITS if quantity == "force" else LOCAL_UNITS
    if "force_unit" not in raw:
        ck.missing(f"{prefix}.force_unit", f"the unit of {quantity!r}, one of " + ", ".join(map(repr, units)))
    return ck.choice(f"{prefix}.force_unit", raw["force_unit"], tuple(units))


def _kind(ck: Checker, prefix: str, raw: dict) -> str:
    """``kind``, refusing the column keys of another kind."""
    kind = ck.choice(f"{prefix}.kind", _required(ck, prefix, raw, "kind"), KINDS)
    for name in raw:
        if name in {k for ks in KIND_KEYS.values() for k in ks} and name not in KIND_KEYS[kind]:
            ck.fail(f"{prefix}.{name}", raw[name], f"not used by kind {kind!r}, which takes "
                    + ", ".join(KIND_KEYS[kind]))
    return kind


def _file_format(ck: Checker, prefix: str, raw: dict) -> tuple[str, str]:
    """(cell separator, decimal mark) of the data file: ``delimiter`` and ``decimal``."""
    delimiter = raw.get("delimiter", ",")
    if not isinstance(delimiter, str) or delimiter not in DELIMITERS:
        ck.fail(f"{prefix}.delimiter", delimiter, 'must be one of ",", ";", "\\t" (or "tab"), " " (any run of '
                                                 "spaces and tabs); the cell separator of the file")
    delimiter = DELIMITERS[delimiter]
    decimal = ck.choice(f"{prefix}.decimal", raw.get("decimal", "."), DECIMALS)
    if decimal == delimiter:
        ck.fail(f"{prefix}.decimal", decimal, 'a decimal comma needs another delimiter: with delimiter = "," (the '
                                              'default) a comma cannot also mark the decimals; files with decimal '
                                              'commas are separated by ";" or tabs: set delimiter = ";" or "tab"')
    return delimiter, decimal


def _backtrack_tolerance(ck: Checker, prefix: str, raw: dict, control_unit: str) -> float | None:
    """``backtrack_tolerance`` in ``control_unit``, None when not given (the reader's default)."""
    if "backtrack_tolerance" not in raw:
        return None
    return ck.number(f"{prefix}.backtrack_tolerance", raw["backtrack_tolerance"],
                     f"must be a number >= 0 [{control_unit}] (the largest backtrack of the control column "
                     "treated as noise)", lambda v: v >= 0)


def _data_columns(ck: Checker, prefix: str, raw: dict, kind: str) -> tuple[dict, dict]:
    """The column keys of ``kind``: (their ExperimentConfig fields, and for :func:`_check_columns` each dotted
    key -> (the value given, the column names it holds))."""
    if kind in ("repeats", "single"):
        key = f"{prefix}.force_columns"
        names = ck.strings(key, _required(ck, prefix, raw, "force_columns"))
        if kind == "repeats" and len(names) < 2:
            ck.fail(key, raw["force_columns"], "kind 'repeats' needs at least 2 columns (one per repeated test)")
        if kind == "single" and len(names) != 1:
            ck.fail(key, raw["force_columns"], "kind 'single' takes exactly 1 column")
        return {"force_columns": names}, {key: (raw["force_columns"], names)}
    options = {name: ck.string(f"{prefix}.{name}", _required(ck, prefix, raw, name), "must be a column name (string)")
               for name in KIND_KEYS["envelope"]}
    columns = {f"{prefix}.{name}": (options[name], [options[name]]) for name in KIND_KEYS["envelope"]}
    return options, columns


def _check_columns(ck: Checker, prefix: str, raw: dict, file: Path, delimiter: str, decimal: str, columns: dict):
    """Every configured column (``columns``: key -> (value given, column names)) is in the file's header."""
    table = _csv_table(ck, f"{prefix}.file", raw["file"], file, delimiter, decimal,
                       [name for _, names in columns.values() for name in names])
    for key, (value, names) in columns.items():
        for name in names:
            if name not in table.header:
                ck.fail(key, value, f"{name!r} is not a column of {file}: {table.missing_column(name)}")


def _single_std(ck: Checker, prefix: str, raw: dict, force_unit: str) -> dict:
    """``{"std": ...}`` or ``{"relative_std": ...}`` of kind 'single' (exactly one of them)."""
    given = [name for name in ("std", "relative_std") if name in raw]
    if len(given) != 1:
        key = f"{prefix}.{given[1] if given else 'std'}"
        text = "kind 'single' needs exactly one of std (absolute, in force_unit, > 0) or relative_std (fraction of |y|, > 0)"
        if not given:
            ck.missing(key, text)
        ck.fail(key, raw[given[1]], text)
    name = given[0]
    unit = f" [{force_unit}]" if name == "std" else " (fraction of |y|)"
    value = ck.number(f"{prefix}.{name}", raw[name], f"must be a number > 0{unit}", lambda v: v > 0)
    if name == "relative_std" and value > 1:
        ck.warn(f"{prefix}.relative_std = {value:g} is more than 1, i.e. more than 100 % of the value; "
                f"if you meant {value:g} %, write {value / 100:g}")
    return {name: value}


def _control_range(ck: Checker, prefix: str, raw: dict, control_unit: str) -> tuple | None:
    """``control_range`` (start, stop) in ``control_unit``, None when not given."""
    if "control_range" not in raw:
        return None
    value = raw["control_range"]
    allowed = f"must be [start, stop] with 0 < start < stop [{control_unit}]"
    a, b = ck.pair(f"{prefix}.control_range", value, allowed)
    if not 0 < a < b:
        ck.fail(f"{prefix}.control_range", value, allowed)
    return (a, b)


def _overrides(ck: Checker, prefix: str, raw: dict, specimen: SpecimenConfig) -> tuple:
    """The block's ``specimen`` overrides ((field, value), ...), checked with the rest of ``[specimen]``."""
    cls = specimen_class(specimen.type)
    if "specimen" in raw and section_reader(cls) is not None:
        ck.fail(f"{prefix}.specimen", raw["specimen"], f"a {specimen.type} specimen (read by its own [specimen] "
                "section) takes no per-experiment overrides yet; run the experiments of different specimens from "
                "configurations of their own")
    if "specimen" not in raw:
        return ()
    fields = [f.name for f in dataclasses.fields(cls)]
    given = specimen_options(ck, f"{prefix}.specimen", ck.table(f"{prefix}.specimen", raw["specimen"], fields), cls)
    check_specimen(ck, f"{prefix}.specimen", specimen.type, cls, {**dict(specimen.options), **given}, given)
    check_specimen_size(ck, f"{prefix}.specimen", specimen.type, cls, {**dict(specimen.options), **given}, given)
    return tuple(given.items())


def _damage_threshold(ck: Checker, prefix: str, raw: dict, quantity: str) -> float:
    """``damage_threshold`` of a local quantity (0 when not given)."""
    if "damage_threshold" not in raw:
        return 0.0
    if quantity == "force":
        ck.fail(f"{prefix}.damage_threshold", raw["damage_threshold"],
                "applies to a local quantity only (this block's quantity is 'force')")
    return ck.number(f"{prefix}.damage_threshold", raw["damage_threshold"],
                     "must be a number with 0 <= t < 1 (damage counted in the width)", lambda v: 0 <= v < 1)


_REQUIRED_TEXT = {
    "file": "a CSV file path, relative to the config file",
    "control_column": "the name of the control column",
    "control_unit": "one of " + ", ".join(map(repr, CONTROL_UNITS)),
    "kind": "one of " + ", ".join(map(repr, KINDS)),
    "n_points": "an integer >= 3",
    "force_columns": "a list of force column names",
    "mean_column": "the name of the mean column (kind 'envelope')",
    "lower_column": "the name of the lower-envelope column (kind 'envelope')",
    "upper_column": "the name of the upper-envelope column (kind 'envelope')",
}


def _negated(ck: Checker, key: str, value) -> tuple:
    """``negate``: a list of "control" and/or "force" (the columns to multiply by -1)."""
    allowed = 'must be a list of "control" and/or "force": the columns recorded with a negative sign'
    if not isinstance(value, list) or any(v not in ("control", "force") for v in value):
        ck.fail(key, value, allowed)
    return tuple(dict.fromkeys(value))


def read_experiments(ck: Checker, raw, base: Path, specimen: SpecimenConfig, needed: bool) -> tuple:
    """The validated ``[[experiments]]`` blocks in order: the field blocks read, the blocks derived from them
    (:mod:`~fracid.config.derived_experiments`) checked last, on the field blocks as read."""
    if raw is None:
        if needed:
            ck.missing("experiments", "one or more [[experiments]] blocks (data files) for identification")
        return ()
    if not isinstance(raw, list) or not raw:
        ck.fail("experiments", raw, "must be one or more [[experiments]] tables")
    read, fields = {}, {}  # index -> config; a field block's name -> [(config, FieldBlock), ...]
    for i, block in enumerate(raw):
        kind = block.get("kind") if isinstance(block, dict) else None
        if kind == "field":
            exp, field = read_field_experiment(ck, i, block, base, specimen)
            read[i] = exp
            fields.setdefault(exp.name, []).append((exp, field))
        elif kind not in DERIVED_KINDS:
            read[i] = _experiment(ck, i, block, base, specimen)
    for i, block in enumerate(raw):  # the derived blocks, once the field blocks they name are read
        if i not in read:
            read[i] = read_derived_experiment(ck, i, block, fields, specimen)
    return tuple(read[i] for i in range(len(raw)))
