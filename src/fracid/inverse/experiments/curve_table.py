"""Reading and checking the table of a curve block (``[[experiments]] kind = "repeats" | "envelope" |
"single"``): keys, units, the data file's header and columns (read with the block's delimiter and decimal
mark). The number of data values is not capped: the covariance of the data is not held as an n x n matrix.

Every check goes through the checker passed in (:class:`~fracid.inverse.experiments.registry.TableChecker`),
whose messages name the key and the value; a kind's own columns and std are its ``read_columns`` and
``read_std`` (:mod:`fracid.inverse.experiments.curves`).
"""

from __future__ import annotations

from pathlib import Path

from fracid.data.sampling import SAMPLINGS
from fracid.inverse.core.observations import FORCE
from fracid.inverse.experiments.vocabulary import (BLOCK_KEYS, choices_text, CONTROL_UNITS, FORCE_UNITS, FORMAT_KEYS,
                                                   LOCAL_UNITS, ROLES, file_format)
from fracid.settings.checks import show
from fracid.settings.keys import REQUIRED, UNSET, Key, Said

#: the keys of a curve block's table, each described (the column keys of every curve kind among them: a block refuses
#: another kind's with a message naming its own; each kind lists its ``column_keys``)
CURVE_KEY_DOCS = {
    "file": Key(REQUIRED, "", "a CSV file path", "The data file: a CSV with a header row; relative to the "
                                                 "configuration file unless absolute."),
    "control_column": Key(REQUIRED, "", "a column name", "The column of the control quantity (CMOD, displacement ...)."),
    "control_unit": Key(REQUIRED, "", choices_text(CONTROL_UNITS), "The unit of the control column (scaled to mm)."),
    "force_unit": Key(REQUIRED, "", f"force: {choices_text(FORCE_UNITS)}; a local quantity: {choices_text(LOCAL_UNITS)}",
                      "The unit of the measured values (scaled to N, a local quantity to mm)."),
    "kind": Key(REQUIRED, "", "a registered kind", "The kind of the block: which columns hold the data and how "
                                                   "their scatter is known."),
    "force_columns": Key(REQUIRED, "", "a list of column names", "The force columns: one per repeated test (their "
                                                                  "mean and sample std), or the one curve."),
    "mean_column": Key(REQUIRED, "", "a column name", "The mean force of the repeats."),
    "lower_column": Key(REQUIRED, "", "a column name", "The lowest force of the repeats (std = (upper - lower) / 4)."),
    "upper_column": Key(REQUIRED, "", "a column name", "The highest force of the repeats."),
    "std": Key(UNSET, "force_unit", "> 0; this or relative_std", "The standard deviation of every value."),
    "relative_std": Key(UNSET, "-", "> 0; this or std", "The standard deviation as a fraction of |y|."),
    "n_points": Key(REQUIRED, "", "integer >= 3", "The number of data values taken from the curve."),
    "control_range": Key(Said("the range common to the columns"), "control_unit", "[start, stop], 0 < start < stop",
                         "The part of the curve used."),
    "quantity": Key(FORCE, "", f'"{FORCE}" or a local observable of the specimen (e.g. "fpz_width")',
                    "What the values measure: the force, or a local quantity of the specimen [mm]."),
    "name": Key(Said('"global" (a force) or the quantity'), "", "a non-empty string", "The block's name in the results."),
    "specimen": Key(UNSET, "", "a table of the specimen's fields",
                    "Fields of [specimen] overridden for this test (a size series: one block per size); blocks "
                    "of the same specimen share one forward run."),
    "weight": BLOCK_KEYS["weight"],
    "damage_threshold": Key(0.0, "-", "0 <= t < 1; a local quantity only", "The damage counted in the width."),
    "role": BLOCK_KEYS["role"],
    **FORMAT_KEYS,
    "backtrack_tolerance": Key(Said("1 % of the control's range"), "control_unit", ">= 0",
                               "The largest backtrack of the control column dropped as noise."),
    "negate": Key([], "", 'a list of "control" and/or "force"', "The columns the machine records with a negative "
                                                                "sign, multiplied by -1."),
    "sampling": Key(SAMPLINGS[0], "", choices_text(SAMPLINGS),
                    '"equally-spaced": n_points equally spaced control values, the one nearest the measured peak '
                    'moved onto it; "measured": the measured points themselves, all if at most n_points, else '
                    "n_points of them by arc length along the normalised curve (ends and peak kept)."),
}
CURVE_KEYS = tuple(CURVE_KEY_DOCS)


