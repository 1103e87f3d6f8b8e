"""TOML configuration of a study, validated when it is loaded.

:func:`load_config` reads a TOML file (stdlib ``tomllib``) and checks every key before anything
runs: unknown keys are rejected at every level, every value is type- and range-checked, data files
and their columns must exist, and the specimen and the model parameters are built once to run
their own validation. Every problem raises :class:`ConfigError` (a ``ValueError``) with a
one-paragraph message naming the file, the dotted key (``identify.bounds.c``,
``experiments[0].control_unit``), the value given and what is allowed. Relative file paths are
resolved against the directory of the configuration file.

The builders (:func:`build_parameters`, :func:`build_specimen`, :func:`build_data`,
:func:`build_operator`, :func:`build_space`, :func:`identify_settings`, :func:`simulate_settings`)
are pure functions of the validated :class:`Config`.

Units: N, mm, MPa; ``c`` in mm^2. Data files are scaled to mm and N by the units given.

Limits: a configuration beyond what a workstation holds is refused with the estimate and the limit
(:data:`MAX_POPULATION` KNN points, :data:`MAX_BAR_ELEMENTS` bar elements, :data:`MAX_UNKNOWNS`
unknowns of a 2D mesh counted from the geometry, :data:`MAX_DATA_VALUES` data values).

Warnings: valid settings that are probably not meant (``relative_std`` above 1, process-zone
elements larger than the internal length l = sqrt(2 c)) are returned in ``Config.warnings``.

Schema
------
The sections ``[[experiments]]`` and ``[identify]`` are required for identification
(``purpose="identify"``) and optional for a forward analysis (``purpose="simulate"``); when
present they are always validated. Every other key is optional unless marked *required*.

.. code-block:: toml

    [model]                             # optional; defaults: gradient damage, DamageParameters()
    type = "gradient-damage"            # any name of fracid.models.MODEL_TYPES, read when the file is
                                        #   validated: "gradient-damage" | "local-damage" (mesh-
                                        #   dependent) | "cohesive-crack" (Hordijk crack on the beam's
                                        #   ligament; parameters E nu ft Gf c1 c2) | models added later
    [model.parameters]                  # any subset of the model's parameters (its parameter class's
                                        # names(); checked by its own validation); the rest take the
                                        # class's defaults. Gradient and local damage (DamageParameters):
                                        # E 20000, nu 0.2, kappa_i 1e-4, alpha 0.99, beta 300, c 1, eta 10
    E = 37000.0                         # MPa, E > 0
    nu = 0.2                            # -, -1 < nu < 0.5
    kappa_i = 6.6e-5                    # -, kappa_i > 0
    alpha = 0.99                        # -, 0 <= alpha <= 1
    beta = 600.0                        # -, beta >= 0
    c = 9.0                             # mm^2, c > 0
    eta = 10.0                          # -, eta >= 1

    [specimen]                          # required
    type = "notched-beam"               # required: "notched-beam" | "dogbone" | "bar"
    control = "cmod"                    # the specimen's default if omitted:
                                        #   notched-beam: "cmod" (default) | "deflection"
                                        #   dogbone:      "elongation" (default) | "platen_displacement"
                                        #   bar:          "end_displacement" (default) | "weak_zone_elongation"
    # every other key is a field of the specimen class, type-checked (lengths in mm):
    #   notched-beam (NotchedBeam): depth thickness length span notch_depth notch_width plate_width
    #                               h_fine h_coarse fine_width
    #   dogbone (DogBone):          size thickness gauge_length h_fine fine_height h_coarse
    #                               notch_radius notch_width platens ("glued" | "hinged")
    #                               platen_height platen_stiffness hinge_offset
    #   bar (BarWithWeakZone):      length area (mm^2) weak_zone_width weak_zone_factor
    #                               weakening ("modulus" | "area") profile ("step" | "hat")
    #                               n_elements (integer)
    h_fine = 1.0

    [[experiments]]                     # one or more data blocks, stacked in this order into y_exp
    file = "load_cmod.csv"              # required: CSV with a header row, relative to this file
    control_column = "cmod_mm"          # required: column of the control quantity
    control_unit = "mm"                 # required: "mm" | "um" | "m" (scaled to mm)
    force_unit = "N"                    # required: quantity "force": "N" | "kN" | "MN" (scaled to N);
                                        #   a local quantity: its unit, "mm" | "um" | "m" (scaled to mm)
    kind = "envelope"                   # required: "repeats" | "envelope" | "single"
    #   repeats:  force_columns = ["F1", "F2", ...]   (>= 2 columns: mean and sample std of the repeats)
    #   envelope: mean_column, lower_column, upper_column   (std = (upper - lower) / 4)
    #   single:   force_columns = ["F"]  (exactly 1) and either std (absolute, in force_unit, > 0)
    #             or relative_std (fraction of |y|, > 0)
    mean_column = "load_mean_N"
    lower_column = "load_min_N"
    upper_column = "load_max_N"
    n_points = 40                       # required: integer >= 3, equally spaced control values
    control_range = [0.001, 0.2]        # optional [start, stop], 0 < start < stop, in control_unit;
                                        #   default: the range common to the columns
    quantity = "force"                  # "force" (default) or a local observable of the specimen:
                                        #   notched-beam, dogbone: "fpz_width"; bar: "damaged_zone_width"
    name = "global"                     # block name; default "global" (force) or the quantity's name
    specimen = { size = 200.0 }         # optional: fields of [specimen] overridden for this test (a size
                                        #   series: one block per size); blocks of the same specimen
                                        #   share one forward run
    weight = 1.0                        # optional p_b > 0: f = sum p_b f_b (global p1, local p2); the
                                        #   block's covariance is divided by p_b
    damage_threshold = 0.5              # optional, local quantity only: 0 <= t < 1, damage counted in
                                        #   the width (default 0: any damage)
    role = "calibration"                # "calibration" (default) | "prediction": predicted at the
                                        #   estimate by `fracid study`, not calibrated on
    delimiter = ","                     # cell separator: "," (default) | ";" | "\\t" (or "tab") | " " (any
                                        #   run of spaces and tabs)
    decimal = "."                       # decimal mark: "." (default) | "," (0,001); "," needs another delimiter
    backtrack_tolerance = 0.002         # optional number >= 0 in control_unit: the largest backtrack of the
                                        #   control column dropped as noise (default 1 % of its range)

    [identify]                          # required for identification
    parameters = ["kappa_i", "beta", "c"]   # required: parameters of the [model] type to identify,
                                            #   no duplicates
    [identify.bounds]                   # required: [lower, upper] for every identified parameter,
                                        #   lower < upper, both inside the parameter's valid range
    kappa_i = [4e-5, 1.2e-4]
    beta = [100.0, 2000.0]
    c = [1.0, 30.0]                     # mm^2
    log = ["beta"]                      # optional: sampled uniformly in log(x); needs lower > 0
    [identify.knn]                      # optional
    n = 64                              # integer >= 2 (grid: points per parameter), default 64
    method = "sobol"                    # "sobol" (default) | "lhs" | "grid"
    k = 5                               # neighbours, 1 <= k <= population (n, or n**p for grid), default 5
    seed = 0                            # integer >= 0, default 0
    [identify.kalman]                   # optional
    groups = 4                          # consecutive observation groups, 1 <= groups <= n_y (total
                                        #   n_points); omitted: one observation per step
    max_iterations = 10                 # integer >= 1, default 10
    tol = 0.01                          # > 0, in standard deviations, default 0.01
    restart = "linearize"               # "linearize" (default) | "prior-mean"

    [study]                             # optional: the checks of `fracid study`
    starts = 3                          # multi-start Kalman filters from distinct population points
                                        #   (0 or 1: no check), default 3
    replicates = 5                      # identifications on data with noise added (0: none; else >= 2)
    seed = 0                            # seed of the replicates' noise, default 0
    tolerance = 0.1                     # largest relative std called "identified", default 0.1
    prior = "knn"                       # Kalman prior covariance: "knn" (neighbours' spread, default)
                                        #   | "bounds" (uniform over the bounds: the data's information only)

    [output]                            # optional
    directory = "results"               # default "results", relative to this file unless absolute
    vtk_steps = []                      # integers >= 0: steps whose fields go to VTK (simulate)

    [simulate]                          # optional: settings of a forward analysis
    target = 0.3                        # mm, > 0; default: the specimen's
    stop_force_fraction = 0.1           # 0 < f < 1, default 0.1: stop below f x peak force
    damage_threshold = 0.0              # 0 <= t < 1, default 0: damage counted in widths

Example
-------
>>> from fracid.config import load_config, build_data, build_operator, build_space, identify_settings
>>> from fracid.inverse.strategy import identify_data
>>> cfg = load_config("study.toml")                                   # doctest: +SKIP
>>> data = build_data(cfg)                                            # doctest: +SKIP
>>> result = identify_data(build_operator(cfg, data), data, build_space(cfg),
...                        **identify_settings(cfg))                  # doctest: +SKIP
"""

