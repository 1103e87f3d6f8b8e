"""The curve kinds of ``[[experiments]]``: a force (or a local quantity) against the control, read from a CSV
file.

- ``kind = "repeats"``: repeated tests, one column each (``force_columns``, at least 2): their mean and
  scatter (:func:`fracid.data.experimental.from_repeats`);
- ``kind = "envelope"``: a mean and its lower and upper envelopes (``mean_column``, ``lower_column``,
  ``upper_column``: :func:`~fracid.data.experimental.from_envelope`);
- ``kind = "single"``: one curve with a given ``std`` (absolute, in ``force_unit``) or ``relative_std``
  (:func:`~fracid.data.experimental.with_std`).

Their shared keys are read by :mod:`fracid.inverse.experiments.curve_table`; each kind reads its own columns
(``read_columns``) and std (``read_std``) and makes its data from the curves read (``from_curves``).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from fracid.data.covariance import STD_ALLOWED, usable_std
from fracid.inverse.experiments.curve_table import CURVE_KEY_DOCS, CURVE_KEYS, read_curve_fields, required
from fracid.inverse.core.observations import FORCE
from fracid.inverse.experiments.vocabulary import CONTROL_UNITS, FORCE_UNITS, LOCAL_UNITS
from fracid.settings.checks import SettingError


@dataclass(frozen=True)
class CurveExperimentConfig:
    """One ``[[experiments]]`` block of a curve kind (``index`` is its position, ``file`` an absolute path)."""

    index: int
    file: Path
    control_column: str
    control_unit: str
    force_unit: str
    kind: str
    n_points: int
    force_columns: tuple = ()
    mean_column: str | None = None
    lower_column: str | None = None
    upper_column: str | None = None
    std: float | None = None
    relative_std: float | None = None
    control_range: tuple | None = None  # in control_unit, as given
    quantity: str = FORCE
    name: str = "global"
    specimen: tuple = ()  # ((field, value), ...) overriding [specimen] for this test (e.g. its size)
    weight: float = 1.0
    damage_threshold: float = 0.0
    role: str = "calibration"
    delimiter: str = ","  # the cell separator itself ("tab" is stored as "\t"; " " is any whitespace)
    decimal: str = "."
    backtrack_tolerance: float | None = None  # in control_unit, as given; None: 1 % of the control range
    negate: tuple = ()  # of "control", "force": columns the machine records with a negative sign
    sampling: str = "equally-spaced"  # or "measured" (fracid.data.sampling.SAMPLINGS)

    def sign(self, column: str) -> float:
        """-1 if the ``column`` ("control" or "force") is to be negated, else 1."""
        return -1.0 if column in self.negate else 1.0

    @property
    def measures_force(self) -> bool:
        """Whether the block holds forces [N] (else a local quantity [mm])."""
        return self.quantity == FORCE

    @property
    def control_scale(self) -> float:
        """Multiplier from ``control_unit`` to mm."""
        return CONTROL_UNITS[self.control_unit]

    @property
    def force_scale(self) -> float:
        """Multiplier from ``force_unit`` to N (force) or to mm (local quantity)."""
        return (FORCE_UNITS if self.measures_force else LOCAL_UNITS)[self.force_unit]

    def given_units(self) -> tuple:
        """((control unit, its multiplier to mm), (value unit, its multiplier to N or mm)) as the block gives
        them (``control_unit``, ``force_unit``): what ``fracid check`` prints the block's values in."""
        return (self.control_unit, self.control_scale), (self.force_unit, self.force_scale)

    @property
    def control_range_mm(self) -> tuple | None:
        """``control_range`` in mm."""
        if self.control_range is None:
            return None
        return tuple(v * self.control_scale for v in self.control_range)

    @property
    def backtrack_tolerance_mm(self) -> float | None:
        """``backtrack_tolerance`` in mm (None: the reader's default, 1 % of the control range)."""
        return None if self.backtrack_tolerance is None else self.backtrack_tolerance * self.control_scale