def _csv_table(ck, key: str, value, path: Path, delimiter: str, decimal: str, columns):
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
        ck.fail(key, value, f"the header is one cell {show(header[0])} when split by delimiter = {given}: the file seems "
                            f"to be separated by {guess!r}; set delimiter = {_toml_text(guess)} (and decimal = \",\" "
                            "for decimal commas)")
    first = table.rows[0][1] if table.rows else None
    hint = first is not None and decimal_comma_hint(first, delimiter, decimal, len(header))
    if hint:
        row = ", ".join(show(cell.strip()) for cell in first)
        ck.fail(key, value, f"the first data row ({row}) cannot be read with delimiter = {_toml_text(delimiter)} and "
                            f"decimal = {_toml_text(decimal)}: {hint}")
    return table


def _toml_text(text: str) -> str:
    """A string as written in TOML: ``";"``, ``"\\t"``."""
    return '"' + text.replace("\\", "\\\\").replace('"', '\\"').replace("\t", "\\t") + '"'


def read_curve_fields(ck, i: int, raw, context, kind) -> dict:
    """The fields of the validated curve block ``i`` of the curve kind ``kind``
    (:class:`~fracid.inverse.experiments.curves.CurveKind`; ``context``: a
    :class:`~fracid.inverse.experiments.registry.ReadContext`); its keys are checked in a fixed order (the
    first problem is the one reported): units and kind, then the file's format and columns, then the rest."""
    prefix = f"experiments[{i}]"
    ck.table(prefix, raw, CURVE_KEYS)
    quantity = ck.choice(f"{prefix}.quantity", raw.get("quantity", FORCE), (FORCE, *context.observables()))
    file = ck.file(f"{prefix}.file", required(ck, prefix, raw, "file", context), context.base)
    control_column = ck.string(f"{prefix}.control_column", required(ck, prefix, raw, "control_column", context),
                               "must be a column name")
    control_unit = ck.choice(f"{prefix}.control_unit", required(ck, prefix, raw, "control_unit", context),
                             tuple(CONTROL_UNITS))
    force_unit = _force_unit(ck, prefix, raw, quantity)
    _kind(ck, prefix, raw, context)
    n_points = ck.integer(f"{prefix}.n_points", required(ck, prefix, raw, "n_points", context),
                          "must be an integer >= 3", lambda v: v >= 3)
    sampling = ck.choice(f"{prefix}.sampling", raw.get("sampling", SAMPLINGS[0]), SAMPLINGS)
    delimiter, decimal = file_format(ck, prefix, raw)
    backtrack = _backtrack_tolerance(ck, prefix, raw, control_unit)
    options, columns = kind.read_columns(ck, prefix, raw)
    _check_columns(ck, prefix, raw, file, delimiter, decimal,
                   {f"{prefix}.control_column": (control_column, [control_column]), **columns})
    options.update(kind.read_std(ck, prefix, raw, force_unit))
    control_range = _control_range(ck, prefix, raw, control_unit)
    default_name = "global" if quantity == FORCE else quantity
    name = ck.string(f"{prefix}.name", raw.get("name", default_name), "must be a non-empty string")
    overrides = context.overrides(ck, prefix, raw)
    weight = ck.number(f"{prefix}.weight", raw.get("weight", 1.0), "must be a number > 0 (p in f = sum p_b f_b)",
                       lambda v: v > 0)
    threshold = _damage_threshold(ck, prefix, raw, quantity)
    role = ck.choice(f"{prefix}.role", raw.get("role", "calibration"), ROLES)
    negate = _negated(ck, f"{prefix}.negate", raw.get("negate", []))
    return dict(index=i, file=file, control_column=control_column, control_unit=control_unit, force_unit=force_unit,
                kind=kind.name, n_points=n_points, control_range=control_range, quantity=quantity, name=name,
                specimen=overrides, weight=weight, damage_threshold=threshold, role=role, delimiter=delimiter,
                decimal=decimal, backtrack_tolerance=backtrack, negate=negate, sampling=sampling, **options)


def required(ck, prefix: str, raw: dict, name: str, context=None):
    """The value of the required key ``name`` of the block (missing: the message says what it takes; the kinds
    ``context.kinds``)."""
    if name not in raw:
        kinds = context.kinds if context is not None else ()
        ck.missing(f"{prefix}.{name}", _REQUIRED_TEXT.get(name) or "one of " + ", ".join(map(repr, kinds)))
    return raw[name]


