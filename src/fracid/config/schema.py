"""The schema of a TOML configuration, its vocabularies and limits, and the frozen dataclasses of a
validated one (:class:`Config` and its sections).

Schema
------
Every key, with its default, unit, allowed values and meaning, is in the configuration reference
(:func:`fracid.config.reference.entries`, rendered in docs/reference/configuration.md), built from where each key
is declared: :mod:`fracid.config.vocabulary` (the sections without a class of their own), the specimens' and
models' classes, the experiment kinds (:mod:`fracid.inverse.experiments.registry`), the inverse methods' tables
(:func:`fracid.inverse.methods.registry.table_keys`) and the error terms (:mod:`fracid.inverse.likelihood.settings`).
What the reference does not say:

- ``[[experiments]]`` and ``[identify]`` are required for identification (``purpose="identify"``) and optional for
  a forward analysis (``purpose="simulate"``); when present they are always validated. Every other key is optional
  unless the reference says *required*.
- The ``[[experiments]]`` blocks are stacked in their order into the data vector; blocks of the same specimen (the
  same ``specimen`` overrides) share one forward run; a derived block names a field block of the same file.
- ``[identify]`` allows every table a registered method reads (``[identify.<table>]``); the chosen method checks
  its own, a table it does not read is checked by a method that reads it and warned about.
- Relative paths (data files, a mesh file, ``[output] directory``) start from the configuration file's directory
  (standard input: the working directory).

.. code-block:: toml

    [model]
    type = "gradient-damage"
    [model.parameters]
    c = 9.0

    [specimen]
    type = "notched-beam"
    h_fine = 1.0

    [[experiments]]
    file = "load_cmod.csv"
    control_column = "cmod_mm"
    control_unit = "mm"
    force_unit = "N"
    kind = "envelope"
    mean_column = "load_mean_N"
    lower_column = "load_min_N"
    upper_column = "load_max_N"
    n_points = 40

    [identify]
    parameters = ["kappa_i", "beta", "c"]
    [identify.bounds]
    kappa_i = [4e-5, 1.2e-4]
    beta = [100.0, 2000.0]
    c = [1.0, 30.0]
    log = ["beta"]
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from fracid.config.registry import model_of
from fracid.models.registry import DEFAULT_MODEL_TYPE
from fracid.config.vocabulary import DEFAULT_INVERSE_METHOD, SIMULATE, STUDY
from fracid.inverse.sampling.posterior import PosteriorSettings


class ConfigError(ValueError):
    """An invalid configuration: the message names the file, the dotted key, the value and what is allowed."""


# ------------------------------------------------------------------------------ size limits
# A configuration asking for more than a workstation can hold is refused when it is loaded, with
# the estimate, instead of failing (or swapping for hours) in the middle of a study.

# The largest KNN population (MAX_POPULATION) is the KNN settings' (fracid.inverse.methods.knn_settings), checked
# by the methods that read [identify.knn]; the limits of a forward run's memory (MAX_BAR_ELEMENTS,
# BAR_BYTES_PER_ELEMENT, MAX_UNKNOWNS, BYTES_PER_UNKNOWN) are the specimens' (fracid.specimens.protocol).


# ------------------------------------------------------------------------------ validated config


@dataclass(frozen=True)
class ModelConfig:
    """``[model]``: the model type, its law and the parameter values given (the rest are defaults)."""

    type: str = DEFAULT_MODEL_TYPE
    parameters: tuple = ()  # ((name, value), ...) as given
    law: str | None = None  # a law of the model by name (fracid.models.model_laws); None: its default

    @property
    def regularization(self) -> str | None:
        """The ``regularization`` argument of :func:`fracid.models.forward.simulate` for the damage models
        (``"gradient"``, ``"local"``); None for a model that has none (e.g. the cohesive crack)."""
        return model_of(self.type, self.law).regularization


@dataclass(frozen=True)
class SpecimenConfig:
    """``[specimen]``: type, control (resolved to the default when omitted) and the dataclass fields given."""

    type: str
    control: str
    options: tuple = ()  # ((field, value), ...) as given, type-checked


@dataclass(frozen=True)
class IdentifyConfig:
    """``[identify]``: identified parameters, their bounds and log flags, the inverse method (a key of
    :data:`fracid.inverse.methods.registry.METHODS`) and the tables of the methods' settings."""

    parameters: tuple
    lower: tuple
    upper: tuple
    log: tuple = ()  # names sampled in log scale
    method: str = DEFAULT_INVERSE_METHOD
    #: the tables of the methods' settings ``[identify.<table>]`` given, by name, as read (the methods that
    #: read them check them: :func:`fracid.config.identify.method_from_config`)
    tables: dict = field(default_factory=dict)
    #: the error terms added to the data covariance (None: "off"): a
    #: :class:`~fracid.inverse.likelihood.settings.DiscretisationError` and a
    #: :class:`~fracid.inverse.likelihood.settings.ModelError`
    discretisation_error: object = None
    model_error: object = None


@dataclass(frozen=True)
class OutputConfig:
    """``[output]``: ``directory`` absolute (resolved against the config file)."""

    directory: Path
    vtk_steps: tuple = ()


@dataclass(frozen=True)
class SimulateConfig:
    """``[simulate]``: target [mm] (None: the specimen's), stop_force_fraction, damage_threshold."""

    target: float | None = None
    stop_force_fraction: float = SIMULATE["stop_force_fraction"].default
    damage_threshold: float = SIMULATE["damage_threshold"].default


@dataclass(frozen=True)
class StudyConfig:
    """``[study]``: multi-start points, noisy replicates, their seed, the tolerance of the verdict, the
    Kalman prior, and whether ``fracid study`` samples the posterior (its verdict then reads it)."""

    # the defaults are the vocabulary's (fracid.config.vocabulary.STUDY), where each key is described
    starts: int = STUDY["starts"].default
    replicates: int = STUDY["replicates"].default
    seed: int = STUDY["seed"].default
    tolerance: float = STUDY["tolerance"].default
    prior: str = STUDY["prior"].default
    posterior: bool = STUDY["posterior"].default


#: ``[posterior]``: the sampler's own settings object (its defaults are the section's; the section's checker
#: gives the messages, so that building it never raises)
PosteriorConfig = PosteriorSettings


@dataclass(frozen=True)
class Config:
    """A validated configuration (see the module docstring for the schema)."""

    path: Path
    purpose: str
    model: ModelConfig
    specimen: SpecimenConfig
    experiments: tuple  # of the kinds' validated blocks (fracid.inverse.experiments); empty if none given
    identify: IdentifyConfig | None
    output: OutputConfig
    simulate: SimulateConfig
    study: StudyConfig = StudyConfig()
    posterior: PosteriorConfig = PosteriorConfig()
    warnings: tuple = ()  # of str: valid but probably unintended settings, for the user to read

    @property
    def calibration(self) -> tuple:
        """The experiments used for calibration (role "calibration")."""
        return tuple(e for e in self.experiments if e.role == "calibration")

    @property
    def n_y(self) -> int:
        """Number of measured values used for calibration (sum of their blocks' n_points)."""
        return sum(e.n_points for e in self.calibration)