@dataclass(frozen=True)
class CurveKind:
    """A curve kind: the shared reading, data and observation; a subclass gives its columns, std and data."""

    name: str
    column_keys: tuple
    keys: tuple = CURVE_KEYS
    source: str | None = None
    view: str | None = None  # drawn in the fit figure

    @property
    def key_docs(self) -> dict:
        """Key -> :class:`~fracid.settings.keys.Key` of the block's keys (those of the curve kinds' shared table)."""
        return CURVE_KEY_DOCS

    def read(self, ck, index: int, raw: dict, context) -> tuple:
        """(the validated :class:`CurveExperimentConfig`, None): see :mod:`fracid.inverse.experiments.registry`."""
        return CurveExperimentConfig(**read_curve_fields(ck, index, raw, context, self)), None

    def read_columns(self, ck, prefix: str, raw: dict) -> tuple[dict, dict]:
        """(the config fields of the kind's columns, and each dotted key -> (the value given, its column names))."""
        options = {name: ck.string(f"{prefix}.{name}", required(ck, prefix, raw, name), "must be a column name "
                                   "(string)") for name in self.column_keys}
        return options, {f"{prefix}.{name}": (options[name], [options[name]]) for name in self.column_keys}

    def read_std(self, ck, prefix: str, raw: dict, force_unit: str) -> dict:
        """The config fields of the kind's std (none: the data's scatter gives it)."""
        return {}

    def columns(self, exp: CurveExperimentConfig) -> list:
        """The data columns read, in the order of :meth:`from_curves`'s curves."""
        return [getattr(exp, name) for name in self.column_keys]

    def from_curves(self, curves: list, exp: CurveExperimentConfig, span, sampling: dict):
        """The block's ExperimentalData from its curves (control in mm, values in N or mm)."""
        raise NotImplementedError

    def curves(self, exp: CurveExperimentConfig) -> list:
        """The block's curves as read from its file, scaled to mm and N (checked positive for a force)."""
        from fracid.data.checks import require_positive_force
        from fracid.data.curves import read_curve_csv

        curves = read_curve_csv(exp.file, control_column=exp.control_column, force_columns=self.columns(exp),
                                control_unit_scale=exp.control_scale * exp.sign("control"),
                                force_unit_scale=exp.force_scale * exp.sign("force"),
                                delimiter=exp.delimiter, decimal=exp.decimal,
                                backtrack_tolerance=exp.backtrack_tolerance_mm)
        if exp.measures_force:
            require_positive_force(curves)
        return curves

    def data(self, exp: CurveExperimentConfig, context):
        """The block's ExperimentalData: its curves read, their reach checked (``context.check_reach``), sampled
        at ``n_points`` over ``control_range``."""
        curves = self.curves(exp)
        context.check_reach(exp, max(float(np.max(curve.control)) for curve in curves))
        return self.from_curves(curves, exp, exp.control_range_mm, {"sampling": exp.sampling})

    def observation(self, exp: CurveExperimentConfig, context, name: str, control):
        """The :class:`~fracid.inverse.core.observations.Observation` of the block at ``control`` [mm]."""
        from fracid.inverse.core.observations import Observation

        try:
            return Observation(context.specimen, control, quantity=exp.quantity, control=context.control, name=name,
                               damage_threshold=exp.damage_threshold)
        except ValueError as err:
            raise SettingError("control_range", exp.control_range and list(exp.control_range), str(err)) from None


@dataclass(frozen=True)
class ForceColumns(CurveKind):
    """A kind whose columns are ``force_columns``: between ``least`` and ``most`` of them."""

    least: int = 1
    most: int | None = None
    count_text: str = ""

    def read_columns(self, ck, prefix: str, raw: dict) -> tuple[dict, dict]:
        key = f"{prefix}.force_columns"
        names = ck.strings(key, required(ck, prefix, raw, "force_columns"))
        if len(names) < self.least or (self.most is not None and len(names) > self.most):
            ck.fail(key, raw["force_columns"], self.count_text)
        return {"force_columns": names}, {key: (raw["force_columns"], names)}

    def columns(self, exp: CurveExperimentConfig) -> list:
        return list(exp.force_columns)


@dataclass(frozen=True)
class Repeats(ForceColumns):
    """``kind = "repeats"``: the mean and scatter of repeated tests."""

    def from_curves(self, curves, exp, span, sampling):
        from fracid.data.experimental import from_repeats

        return from_repeats(curves, exp.n_points, span, name=exp.name, **sampling)


@dataclass(frozen=True)
class Envelope(CurveKind):
    """``kind = "envelope"``: a mean curve and its envelopes."""

    def from_curves(self, curves, exp, span, sampling):
        from fracid.data.experimental import from_envelope

        return from_envelope(*curves, exp.n_points, span, name=exp.name, **sampling)


@dataclass(frozen=True)
class Single(ForceColumns):
    """``kind = "single"``: one curve with a given absolute or relative std."""

    def read_std(self, ck, prefix: str, raw: dict, force_unit: str) -> dict:
        """``{"std": ...}`` or ``{"relative_std": ...}`` (exactly one of them)."""
        given = [name for name in ("std", "relative_std") if name in raw]
        if len(given) != 1:
            key = f"{prefix}.{given[1] if given else 'std'}"
            text = (f"kind {self.name!r} needs exactly one of std (absolute, in force_unit, > 0) or relative_std "
                    "(fraction of |y|, > 0)")
            if not given:
                ck.missing(key, text)
            ck.fail(key, raw[given[1]], text)
        name = given[0]
        unit = f" [{force_unit}]" if name == "std" else " (fraction of |y|)"
        value = ck.number(f"{prefix}.{name}", raw[name], f"must be a number {STD_ALLOWED}{unit}", usable_std)
        if name == "relative_std" and value > 1:
            ck.warn(f"{prefix}.relative_std = {value:g} is more than 1, i.e. more than 100 % of the value; "
                    f"if you meant {value:g} %, write {value / 100:g}")
        return {name: value}

    def from_curves(self, curves, exp, span, sampling):
        from fracid.data.experimental import with_std

        if exp.std is not None:
            return with_std(curves[0], exp.std * exp.force_scale, exp.n_points, span, name=exp.name, **sampling)
        return with_std(curves[0], exp.relative_std, exp.n_points, span, name=exp.name, relative=True, **sampling)


REPEATS = Repeats("repeats", ("force_columns",), least=2,
                  count_text="kind 'repeats' needs at least 2 columns (one per repeated test)")
ENVELOPE = Envelope("envelope", ("mean_column", "lower_column", "upper_column"))
SINGLE = Single("single", ("force_columns", "std", "relative_std"), least=1, most=1,
                count_text="kind 'single' takes exactly 1 column")

__all__ = ["ENVELOPE", "REPEATS", "SINGLE", "CurveExperimentConfig", "CurveKind", "Envelope", "ForceColumns",
           "Repeats", "Single"]