from __future__ import annotations

import csv
import dataclasses
import inspect
import math
import os
import re
import tomllib
from dataclasses import dataclass
from pathlib import Path

import numpy as np


__all__ = [
    "Config",
    "ConfigError",
    "ExperimentConfig",
    "IdentifyConfig",
    "KalmanConfig",
    "KnnConfig",
    "ModelConfig",
    "OutputConfig",
    "SimulateConfig",
    "SpecimenConfig",
    "build_data",
    "build_model",
    "build_operator",
    "build_parameters",
    "build_space",
    "build_specimen",
    "identify_settings",
    "load_config",
    "simulate_settings",
    "build_held_out",
    "build_experiment_data",
    "study_settings",
    "StudyConfig",
]


class ConfigError(ValueError):
    """An invalid configuration: the message names the file, the dotted key, the value and what is allowed."""


# ------------------------------------------------------------------------------------ vocabularies

def _model_types() -> tuple:
    """The ``[model] type`` names: those of :data:`fracid.models.MODEL_TYPES` at the time of the call,
    so that a model registered there needs no change here."""
    from fracid.models import MODEL_TYPES

    return tuple(MODEL_TYPES)


def _model_of(kind: str):
    from fracid.models import model_from_type

    return model_from_type(kind)


_CONTROL_UNITS = {"mm": 1.0, "um": 1e-3, "m": 1e3}
#: ``delimiter`` values -> the cell separator ("tab" spells a tab; " " is any run of whitespace)
_DELIMITERS = {",": ",", ";": ";", "\t": "\t", "tab": "\t", " ": " "}
_DECIMALS = (".", ",")
_FORCE_UNITS = {"N": 1.0, "kN": 1e3, "MN": 1e6}
_LOCAL_UNITS = dict(_CONTROL_UNITS)
_KINDS = ("repeats", "envelope", "single")
_METHODS = ("sobol", "lhs", "grid")
_RESTARTS = ("linearize", "prior-mean")
_PURPOSES = ("identify", "simulate")


def _specimen_class(kind: str):
    if kind == "notched-beam":
        from fracid.specimens.beam import NotchedBeam

        return NotchedBeam
    if kind == "dogbone":
        from fracid.specimens.dogbone import DogBone

        return DogBone
    from fracid.specimens.bar import BarWithWeakZone

    return BarWithWeakZone


#: specimen type -> (controls, the first being the default; local observables [mm])
_SPECIMENS = {
    "notched-beam": (("cmod", "deflection"), ("fpz_width",)),
    "dogbone": (("elongation", "platen_displacement"), ("fpz_width",)),
    "bar": (("end_displacement", "weak_zone_elongation"), ("damaged_zone_width",)),
}

_TOP_KEYS = ("model", "specimen", "experiments", "identify", "output", "simulate", "study")
_MODEL_KEYS = ("type", "parameters")
_EXPERIMENT_KEYS = ("file", "control_column", "control_unit", "force_unit", "kind", "force_columns", "mean_column",
                    "lower_column", "upper_column", "std", "relative_std", "n_points", "control_range", "quantity",
                    "name", "specimen", "weight", "damage_threshold", "role", "delimiter", "decimal",
                    "backtrack_tolerance")
_KIND_KEYS = {
    "repeats": ("force_columns",),
    "envelope": ("mean_column", "lower_column", "upper_column"),
    "single": ("force_columns", "std", "relative_std"),
}
_IDENTIFY_KEYS = ("parameters", "bounds", "knn", "kalman")
_KNN_KEYS = ("n", "method", "k", "seed")
_KALMAN_KEYS = ("groups", "max_iterations", "tol", "restart")
_OUTPUT_KEYS = ("directory", "vtk_steps")
_SIMULATE_KEYS = ("target", "stop_force_fraction", "damage_threshold")
_STUDY_KEYS = ("starts", "replicates", "seed", "tolerance", "prior")
_ROLES = ("calibration", "prediction")
#: Kalman steps per pass when [identify.kalman] groups is not given. One observation per step costs
#: 2 p + 1 partial runs per observation (a 30-point curve: over 100 full-run equivalents per pass);
#: with linearised restarts the later passes use one linearisation each whatever the grouping.
DEFAULT_KALMAN_GROUPS = 4


# ------------------------------------------------------------------------------ size limits
# A configuration asking for more than a workstation can hold is refused when it is loaded, with
# the estimate, instead of failing (or swapping for hours) in the middle of a study.

#: largest KNN population (n, or n**p for a grid): each member is one forward run (seconds to
#: minutes each), so 1e5 is already days of computing; n = 1e9 allocated 23.5 GB before the first run
MAX_POPULATION = 100_000

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

#: largest number of data values n_y (the n_points of the calibration blocks together, and of each
#: prediction block): the covariance C_exp is a dense n_y x n_y matrix of 8-byte numbers (5000 ->
#: 191 MiB, 50000 -> 18.6 GiB) factorised by every Kalman step; 40 to 100 points describe a curve
MAX_DATA_VALUES = 5_000


def _bytes(n: float) -> str:
    """A memory size in words: ``18.6 GiB``, ``195 MiB``, ``12 KiB``."""
    for unit, size in (("TiB", 2**40), ("GiB", 2**30), ("MiB", 2**20), ("KiB", 2**10)):
        if n >= size:
            return f"{n / size:.3g} {unit}"
    return f"{n:.0f} bytes"


# ------------------------------------------------------------------------------ validated config


@dataclass(frozen=True)
class ModelConfig:
    """``[model]``: the model type and the parameter values given (the rest are defaults)."""

    type: str = "gradient-damage"
    parameters: tuple = ()  # ((name, value), ...) as given

    @property
    def regularization(self) -> str | None:
        """The ``regularization`` argument of :func:`fracid.forward.simulate` for the damage models
        (``"gradient"``, ``"local"``); None for a model that has none (e.g. the cohesive crack)."""
        return getattr(_model_of(self.type), "regularization", None)


@dataclass(frozen=True)
class SpecimenConfig:
    """``[specimen]``: type, control (resolved to the default when omitted) and the dataclass fields given."""

    type: str
    control: str
    options: tuple = ()  # ((field, value), ...) as given, type-checked