def _force_unit(ck, prefix: str, raw: dict, quantity: str) -> str:
    """``force_unit``: a force's unit (N, kN, MN), or a local quantity's (a length)."""
    units = FORCE_UNITS if quantity == FORCE else LOCAL_UNITS
    if "force_unit" not in raw:
        ck.missing(f"{prefix}.force_unit", f"the unit of {quantity!r}, one of " + ", ".join(map(repr, units)))
    return ck.choice(f"{prefix}.force_unit", raw["force_unit"], tuple(units))


def _kind(ck, prefix: str, raw: dict, context) -> str:
    """``kind``, one of ``context.kinds``, refusing the column keys of another kind (``context.column_keys``)."""
    kind = ck.choice(f"{prefix}.kind", required(ck, prefix, raw, "kind", context), context.kinds)
    own = context.column_keys.get(kind, ())
    for name in raw:
        if name in {k for ks in context.column_keys.values() for k in ks} and name not in own:
            ck.fail(f"{prefix}.{name}", raw[name], f"not used by kind {kind!r}, which takes " + ", ".join(own))
    return kind


def _backtrack_tolerance(ck, prefix: str, raw: dict, control_unit: str) -> float | None:
    """``backtrack_tolerance`` in ``control_unit``, None when not given (the reader's default)."""
    if "backtrack_tolerance" not in raw:
        return None
    return ck.number(f"{prefix}.backtrack_tolerance", raw["backtrack_tolerance"],
                     f"must be a number >= 0 [{control_unit}] (the largest backtrack of the control column "
                     "treated as noise)", lambda v: v >= 0)


def _check_columns(ck, prefix: str, raw: dict, file: Path, delimiter: str, decimal: str, columns: dict):
    """Every configured column (``columns``: key -> (value given, column names)) is in the file's header."""
    table = _csv_table(ck, f"{prefix}.file", raw["file"], file, delimiter, decimal,
                       [name for _, names in columns.values() for name in names])
    for key, (value, names) in columns.items():
        for name in names:
            if name not in table.header:
                said = value == name  # the key's value is this one name: said once, by ck.fail
                what = "not" if said else f"{show(name)} is not"
                ck.fail(key, value, f"{what} a column of {file}: {table.missing_column(name, named=False)}")


def _control_range(ck, prefix: str, raw: dict, control_unit: str) -> tuple | None:
    """``control_range`` (start, stop) in ``control_unit``, None when not given."""
    if "control_range" not in raw:
        return None
    value = raw["control_range"]
    allowed = f"must be [start, stop] with 0 < start < stop [{control_unit}]"
    a, b = ck.pair(f"{prefix}.control_range", value, allowed)
    if not 0 < a < b:
        ck.fail(f"{prefix}.control_range", value, allowed)
    return (a, b)


def _damage_threshold(ck, prefix: str, raw: dict, quantity: str) -> float:
    """``damage_threshold`` of a local quantity (0 when not given)."""
    if "damage_threshold" not in raw:
        return 0.0
    if quantity == FORCE:
        ck.fail(f"{prefix}.damage_threshold", raw["damage_threshold"],
                "applies to a local quantity only (this block's quantity is 'force')")
    return ck.number(f"{prefix}.damage_threshold", raw["damage_threshold"],
                     "must be a number with 0 <= t < 1 (damage counted in the width)", lambda v: 0 <= v < 1)


_REQUIRED_TEXT = {
    "file": "a CSV file path, relative to the config file",
    "control_column": "the name of the control column",
    "control_unit": "one of " + ", ".join(map(repr, CONTROL_UNITS)),
    "n_points": "an integer >= 3",
    "force_columns": "a list of force column names",
    "mean_column": "the name of the mean column (kind 'envelope')",
    "lower_column": "the name of the lower-envelope column (kind 'envelope')",
    "upper_column": "the name of the upper-envelope column (kind 'envelope')",
}


def _negated(ck, key: str, value) -> tuple:
    """``negate``: a list of "control" and/or "force" (the columns to multiply by -1)."""
    allowed = 'must be a list of "control" and/or "force": the columns recorded with a negative sign'
    if not isinstance(value, list) or any(v not in ("control", "force") for v in value):
        ck.fail(key, value, allowed)
    return tuple(dict.fromkeys(value))


__all__ = ["CURVE_KEYS", "CURVE_KEY_DOCS", "read_curve_fields", "required"]
