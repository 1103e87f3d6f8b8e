"""TOML configuration of a study, validated when it is loaded.

:func:`load_config` reads a TOML file (stdlib ``tomllib``) and checks every key before anything
runs: unknown keys are rejected at every level, every value is type- and range-checked, data files
and their columns must exist, and the specimen and the model parameters are built once to run
their own validation. Every problem raises :class:`ConfigError` (a ``ValueError``) with a
one-paragraph message naming the file, the dotted key (``identify.bounds.c``,
``experiments[0].control_unit``), the value given and what is allowed. Relative file paths are
resolved against the directory of the configuration file.

The builders (:func:`build_parameters`, :func:`build_specimen`, :func:`build_data`,
:func:`build_operator`, :func:`build_view_coordinates`, :func:`build_space`, :func:`build_method`,
:func:`simulate_settings`,
:func:`posterior_settings`, :func:`error_terms`)
are pure functions of the validated :class:`Config`.

Units: N, mm, MPa; ``c`` in mm^2. Data files are scaled to mm and N by the units given.

Limits: a configuration beyond what a workstation holds is refused with the estimate and the limit
(the KNN method's :data:`~fracid.inverse.methods.knn_settings.MAX_POPULATION` points, the specimens'
:data:`~fracid.specimens.protocol.MAX_BAR_ELEMENTS` bar elements and
:data:`~fracid.specimens.protocol.MAX_UNKNOWNS` unknowns of a 2D mesh counted from the geometry).

Warnings: valid settings that are probably not meant (``relative_std`` above 1, process-zone
elements larger than the internal length l = sqrt(2 c)) are returned in ``Config.warnings``.

The package's modules, each importing only those listed before it: :mod:`~fracid.config.vocabulary`
(the keys and values of each section), :mod:`~fracid.config.registry` (the model and specimen types),
:mod:`~fracid.config.schema` (the schema and the validated dataclasses), :mod:`~fracid.config.checker`
(TOML reading and value checks), :mod:`~fracid.config.sections`, :mod:`~fracid.config.experiments` (each
``[[experiments]]`` block read by its kind: :mod:`fracid.inverse.experiments.registry`),
:mod:`~fracid.config.identify` and :mod:`~fracid.config.posterior` (one validator per section),
:mod:`~fracid.config.loading` (:func:`load_config`) and :mod:`~fracid.config.builders`.

Example
-------
>>> from fracid.config import load_config, build_data, build_operator, build_space, build_method
>>> from fracid.inverse.methods.strategy import identify_data
>>> cfg = load_config("study.toml")                                   # doctest: +SKIP
>>> data = build_data(cfg)                                            # doctest: +SKIP
>>> result = identify_data(build_operator(cfg, data), data, build_space(cfg),
...                        method=build_method(cfg))                  # doctest: +SKIP

The configuration reads registries only (specimens, models, laws, experiment kinds, methods): it names no
kind. May import every package but the command.
"""

from __future__ import annotations

from fracid.config.builders import (
    CONTROL_SCALE_LIMIT,
    build_data,
    build_experiment_data,
    build_held_out,
    build_method,
    build_model,
    build_operator,
    build_parameters,
    build_space,
    build_specimen,
    build_view_coordinates,
    error_terms,
    posterior_settings,
    simulate_settings,
    study_settings,
)
from fracid.config.loading import load_config
from fracid.config.schema import (
    Config,
    ConfigError,
    IdentifyConfig,
    ModelConfig,
    OutputConfig,
    PosteriorConfig,
    SimulateConfig,
    SpecimenConfig,
    StudyConfig,
)

__all__ = [
    "Config",
    "ConfigError",
    "IdentifyConfig",
    "ModelConfig",
    "OutputConfig",
    "SimulateConfig",
    "SpecimenConfig",
    "build_data",
    "build_model",
    "build_operator",
    "build_parameters",
    "build_space",
    "build_method",
    "build_specimen",
    "build_view_coordinates",
    "load_config",
    "simulate_settings",
    "build_held_out",
    "build_experiment_data",
    "study_settings",
    "StudyConfig",
    "posterior_settings",
    "error_terms",
    "PosteriorConfig",
    # the limits and constants of the docstring
    "CONTROL_SCALE_LIMIT",
]