@dataclass(frozen=True)
class ExperimentConfig:
    """One ``[[experiments]]`` block (``index`` is its position, ``file`` an absolute path)."""

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
    quantity: str = "force"
    name: str = "global"
    specimen: tuple = ()  # ((field, value), ...) overriding [specimen] for this test (e.g. its size)
    weight: float = 1.0
    damage_threshold: float = 0.0
    role: str = "calibration"
    delimiter: str = ","  # the cell separator itself ("tab" is stored as "\t"; " " is any whitespace)
    decimal: str = "."
    backtrack_tolerance: float | None = None  # in control_unit, as given; None: 1 % of the control range

    @property
    def control_scale(self) -> float:
        """Multiplier from ``control_unit`` to mm."""
        return _CONTROL_UNITS[self.control_unit]

    @property
    def force_scale(self) -> float:
        """Multiplier from ``force_unit`` to N (force) or to mm (local quantity)."""
        return (_FORCE_UNITS if self.quantity == "force" else _LOCAL_UNITS)[self.force_unit]

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
class KnnConfig:
    """``[identify.knn]``."""

    n: int = 64
    method: str = "sobol"
    k: int = 5
    seed: int = 0

    def population(self, p: int) -> int:
        """Number of forward runs for p parameters."""
        return self.n**p if self.method == "grid" else self.n


@dataclass(frozen=True)
class KalmanConfig:
    """``[identify.kalman]``; ``groups`` None = one observation per step."""

    groups: int | None = None
    max_iterations: int = 10
    tol: float = 0.01
    restart: str = "linearize"


@dataclass(frozen=True)
class IdentifyConfig:
    """``[identify]``: identified parameters, their bounds and log flags, KNN and Kalman settings."""

    parameters: tuple
    lower: tuple
    upper: tuple
    log: tuple = ()  # names sampled in log scale
    knn: KnnConfig = KnnConfig()
    kalman: KalmanConfig = KalmanConfig()


@dataclass(frozen=True)
class OutputConfig:
    """``[output]``: ``directory`` absolute (resolved against the config file)."""

    directory: Path
    vtk_steps: tuple = ()


@dataclass(frozen=True)
class SimulateConfig:
    """``[simulate]``: target [mm] (None: the specimen's), stop_force_fraction, damage_threshold."""

    target: float | None = None
    stop_force_fraction: float = 0.1
    damage_threshold: float = 0.0


@dataclass(frozen=True)
class StudyConfig:
    """``[study]``: multi-start points, noisy replicates, their seed, and the tolerance of the verdict."""

    starts: int = 3
    replicates: int = 5
    seed: int = 0
    tolerance: float = 0.1
    prior: str = "knn"


@dataclass(frozen=True)
class Config:
    """A validated configuration (see the module docstring for the schema)."""

    path: Path
    purpose: str
    model: ModelConfig
    specimen: SpecimenConfig
    experiments: tuple  # of ExperimentConfig; empty if none given
    identify: IdentifyConfig | None
    output: OutputConfig
    simulate: SimulateConfig
    study: StudyConfig = StudyConfig()
    warnings: tuple = ()  # of str: valid but probably unintended settings, for the user to read

    @property
    def base_dir(self) -> Path:
        """Directory against which relative paths are resolved."""
        return self.path.parent

    @property
    def calibration(self) -> tuple:
        """The experiments used for calibration (role "calibration")."""
        return tuple(e for e in self.experiments if e.role == "calibration")

    @property
    def n_y(self) -> int:
        """Number of measured values used for calibration (sum of their blocks' n_points)."""
        return sum(e.n_points for e in self.calibration)


# ---------------------------------------------------------------------------------- validation


def _show(value) -> str:
    if isinstance(value, dict):
        text = "a table {" + ", ".join(value) + "}"
    else:
        text = repr(value)
    return text if len(text) <= 200 else text[:197] + "..."


class _Checker:
    """Raises ConfigError messages naming the file, the dotted key, the value and what is allowed."""

    def __init__(self, path: Path):
        self.path = path
        self.warnings: list[str] = []

    def fail(self, key: str, value, allowed: str):
        raise ConfigError(f"{self.path}: {key} = {_show(value)}: {allowed}")

    def warn(self, text: str) -> None:
        """Record a warning (a valid value that is probably not what was meant), once."""
        if text not in self.warnings:
            self.warnings.append(text)

    def missing(self, key: str, allowed: str):
        raise ConfigError(f"{self.path}: {key} is missing (no value given); it is required: {allowed}")

    def table(self, key: str, value, allowed_keys) -> dict:
        if not isinstance(value, dict):
            self.fail(key, value, f"must be a table (section) with keys {', '.join(allowed_keys)}")
        prefix = f"{key}." if key else ""
        for k, v in value.items():
            if k not in allowed_keys:
                self.fail(prefix + k, v, f"unknown key; allowed keys here: {', '.join(allowed_keys)}")
        return value

    def number(self, key, value, allowed="must be a number", ok=lambda v: True) -> float:
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value) or not ok(value):
            self.fail(key, value, allowed)
        return float(value)

    def integer(self, key, value, allowed="must be an integer", ok=lambda v: True) -> int:
        if isinstance(value, bool) or not isinstance(value, int) or not ok(value):
            self.fail(key, value, allowed)
        return int(value)

    def string(self, key, value, allowed="must be a string") -> str:
        if not isinstance(value, str) or not value:
            self.fail(key, value, allowed)
        return value

    def choice(self, key, value, choices) -> str:
        text = "must be one of " + ", ".join(repr(c) for c in choices)
        if not isinstance(value, str) or value not in choices:
            self.fail(key, value, text)
        return value

    def pair(self, key, value, allowed) -> tuple[float, float]:
        """Two finite numbers [a, b]; any defect names the whole list."""
        if not (isinstance(value, list) and len(value) == 2):
            self.fail(key, value, allowed)
        for v in value:
            if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
                self.fail(key, value, allowed)
        return float(value[0]), float(value[1])

    def strings(self, key, value, what="column names") -> tuple:
        if not isinstance(value, list) or not all(isinstance(v, str) and v for v in value):
            self.fail(key, value, f"must be a list of {what} (strings)")
        duplicates = sorted({v for v in value if value.count(v) > 1})
        if duplicates:
            self.fail(key, value, f"must not repeat a name; repeated: {', '.join(map(repr, duplicates))}")
        return tuple(value)

    def file(self, key, value, base: Path) -> Path:
        self.string(key, value, "must be a file path (string)")
        given = Path(value).expanduser()
        resolved = (given if given.is_absolute() else base / given).resolve()
        where = f"{resolved}" if given.is_absolute() else f"resolved relative to the config file: {resolved}"
        if not resolved.exists():
            self.fail(key, value, f"file not found ({where})")
        if not resolved.is_file():
            self.fail(key, value, f"not a file ({where})")
        return resolved


def _read_toml(path: Path) -> dict:
    try:
        with open(path, "rb") as handle:
            raw = handle.read()
        # a byte-order mark (Windows Notepad) is not TOML but says nothing wrong about the file
        return tomllib.loads(raw.removeprefix(b"\xef\xbb\xbf").decode("utf-8"))
    except FileNotFoundError:
        raise ConfigError(f"{path}: configuration file not found") from None
    except IsADirectoryError:
        raise ConfigError(f"{path}: is a directory, not a configuration file") from None
    except UnicodeDecodeError as err:
        raise ConfigError(f"{path}: not a UTF-8 text file ({err})") from None
    except tomllib.TOMLDecodeError as err:
        raise ConfigError(f"{path}: not valid TOML: {err}") from None


def _range_text(cls, name: str) -> str:
    """The valid range of parameter ``name`` of the parameter class ``cls`` in words (e.g. ``"0 < c"``,
    ``"-1 < nu < 0.5"``): from its :class:`~fracid.model.ranges.ParameterRange` when it declares
    ``ranges``, else the limits of ``valid_bounds`` (the interface every model's class has)."""
    rng = getattr(cls, "ranges", {}).get(name)
    if rng is not None:
        return rng.describe(name)
    lower, upper = cls.valid_bounds([name])
    return f"{lower[0]:g} <= {name} <= {upper[0]:g}"


def _parameter_allowed(cls, name: str) -> str:
    return f"must be a number in the valid range {_range_text(cls, name)} [{cls.units().get(name, '-')}]"


def _valid_parameter(cls, name: str, value: float) -> bool:
    """Whether ``value`` lies in the valid range of ``name`` (its ``ParameterRange``, else the class's
    ``valid_bounds``, whose open ends are moved inside). Conditions joining several parameters are
    left to the class (see :func:`_model`)."""
    rng = getattr(cls, "ranges", {}).get(name)
    if rng is not None:
        return rng.admits(value)
    lower, upper = cls.valid_bounds([name])
    return bool(lower[0] <= value <= upper[0])


def _model(ck: _Checker, raw) -> ModelConfig:
    if raw is None:
        return ModelConfig()
    ck.table("model", raw, _MODEL_KEYS)
    kind = ck.choice("model.type", raw.get("type", "gradient-damage"), _model_types())
    cls = _model_of(kind).parameters
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
                                 lambda v, name=name: _valid_parameter(cls, name, v))
    try:  # conditions joining several parameters, e.g. the area of the cohesive law over c1, c2
        cls(**values)
    except ValueError as err:
        ck.fail("model.parameters", params, f"rejected together by {cls.__name__} (model.type = {kind!r}): {err}")
    return ModelConfig(type=kind, parameters=tuple(values.items()))


def _check_model_runs_on(ck: _Checker, model: ModelConfig, specimen) -> None:
    from fracid.models import runs_on

    if not runs_on(_model_of(model.type), _specimen_class(specimen.type)):
        fits = [kind for kind in _SPECIMENS if runs_on(_model_of(model.type), _specimen_class(kind))]
        ck.fail("specimen.type", specimen.type, f"model.type = {model.type!r} does not run on it; it runs on "
                + (", ".join(repr(k) for k in fits) or "no built-in specimen"))


def _field_kind(field: dataclasses.Field) -> str:
    text = field.type if isinstance(field.type, str) else getattr(field.type, "__name__", str(field.type))
    return text.replace("| None", "").replace("Optional[", "").replace("]", "").strip()


def _specimen_error_key(message: str, fields, given) -> str | None:
    """The specimen field a validation message is about: the first named one the user gave, else the first named."""
    found = []
    for name in fields:
        match = re.search(rf"(?<![A-Za-z0-9_]){re.escape(name)}(?![A-Za-z0-9_])", message)
        if match:
            found.append((match.start(), name))
    found.sort()
    for _, name in found:
        if name in given:
            return name
    return found[0][1] if found else None


def _specimen_options(ck: _Checker, prefix: str, raw: dict, cls) -> dict:
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


def _check_specimen(ck: _Checker, prefix: str, kind: str, cls, options: dict, given: dict) -> None:
    """Build the specimen once so its own validation runs; errors name the key under ``prefix``."""
    try:
        cls(**options)
    except (TypeError, ValueError) as err:
        fields = {f.name: f for f in dataclasses.fields(cls)}
        name = _specimen_error_key(str(err), fields, options)
        if name is None:
            raise ConfigError(f"{ck.path}: {prefix} ({kind}) is invalid: {err}") from None
        value = options.get(name, getattr(cls, name, None))
        where = f"{prefix}.{name}" if name in given else f"specimen.{name}"
        default = "" if name in options else " (default)"
        raise ConfigError(f"{ck.path}: {where} = {_show(value)}{default}: {err}") from None


def _field_key(prefix: str, name: str, options: dict, given: dict) -> tuple[str, str]:
    """The dotted key of specimen field ``name`` (under ``prefix`` if given there, else ``specimen``)
    and " (default)" when it was not given at all."""
    return (f"{prefix}.{name}" if name in given else f"specimen.{name}"), ("" if name in options else " (default)")


def _check_specimen_size(ck: _Checker, prefix: str, kind: str, cls, options: dict, given: dict) -> None:
    """Refuse a mesh beyond :data:`MAX_BAR_ELEMENTS` or :data:`MAX_UNKNOWNS`, estimated from the
    geometry without building it (the specimen is valid: :func:`_check_specimen` ran first)."""
    specimen = cls(**options)
    if kind == "bar":
        n = specimen.n_elements
        if n > MAX_BAR_ELEMENTS:
            key, default = _field_key(prefix, "n_elements", options, given)
            raise ConfigError(
                f"{ck.path}: {key} = {n}{default}: a forward run of {n:,} bar elements needs about "
                f"{_bytes(n * BAR_BYTES_PER_ELEMENT)} of memory ({BAR_BYTES_PER_ELEMENT:,} bytes per element, "
                f"measured); at most {MAX_BAR_ELEMENTS:,} elements are allowed, and a few elements per internal length "
                "l = sqrt(2 c) are enough")
        return
    elements, nodes, vertices = specimen.mesh_size()
    unknowns = 2 * nodes + vertices
    if unknowns > MAX_UNKNOWNS:
        key, default = _field_key(prefix, "h_fine", options, given)
        if prefix != "specimen" and "h_fine" not in given:  # the experiment's overrides make the mesh too large
            default += f" with {prefix} = {{" + ", ".join(f"{k} = {_show(v)}" for k, v in given.items()) + "}"
        shape = ", ".join(f"{name} = {value:g}" for name, value in options.items()
                          if isinstance(value, float) and name != "h_fine")
        raise ConfigError(
            f"{ck.path}: {key} = {specimen.h_fine:g}{default}: the mesh of this {kind} would have about {elements:,} "
            f"elements and {unknowns:,} unknowns (estimated from the geometry{': ' + shape if shape else ''}), "
            f"needing about {_bytes(unknowns * BYTES_PER_UNKNOWN)} of memory in a forward run "
            f"({BYTES_PER_UNKNOWN:,} bytes per unknown, measured); at most {MAX_UNKNOWNS:,} unknowns are allowed: "
            "use a larger h_fine (a few elements per internal length l = sqrt(2 c) are enough)")


def _data_limit_text(n_y: int, what: str) -> str:
    return (f"{what} n_y = {n_y:,} data values, whose covariance takes n_y^2 x 8 bytes = {_bytes(8.0 * n_y * n_y)}; "
            f"at most {MAX_DATA_VALUES:,} are allowed ({_bytes(8.0 * MAX_DATA_VALUES**2)}), and 40 to 100 points "
            "describe a curve: lower n_points")


def _specimen(ck: _Checker, raw) -> SpecimenConfig:
    if raw is None:
        ck.missing("specimen", "a [specimen] section with type = " + " | ".join(repr(t) for t in _SPECIMENS))
    if not isinstance(raw, dict):
        ck.fail("specimen", raw, "must be a table (section)")
    if "type" not in raw:
        ck.missing("specimen.type", "one of " + ", ".join(repr(t) for t in _SPECIMENS))
    kind = ck.choice("specimen.type", raw["type"], tuple(_SPECIMENS))
    cls = _specimen_class(kind)
    fields = {f.name: f for f in dataclasses.fields(cls)}
    ck.table("specimen", raw, ("type", "control", *fields))
    controls, _ = _SPECIMENS[kind]
    control = ck.choice("specimen.control", raw.get("control", controls[0]), controls)
    options = _specimen_options(ck, "specimen", {k: v for k, v in raw.items() if k not in ("type", "control")}, cls)
    _check_specimen(ck, "specimen", kind, cls, options, options)
    _check_specimen_size(ck, "specimen", kind, cls, options, options)
    return SpecimenConfig(type=kind, control=control, options=tuple(options.items()))


def _csv_header(ck: _Checker, key: str, value, path: Path, delimiter: str, decimal: str) -> list[str]:
    """The header cells of a data file, split by ``delimiter``; a header that is one cell holding
    another separator, or a first data row with decimal commas read with ``decimal = "."``, is named
    as such (instead of a missing column or a cell that is not a number)."""
    from fracid.data.curves import decimal_comma_hint, delimiter_hint, iter_rows

    header = first = None
    try:
        with open(path, newline="", encoding="utf-8-sig") as handle:
            for _, cells in iter_rows(handle, delimiter):
                if not any(cell.strip() for cell in cells):
                    continue
                if header is None:
                    header = [cell.strip() for cell in cells]
                else:
                    first = cells
                    break
    except (UnicodeDecodeError, csv.Error) as err:
        ck.fail(key, value, f"not a readable UTF-8 CSV file ({err})")
    if header is None:
        ck.fail(key, value, f"the file is empty (no header row): {path}")
    guess = delimiter_hint(header, delimiter)
    if guess is not None:
        given = _toml_text(delimiter) + (" (the default)" if delimiter == "," else "")
        ck.fail(key, value, f"the header is one cell {header[0]!r} when split by delimiter = {given}: the file seems "
                            f"to be separated by {guess!r}; set delimiter = {_toml_text(guess)} (and decimal = \",\" "
                            "for decimal commas)")
    hint = first is not None and decimal_comma_hint(first, delimiter, decimal, len(header))
    if hint:
        row = ", ".join(repr(cell.strip()) for cell in first)
        ck.fail(key, value, f"the first data row ({row}) cannot be read with delimiter = {_toml_text(delimiter)} and "
                            f"decimal = {_toml_text(decimal)}: {hint}")
    return header


def _toml_text(text: str) -> str:
    """A string as written in TOML: ``";"``, ``"\\t"``."""
    return '"' + text.replace("\\", "\\\\").replace('"', '\\"').replace("\t", "\\t") + '"'


def _experiment(ck: _Checker, i: int, raw, base: Path, specimen: SpecimenConfig) -> ExperimentConfig:
    prefix = f"experiments[{i}]"
    ck.table(prefix, raw, _EXPERIMENT_KEYS)

    def required(name):
        if name not in raw:
            ck.missing(f"{prefix}.{name}", _REQUIRED_TEXT[name])
        return raw[name]

    _, observables = _SPECIMENS[specimen.type]
    quantity = ck.choice(f"{prefix}.quantity", raw.get("quantity", "force"), ("force", *observables))
    file = ck.file(f"{prefix}.file", required("file"), base)
    control_column = ck.string(f"{prefix}.control_column", required("control_column"), "must be a column name")
    control_unit = ck.choice(f"{prefix}.control_unit", required("control_unit"), tuple(_CONTROL_UNITS))
    units = _FORCE_UNITS if quantity == "force" else _LOCAL_UNITS
    if "force_unit" not in raw:
        ck.missing(f"{prefix}.force_unit", f"the unit of {quantity!r}, one of " + ", ".join(map(repr, units)))
    force_unit = ck.choice(f"{prefix}.force_unit", raw["force_unit"], tuple(units))
    kind = ck.choice(f"{prefix}.kind", required("kind"), _KINDS)
    for name in raw:
        if name in {k for ks in _KIND_KEYS.values() for k in ks} and name not in _KIND_KEYS[kind]:
            ck.fail(f"{prefix}.{name}", raw[name], f"not used by kind {kind!r}, which takes "
                    + ", ".join(_KIND_KEYS[kind]))
    n_points = ck.integer(f"{prefix}.n_points", required("n_points"), "must be an integer >= 3", lambda v: v >= 3)
    if n_points > MAX_DATA_VALUES:
        ck.fail(f"{prefix}.n_points", n_points, _data_limit_text(n_points, "this block alone has"))

    delimiter = raw.get("delimiter", ",")
    if not isinstance(delimiter, str) or delimiter not in _DELIMITERS:
        ck.fail(f"{prefix}.delimiter", delimiter, 'must be one of ",", ";", "\\t" (or "tab"), " " (any run of '
                                                 "spaces and tabs); the cell separator of the file")
    delimiter = _DELIMITERS[delimiter]
    decimal = ck.choice(f"{prefix}.decimal", raw.get("decimal", "."), _DECIMALS)
    if decimal == delimiter:
        ck.fail(f"{prefix}.decimal", decimal, 'a decimal comma needs another delimiter: with delimiter = "," (the '
                                              'default) a comma cannot also mark the decimals; files with decimal '
                                              'commas are separated by ";" or tabs: set delimiter = ";" or "tab"')
    backtrack = None
    if "backtrack_tolerance" in raw:
        backtrack = ck.number(f"{prefix}.backtrack_tolerance", raw["backtrack_tolerance"],
                              f"must be a number >= 0 [{control_unit}] (the largest backtrack of the control column "
                              "treated as noise)", lambda v: v >= 0)

    header = _csv_header(ck, f"{prefix}.file", raw["file"], file, delimiter, decimal)
    available = "available columns: " + ", ".join(repr(c) for c in header)

    def column(name, value):
        key = f"{prefix}.{name}"
        ck.string(key, value, "must be a column name (string)")
        if value not in header:
            ck.fail(key, value, f"the file {file} has no such column; {available}")
        return value

    column("control_column", control_column)
    options = {}
    if kind in ("repeats", "single"):
        key = f"{prefix}.force_columns"
        names = ck.strings(key, required("force_columns"))
        if kind == "repeats" and len(names) < 2:
            ck.fail(key, raw["force_columns"], "kind 'repeats' needs at least 2 columns (one per repeated test)")
        if kind == "single" and len(names) != 1:
            ck.fail(key, raw["force_columns"], "kind 'single' takes exactly 1 column")
        for name in names:
            if name not in header:
                ck.fail(key, raw["force_columns"], f"the file {file} has no column {name!r}; {available}")
        options["force_columns"] = names
    else:
        for name in _KIND_KEYS["envelope"]:
            options[name] = column(name, required(name))
    if kind == "single":
        given = [name for name in ("std", "relative_std") if name in raw]
        if len(given) != 1:
            key = f"{prefix}.{given[1] if given else 'std'}"
            text = "kind 'single' needs exactly one of std (absolute, in force_unit, > 0) or relative_std (fraction of |y|, > 0)"
            if not given:
                ck.missing(key, text)
            ck.fail(key, raw[given[1]], text)
        name = given[0]
        unit = f" [{force_unit}]" if name == "std" else " (fraction of |y|)"
        options[name] = ck.number(f"{prefix}.{name}", raw[name], f"must be a number > 0{unit}", lambda v: v > 0)
        value = options[name]
        if name == "relative_std" and value > 1:
            ck.warn(f"{prefix}.relative_std = {value:g} is more than 1, i.e. more than 100 % of the value; "
                    f"if you meant {value:g} %, write {value / 100:g}")
    control_range = None
    if "control_range" in raw:
        value = raw["control_range"]
        allowed = f"must be [start, stop] with 0 < start < stop [{control_unit}]"
        a, b = ck.pair(f"{prefix}.control_range", value, allowed)
        if not 0 < a < b:
            ck.fail(f"{prefix}.control_range", value, allowed)
        control_range = (a, b)
    default_name = "global" if quantity == "force" else quantity
    name = ck.string(f"{prefix}.name", raw.get("name", default_name), "must be a non-empty string")
    overrides = ()
    if "specimen" in raw:
        cls = _specimen_class(specimen.type)
        fields = [f.name for f in dataclasses.fields(cls)]
        given = _specimen_options(ck, f"{prefix}.specimen", ck.table(f"{prefix}.specimen", raw["specimen"], fields), cls)
        _check_specimen(ck, f"{prefix}.specimen", specimen.type, cls, {**dict(specimen.options), **given}, given)
        _check_specimen_size(ck, f"{prefix}.specimen", specimen.type, cls, {**dict(specimen.options), **given}, given)
        overrides = tuple(given.items())
    weight = ck.number(f"{prefix}.weight", raw.get("weight", 1.0), "must be a number > 0 (p in f = sum p_b f_b)",
                       lambda v: v > 0)
    threshold = 0.0
    if "damage_threshold" in raw:
        if quantity == "force":
            ck.fail(f"{prefix}.damage_threshold", raw["damage_threshold"],
                    "applies to a local quantity only (this block's quantity is 'force')")
        threshold = ck.number(f"{prefix}.damage_threshold", raw["damage_threshold"],
                              "must be a number with 0 <= t < 1 (damage counted in the width)", lambda v: 0 <= v < 1)
    role = ck.choice(f"{prefix}.role", raw.get("role", "calibration"), _ROLES)
    return ExperimentConfig(index=i, file=file, control_column=control_column, control_unit=control_unit,
                            force_unit=force_unit, kind=kind, n_points=n_points, control_range=control_range,
                            quantity=quantity, name=name, specimen=overrides, weight=weight,
                            damage_threshold=threshold, role=role, delimiter=delimiter, decimal=decimal,
                            backtrack_tolerance=backtrack, **options)


_REQUIRED_TEXT = {
    "file": "a CSV file path, relative to the config file",
    "control_column": "the name of the control column",
    "control_unit": "one of " + ", ".join(map(repr, _CONTROL_UNITS)),
    "kind": "one of " + ", ".join(map(repr, _KINDS)),
    "n_points": "an integer >= 3",
    "force_columns": "a list of force column names",
    "mean_column": "the name of the mean column (kind 'envelope')",
    "lower_column": "the name of the lower-envelope column (kind 'envelope')",
    "upper_column": "the name of the upper-envelope column (kind 'envelope')",
}


def _experiments(ck: _Checker, raw, base: Path, specimen: SpecimenConfig, needed: bool) -> tuple:
    if raw is None:
        if needed:
            ck.missing("experiments", "one or more [[experiments]] blocks (data files) for identification")
        return ()
    if not isinstance(raw, list) or not raw:
        ck.fail("experiments", raw, "must be one or more [[experiments]] tables")
    return tuple(_experiment(ck, i, block, base, specimen) for i, block in enumerate(raw))


def _identify(ck: _Checker, raw, n_y: int | None, needed: bool, model: ModelConfig) -> IdentifyConfig | None:
    if raw is None:
        if needed:
            ck.missing("identify", "an [identify] section with parameters and [identify.bounds]")
        return None
    ck.table("identify", raw, _IDENTIFY_KEYS)
    cls = _model_of(model.type).parameters
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
    names = tuple(value)

    if "bounds" not in raw:
        ck.missing("identify.bounds", "a table with [lower, upper] for " + ", ".join(names))
    bounds = ck.table("identify.bounds", raw["bounds"], (*names, "log"))
    lower, upper = [], []
    for name in names:
        key = f"identify.bounds.{name}"
        unit = cls.units().get(name, "-")
        allowed = f"must be [lower, upper] with lower < upper, both in the valid range {_range_text(cls, name)} [{unit}]"
        if name not in bounds:
            ck.missing(key, f"[lower, upper] bounds of the identified parameter {name} [{unit}]")
        pair = bounds[name]
        lo, hi = ck.pair(key, pair, allowed)
        if not lo < hi:
            ck.fail(key, pair, f"lower = {lo:g} must be below upper = {hi:g} ({allowed})")
        for which, v in (("lower", lo), ("upper", hi)):
            if not _valid_parameter(cls, name, v):
                ck.fail(key, pair, f"the {which} bound {v:g} is outside the valid range {_range_text(cls, name)} [{unit}]")
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

    raw_knn = ck.table("identify.knn", raw.get("knn", {}), _KNN_KEYS)
    n = ck.integer("identify.knn.n", raw_knn.get("n", 64), "must be an integer >= 2", lambda v: v >= 2)
    method = ck.choice("identify.knn.method", raw_knn.get("method", "sobol"), _METHODS)
    seed = ck.integer("identify.knn.seed", raw_knn.get("seed", 0), "must be an integer >= 0", lambda v: v >= 0)
    knn = KnnConfig(n=n, method=method, k=5, seed=seed)
    population = knn.population(len(names))
    how = f"n**p = {n}**{len(names)}" if method == "grid" else f"n = {n}"
    if population > MAX_POPULATION:
        values = population * (len(names) + (n_y or 0))
        ck.fail("identify.knn.n", n, f"the population of {population:,} points ({how}, method {method!r}) is above the "
                                     f"limit of {MAX_POPULATION:,}: each point is one forward run (seconds to minutes "
                                     f"each), and the points and their outputs alone take {values:,} x 8 bytes = "
                                     f"{_bytes(8.0 * values)} (p = {len(names)} parameters + n_y = {n_y or 0} outputs "
                                     "per point); a few hundred points are enough to start the Kalman filter")
    k_value = raw_knn.get("k", 5)
    k = ck.integer("identify.knn.k" + ("" if "k" in raw_knn else " (default)"), k_value,
                   f"must be an integer with 1 <= k <= the population size {population} ({how}, method {method!r})",
                   lambda v: 1 <= v <= population)
    knn = dataclasses.replace(knn, k=k)

    raw_kf = ck.table("identify.kalman", raw.get("kalman", {}), _KALMAN_KEYS)
    groups = None
    if "groups" in raw_kf:
        top = n_y if n_y else None
        allowed = (f"must be an integer with 1 <= groups <= n_y = {top} (the total n_points of the experiments)"
                   if top else "must be an integer >= 1")
        groups = ck.integer("identify.kalman.groups", raw_kf["groups"], allowed,
                            lambda v: v >= 1 and (top is None or v <= top))
    kalman = KalmanConfig(
        groups=groups,
        max_iterations=ck.integer("identify.kalman.max_iterations", raw_kf.get("max_iterations", 10),
                                  "must be an integer >= 1", lambda v: v >= 1),
        tol=ck.number("identify.kalman.tol", raw_kf.get("tol", 0.01), "must be a number > 0 [standard deviations]",
                      lambda v: v > 0),
        restart=ck.choice("identify.kalman.restart", raw_kf.get("restart", "linearize"), _RESTARTS),
    )
    return IdentifyConfig(parameters=names, lower=tuple(lower), upper=tuple(upper), log=log, knn=knn, kalman=kalman)


def _output(ck: _Checker, raw, base: Path) -> OutputConfig:
    raw = ck.table("output", {} if raw is None else raw, _OUTPUT_KEYS)
    directory = ck.string("output.directory", raw.get("directory", "results"), "must be a directory path (string)")
    path = Path(directory).expanduser()
    path = (path if path.is_absolute() else base / path).resolve()
    steps = raw.get("vtk_steps", [])
    allowed = "must be a list of step numbers (integers >= 0)"
    if not isinstance(steps, list):
        ck.fail("output.vtk_steps", steps, allowed)
    for step in steps:
        if isinstance(step, bool) or not isinstance(step, int) or step < 0:
            ck.fail("output.vtk_steps", steps, allowed)
    return OutputConfig(directory=path, vtk_steps=tuple(sorted(set(steps))))


def _simulate(ck: _Checker, raw) -> SimulateConfig:
    raw = ck.table("simulate", {} if raw is None else raw, _SIMULATE_KEYS)
    target = None
    if "target" in raw:
        target = ck.number("simulate.target", raw["target"], "must be a number > 0 [mm] (final control value)",
                           lambda v: v > 0)
    return SimulateConfig(
        target=target,
        stop_force_fraction=ck.number("simulate.stop_force_fraction", raw.get("stop_force_fraction", 0.1),
                                      "must be a number with 0 < f < 1 (fraction of the peak force)",
                                      lambda v: 0 < v < 1),
        damage_threshold=ck.number("simulate.damage_threshold", raw.get("damage_threshold", 0.0),
                                   "must be a number with 0 <= t < 1 (damage)", lambda v: 0 <= v < 1),
    )


def _study(ck: _Checker, raw) -> StudyConfig:
    raw = ck.table("study", {} if raw is None else raw, _STUDY_KEYS)
    return StudyConfig(
        starts=ck.integer("study.starts", raw.get("starts", 3), "must be an integer >= 0 (0 or 1: no multi-start check)",
                          lambda v: v >= 0),
        replicates=ck.integer("study.replicates", raw.get("replicates", 5),
                              "must be 0 (no stability check) or an integer >= 2", lambda v: v == 0 or v >= 2),
        seed=ck.integer("study.seed", raw.get("seed", 0), "must be an integer >= 0", lambda v: v >= 0),
        tolerance=ck.number("study.tolerance", raw.get("tolerance", 0.1),
                            "must be a number with 0 < t < 1 (largest relative std called identified)",
                            lambda v: 0 < v < 1),
        prior=ck.choice("study.prior", raw.get("prior", "knn"), ("knn", "bounds")),
    )


def load_config(path: str | os.PathLike, *, purpose: str = "identify") -> Config:
    """Read and validate a TOML configuration.

    Parameters
    ----------
    path : str or path-like
        The TOML file; relative paths inside it are resolved against its directory.
    purpose : {"identify", "simulate"}
        ``"identify"`` requires ``[[experiments]]`` and ``[identify]``; ``"simulate"`` does not
        (they are validated when present).

    Returns
    -------
    Config
        Frozen, validated configuration.

    Raises
    ------
    ConfigError
        For any invalid, missing or unknown key, naming the file, the key, the value and what is allowed.
    """
    if purpose not in _PURPOSES:
        raise ValueError(f"purpose = {purpose!r}; choose 'identify' or 'simulate'")
    path = Path(path).expanduser().resolve()
    ck = _Checker(path)
    raw = ck.table("", _read_toml(path), _TOP_KEYS)
    base = path.parent
    model = _model(ck, raw.get("model"))
    specimen = _specimen(ck, raw.get("specimen"))
    _check_model_runs_on(ck, model, specimen)
    experiments = _experiments(ck, raw.get("experiments"), base, specimen, purpose == "identify")
    n_y = sum(e.n_points for e in experiments if e.role == "calibration") or None
    if experiments and not n_y and purpose == "identify":
        ck.fail("experiments", [e.role for e in experiments], "at least one experiment needs role = 'calibration'")
    if n_y and n_y > MAX_DATA_VALUES:
        ck.fail("experiments", [e.n_points for e in experiments if e.role == "calibration"],
                _data_limit_text(n_y, "the n_points of the calibration blocks add up to"))
    identify = _identify(ck, raw.get("identify"), n_y, purpose == "identify", model)
    output = _output(ck, raw.get("output"), base)
    simulate = _simulate(ck, raw.get("simulate"))
    study = _study(ck, raw.get("study"))
    _mesh_warnings(ck, model, specimen, experiments, identify)
    return Config(path=path, purpose=purpose, model=model, specimen=specimen, experiments=experiments,
                  identify=identify, output=output, simulate=simulate, study=study, warnings=tuple(ck.warnings))


def _mesh_warnings(ck: _Checker, model: ModelConfig, specimen: SpecimenConfig, experiments, identify) -> None:
    """Warn when the element size in the process zone exceeds the internal length l = sqrt(2 c) of a
    gradient or integral damage model (the smallest c: the given one, or the lower bound when c is
    identified): the damage band, a few l wide, is then not resolved and the results depend on the mesh.

    Element size: ``h_fine`` for the notched beam and the dog-bone (8-node elements in the refined
    band), ``length / n_elements`` for the bar.
    """
    if model.regularization not in ("gradient", "integral"):
        return
    c = _model_parameters(model).c
    where = f"c = {c:g} mm^2" if "c" in dict(model.parameters) else f"c = {c:g} mm^2 (default)"
    if identify is not None and "c" in identify.parameters:
        lower = identify.lower[identify.parameters.index("c")]
        if lower < c:
            c, where = lower, f"the lower bound c = {lower:g} mm^2 of identify.bounds.c"
    length = math.sqrt(2.0 * c)
    variants = [("specimen", dict(specimen.options), dict(specimen.options))]
    variants += [(f"experiments[{e.index}].specimen", {**dict(specimen.options), **dict(e.specimen)}, dict(e.specimen))
                 for e in experiments if e.specimen]
    cls = _specimen_class(specimen.type)
    for prefix, options, given in variants:
        built = cls(**options)
        if specimen.type == "bar":
            h = built.length / built.n_elements
            key, default = _field_key(prefix, "n_elements", options, given)
            size = f"{key} = {built.n_elements}{default}: the element size length / n_elements = {h:.3g} mm"
            needed = 2.0 * built.length / length
            advice = (f"use n_elements >= {math.ceil(needed)} (h <= l/2)" if needed <= MAX_BAR_ELEMENTS else
                      f"that needs {needed:.3g} elements, beyond the limit {MAX_BAR_ELEMENTS}: is c in mm^2?")
        else:
            h = built.h_fine
            key, default = _field_key(prefix, "h_fine", options, given)
            size = f"{key} = {h:g}{default}: the element size h_fine = {h:g} mm"
            advice = "use h_fine <= l/2"
        if h > length:
            ck.warn(f"{size} is larger than the internal length l = sqrt(2 c) = {length:.3g} mm (with {where}): "
                    f"the damage band is not resolved and the results depend on the mesh; {advice}")


def _model_parameters(model: ModelConfig):
    """The parameters of a validated ``[model]`` section (those given, the rest the class's defaults)."""
    return _model_of(model.type).parameters(**dict(model.parameters))


# ------------------------------------------------------------------------------------ builders


def _require(cfg: Config, section: str):
    value = getattr(cfg, section)
    if not value:
        what = "[[experiments]] blocks" if section == "experiments" else f"an [{section}] section"
        raise ConfigError(f"{cfg.path}: {section} is missing (no value given); identification needs {what}")
    return value


def build_model(cfg: Config):
    """The forward model of ``[model] type`` (:func:`fracid.models.model_from_type`)."""
    return _model_of(cfg.model.type)


def build_parameters(cfg: Config):
    """The model parameters, an instance of the model's parameter class (``DamageParameters`` for
    the damage models, ``CohesiveParameters`` for the cohesive crack): those given in
    ``[model.parameters]``, the rest the class's defaults."""
    return build_model(cfg).parameters(**dict(cfg.model.parameters))


def build_specimen(cfg: Config, experiment: ExperimentConfig | None = None):
    """The specimen object (NotchedBeam, DogBone or BarWithWeakZone) with the fields given; with an
    experiment, its ``specimen`` overrides applied (e.g. the size of one specimen of a series)."""
    options = dict(cfg.specimen.options)
    if experiment is not None:
        options.update(dict(experiment.specimen))
    return _specimen_class(cfg.specimen.type)(**options)


def _experiment_data(cfg: Config, exp: ExperimentConfig):
    from fracid.data import from_envelope, from_repeats, read_curve_csv, require_positive_force, with_std

    if exp.kind == "envelope":
        columns = [exp.mean_column, exp.lower_column, exp.upper_column]
    else:
        columns = list(exp.force_columns)
    curves = read_curve_csv(exp.file, control_column=exp.control_column, force_columns=columns,
                            control_unit_scale=exp.control_scale, force_unit_scale=exp.force_scale,
                            delimiter=exp.delimiter, decimal=exp.decimal,
                            backtrack_tolerance=exp.backtrack_tolerance_mm)
    if exp.quantity == "force":
        require_positive_force(curves)
    _check_control_scale(cfg, exp, max(float(np.max(curve.control)) for curve in curves))
    span = exp.control_range_mm
    if exp.kind == "repeats":
        return from_repeats(curves, exp.n_points, span, name=exp.name)
    if exp.kind == "envelope":
        return from_envelope(*curves, exp.n_points, span, name=exp.name)
    if exp.std is not None:
        return with_std(curves[0], exp.std * exp.force_scale, exp.n_points, span, name=exp.name)
    return with_std(curves[0], exp.relative_std, exp.n_points, span, name=exp.name, relative=True)


def _stacked_data(cfg: Config, experiments):
    from fracid.data import DataError, stack

    blocks = []
    for exp in experiments:
        try:
            block = _experiment_data(cfg, exp)
            blocks.append(block.weighted({exp.name: exp.weight}) if exp.weight != 1.0 else block)
        except DataError as err:
            raise ConfigError(f"{cfg.path}: experiments[{exp.index}] (file {exp.file}): {err}") from None
    return blocks[0] if len(blocks) == 1 else stack(*blocks)


#: Data whose control values go further than this many times the specimen's default target (a point
#: well past the peak for the configured parameters, the identified ones at their upper bounds), or
#: stop before 1/CONTROL_SCALE_LIMIT^2 of it (deep in the elastic range), are refused: the control is
#: almost surely in another unit (um declared as mm gives 1000 times, m as mm 1/1000), and every
#: forward run would trace a far too long path (a bar identification took minutes to fail).
CONTROL_SCALE_LIMIT = 30.0


def _check_control_scale(cfg: Config, exp: ExperimentConfig, reach: float) -> None:
    specimen = build_specimen(cfg, exp)
    if not hasattr(specimen, "default_target"):
        return
    params = build_parameters(cfg)
    candidates = [params]
    if cfg.identify is not None:
        for name, upper in zip(cfg.identify.parameters, cfg.identify.upper):
            try:
                candidates.append(params.replace(**{name: upper}))
            except ValueError:
                continue
    try:
        target = max(float(specimen.default_target(p)) for p in candidates)
    except (AttributeError, ValueError, TypeError):
        return
    where = f"{cfg.path}: experiments[{exp.index}].control_unit = {exp.control_unit!r}: the control values of {exp.file}"
    if target > 0 and reach > CONTROL_SCALE_LIMIT * target:
        raise ConfigError(
            f"{where} reach {reach:.6g} mm, {reach / target:.0f} times the {target:.3g} mm at which this "
            f"specimen has long failed with these parameters; check control_unit (values in um declared as mm "
            f"are 1000 times too large) and control_range")
    if target > 0 and reach < target / CONTROL_SCALE_LIMIT**2:
        raise ConfigError(
            f"{where} reach only {reach:.3g} mm, 1/{target / reach:.0f} of the {target:.3g} mm at which this "
            f"specimen has long failed with these parameters, deep in its elastic range; check control_unit "
            f"(values in m declared as mm are 1000 times too small)")


def build_experiment_data(cfg: Config, experiment: ExperimentConfig):
    """The data of one experiment (any role), weighted."""
    return _stacked_data(cfg, [experiment])


def build_data(cfg: Config):
    """The calibration data: one block per ``[[experiments]]`` entry with role "calibration",
    stacked in order, each block's covariance divided by its ``weight``.

    Raises
    ------
    ConfigError
        Wrapping any :class:`fracid.data.DataError` (bad rows, a range beyond the data, ...) with
        ``experiments[i]`` and the file named.
    """
    _require(cfg, "experiments")
    return _stacked_data(cfg, cfg.calibration)


def _operator(cfg: Config, experiments, data):
    from fracid.inverse.forward_operator import ForwardOperator, Observation

    identify = _require(cfg, "identify")
    if len(data.blocks) != len(experiments):
        raise ConfigError(f"{cfg.path}: experiments: the data hold {len(data.blocks)} blocks but the configuration "
                          f"has {len(experiments)} such [[experiments]] entries; build the data with build_data(cfg)")
    observations = []
    for exp, (name, start, stop) in zip(experiments, data.blocks):
        try:
            observations.append(Observation(build_specimen(cfg, exp), data.control[start:stop], quantity=exp.quantity,
                                            control=cfg.specimen.control, name=name,
                                            damage_threshold=exp.damage_threshold))
        except ValueError as err:
            raise ConfigError(f"{cfg.path}: experiments[{exp.index}].control_range = "
                              f"{_show(exp.control_range and list(exp.control_range))}: {err}") from None
    return ForwardOperator(observations, build_parameters(cfg), identify.parameters, model=build_model(cfg))


def build_operator(cfg: Config, data):
    """The forward operator: one Observation per calibration experiment, at the data's control points.

    ``data`` is the result of :func:`build_data` (its blocks line up with the calibration
    ``[[experiments]]``). Blocks of the same specimen share one forward run.
    """
    _require(cfg, "experiments")
    return _operator(cfg, cfg.calibration, data)


def build_held_out(cfg: Config) -> list:
    """(operator, data) per experiment with role "prediction": data predicted, not calibrated on."""
    held = [e for e in cfg.experiments if e.role == "prediction"]
    out = []
    for exp in held:
        data = _stacked_data(cfg, [exp])
        out.append((_operator(cfg, [exp], data), data))
    return out


def study_settings(cfg: Config) -> dict:
    """Keyword arguments of :func:`fracid.inverse.study.run_study` from ``[study]`` and ``[identify]``."""
    study = cfg.study
    return {**identify_settings(cfg), "starts": study.starts, "replicates": study.replicates,
            "noise_seed": study.seed, "tolerance": study.tolerance, "prior": study.prior}


def build_space(cfg: Config):
    """The parameter space of the KNN population: identified names, bounds, log flags."""
    from fracid.inverse.knn import ParameterSpace

    identify = _require(cfg, "identify")
    return ParameterSpace(identify.parameters, lower=list(identify.lower), upper=list(identify.upper),
                          log=tuple(name in identify.log for name in identify.parameters))


def identify_settings(cfg: Config) -> dict:
    """Keyword arguments of :func:`fracid.inverse.strategy.identify_data` (and ``identify``).

    ``n``, ``method``, ``seed``, ``k``, ``groups`` (``groups`` consecutive index arrays covering
    the n_y observations; :data:`DEFAULT_KALMAN_GROUPS` when not given), ``max_iterations``,
    ``tol`` and ``restart`` (only when ``identify`` accepts it; a non-default restart it cannot take raises ConfigError). Execution
    (executor, store, progress) is not configuration: add it at the call.
    """
    from fracid.inverse.strategy import identify

    settings = _require(cfg, "identify")
    knn, kalman = settings.knn, settings.kalman
    count = kalman.groups if kalman.groups is not None else min(DEFAULT_KALMAN_GROUPS, cfg.n_y)
    groups = [np.asarray(g) for g in np.array_split(np.arange(cfg.n_y), count)]
    out = {"n": knn.n, "method": knn.method, "seed": knn.seed, "k": knn.k, "groups": groups,
           "max_iterations": kalman.max_iterations, "tol": kalman.tol}
    if "restart" in inspect.signature(identify).parameters:
        out["restart"] = kalman.restart
    elif kalman.restart != "linearize":
        raise ConfigError(f"{cfg.path}: identify.kalman.restart = {kalman.restart!r}: this version of "
                          "fracid.inverse.strategy.identify cannot forward it; only 'linearize' (the default) is available")
    return out


def simulate_settings(cfg: Config) -> dict:
    """Keyword arguments of a forward run besides the specimen and parameters: ``control``,
    ``target``, ``stop_force_fraction``, ``damage_threshold`` and ``field_steps`` (the VTK steps, or
    ``"last"`` when none are listed), as taken by ``build_model(cfg).simulate``; for the damage
    models also ``regularization``, so that they are those of :func:`fracid.forward.simulate` too
    (drop it when calling the model's ``simulate``, which sets it itself)."""
    sim = cfg.simulate
    settings = {"control": cfg.specimen.control, "target": sim.target,
                "stop_force_fraction": sim.stop_force_fraction, "damage_threshold": sim.damage_threshold,
                "field_steps": list(cfg.output.vtk_steps) if cfg.output.vtk_steps else "last"}
    regularization = cfg.model.regularization
    return settings if regularization is None else {"regularization": regularization, **settings}
