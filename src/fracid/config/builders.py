"""The builders: pure functions of a validated :class:`~fracid.config.schema.Config` that make the
model, its parameters, the specimens, the data, the forward operator, the parameter space and the
keyword arguments of the identification, the study and a forward run."""

from __future__ import annotations

import contextlib

import numpy as np


from fracid.config.checker import show
from fracid.config.registry import model_of, model_parameters, specimen_class
from fracid.config.schema import Config, ConfigError
from fracid.inverse.experiments.registry import BuildContext, experiment_kind, source_block
from fracid.settings.checks import SettingError


def _require(cfg: Config, section: str):
    value = getattr(cfg, section)
    if not value:
        what = "[[experiments]] blocks" if section == "experiments" else f"an [{section}] section"
        raise ConfigError(f"{cfg.path}: {section} is missing (no value given); identification needs {what}")
    return value


def build_model(cfg: Config):
    """The forward model of ``[model] type`` (:func:`fracid.models.model_from_type`)."""
    return model_of(cfg.model.type, cfg.model.law)


def build_parameters(cfg: Config):
    """The model parameters, an instance of the model's parameter class (``DamageParameters`` for
    the damage models, ``CohesiveParameters`` for the cohesive crack): those given in
    ``[model.parameters]``, the rest the class's defaults."""
    return model_parameters(cfg.model)


def build_specimen(cfg: Config, experiment=None):
    """The specimen object of ``[specimen] type`` (a class of :data:`fracid.specimens.SPECIMENS`) with the
    fields given; with an experiment, its ``specimen`` overrides applied (e.g. the size of one specimen of
    a series)."""
    options = dict(cfg.specimen.options)
    if experiment is not None:
        options.update(dict(experiment.specimen))
    return specimen_class(cfg.specimen.type)(**options)


def _build_context(cfg: Config, exp) -> BuildContext:
    """What the experiment's kind builds its data and observation with: its specimen, the runs' control, the
    check of a curve's control reach, and the product of a source block (for a derived kind)."""
    return BuildContext(specimen=build_specimen(cfg, exp), control=cfg.specimen.control,
                        check_reach=lambda e, reach: _check_control_scale(cfg, e, reach),
                        source_block=lambda source: source_block(source, _build_context(cfg, source)))


def _stacked_data(cfg: Config, experiments):
    from fracid.data import DataError, stack

    blocks = []
    for exp in experiments:
        try:
            block = experiment_kind(exp).data(exp, _build_context(cfg, exp))
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


def _check_control_scale(cfg: Config, exp, reach: float) -> None:
    """Refuse data whose control reaches far beyond, or stops far short of, the control at which the
    specimen has long failed: blamed on ``control_unit`` unless a bound or a parameter value explains it."""
    specimen, model = build_specimen(cfg, exp), build_model(cfg)
    params = build_parameters(cfg)
    candidates = {"[model.parameters]": params}
    if cfg.identify is not None:
        for name, upper in zip(cfg.identify.parameters, cfg.identify.upper):
            with contextlib.suppress(ValueError):
                candidates[f"identify.bounds.{name} (upper bound {upper:g})"] = params.replace(**{name: upper})
    try:
        targets = {label: float(model.default_target(specimen, p)) for label, p in candidates.items()}
    except (AttributeError, ValueError, TypeError):
        return
    target = max(targets.values())
    where = f"{cfg.path}: experiments[{exp.index}].control_unit = {exp.control_unit!r}: the control values of {exp.file}"
    if target > 0 and reach > CONTROL_SCALE_LIMIT * target:
        raise ConfigError(
            f"{where} reach {reach:.6g} mm, {reach / target:.0f} times the {target:.3g} mm at which this "
            f"specimen has long failed with these parameters; check control_unit (values in um declared as mm "
            f"are 1000 times too large) and control_range")
    if target > 0 and reach < target / CONTROL_SCALE_LIMIT**2:
        _blame_short_reach(cfg, exp, reach, targets, params)
        raise ConfigError(
            f"{where} reach only {reach:.3g} mm, 1/{target / reach:.0f} of the {target:.3g} mm at which this "
            f"specimen has long failed with these parameters, deep in its elastic range; check control_unit "
            f"(values in m declared as mm are 1000 times too small){_unusual_values(cfg, params)}")


def _unusual_values(cfg: Config, params) -> str:
    """``"; or model.parameters.kappa_i = 0.009 (usual: ...)"`` for the given values outside their usual range."""
    from fracid.models import usual_range_text, usual_ranges

    usual = usual_ranges()
    unusual = [f"model.parameters.{name} = {value:g} (usual: {usual_range_text(name)})"
               for name, value in dict(cfg.model.parameters).items()
               if name in usual and not usual[name][0] <= value <= usual[name][1]]
    return "; or " + ", ".join(unusual) if unusual else ""


def _blame_short_reach(cfg: Config, exp, reach: float, targets: dict, params) -> None:
    """When data stop deep in the elastic range of some parameters: a ConfigError naming the parameter value
    or the upper bound that puts failure so far out, if the data are plausible for the others."""
    from fracid.models import implausible, usual_range_text

    for name in dict(cfg.model.parameters):
        why = implausible(name, float(getattr(params, name, float("nan"))))
        if why is not None:
            raise ConfigError(f"{cfg.path}: model.parameters.{name}: {why}; the data of experiments[{exp.index}] "
                              f"({exp.file}) end at {reach:.3g} mm, deep in the elastic range such a value gives. "
                              "Check the value's unit and scale")
    if reach * CONTROL_SCALE_LIMIT**2 < targets["[model.parameters]"]:
        return  # the given parameters too: the data's unit is the likelier cause
    label, target = max(targets.items(), key=lambda item: item[1])
    name = label.split()[0].rsplit(".", 1)[-1]
    raise ConfigError(f"{cfg.path}: {label}: with it this specimen fails only at a control of {target:.3g} mm, "
                      f"{target / reach:.0f} times the {reach:.3g} mm that the data of experiments[{exp.index}] "
                      f"reach; the bound is implausible (usual: {usual_range_text(name) or 'see the README'}). "
                      "Lower it, or check its unit")


def build_experiment_data(cfg: Config, experiment):
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
    from fracid.inverse.core.forward_operator import ForwardOperator

    identify = _require(cfg, "identify")
    if len(data.blocks) != len(experiments):
        raise ConfigError(f"{cfg.path}: experiments: the data hold {len(data.blocks)} blocks but the configuration "
                          f"has {len(experiments)} such [[experiments]] entries; build the data with build_data(cfg)")
    observations = [_observation(cfg, exp, name, data.control[start:stop])
                    for exp, (name, start, stop) in zip(experiments, data.blocks)]
    return ForwardOperator(observations, build_parameters(cfg), identify.parameters, model=build_model(cfg))


def _observation(cfg: Config, exp, name: str, control):
    """The observation kind of an experiment (its kind's), at its block's control values [mm]."""
    try:
        return experiment_kind(exp).observation(exp, _build_context(cfg, exp), name, control)
    except SettingError as err:
        raise ConfigError(f"{cfg.path}: experiments[{exp.index}].{err.key} = {show(err.value)}: {err.allowed}") from None
    except ValueError as err:
        raise ConfigError(f"{cfg.path}: experiments[{exp.index}]: {err}") from None


def build_operator(cfg: Config, data):
    """The forward operator: one Observation per calibration experiment, at the data's control points.

    ``data`` is the result of :func:`build_data` (its blocks line up with the calibration
    ``[[experiments]]``). Blocks of the same specimen share one forward run.
    """
    _require(cfg, "experiments")
    return _operator(cfg, cfg.calibration, data)


def build_view_coordinates(cfg: Config, operator, data) -> dict:
    """The coordinates of every calibration block whose kind names a report view, by block name, for
    :func:`fracid.report.views.block_views`: its observation's ``coordinates()`` (a field's frame, component,
    point, x, y [mm], control [mm]), ``view`` (the kind's view name) and ``covariance`` (the block's data
    covariance, the noise its residual is measured against).

    ``operator`` and ``data`` are :func:`build_operator`'s and :func:`build_data`'s (their blocks line up with
    the calibration ``[[experiments]]``).
    """
    coordinates = {}
    for exp, observation, (name, start, stop) in zip(cfg.calibration, operator.observations, data.blocks):
        view = experiment_kind(exp).view
        if view is not None:
            extras = exp.view_extras(build_specimen(cfg)) if hasattr(exp, "view_extras") else {}
            coordinates[name] = {**observation.coordinates(), **getattr(observation, "view_extras", dict)(), **extras,
                                 "view": view, "covariance": data.covariance.take(np.arange(start, stop))}
    return coordinates


def build_held_out(cfg: Config) -> list:
    """(operator, data) per experiment with role "prediction": data predicted, not calibrated on."""
    held = [e for e in cfg.experiments if e.role == "prediction"]
    out = []
    for exp in held:
        data = _stacked_data(cfg, [exp])
        out.append((_operator(cfg, [exp], data), data))
    return out


def study_settings(cfg: Config) -> dict:
    """The checks of ``[study]`` as keyword arguments of :meth:`fracid.inverse.studies.study.StudySettings.replace`
    (``starts``, ``replicates``, ``noise_seed``, ``tolerance``, ``prior``; ``posterior``: the
    :func:`posterior_settings` of ``[posterior]`` when ``[study] posterior = true``, None otherwise;
    ``error_terms``: those of ``[identify]``, an :class:`~fracid.inverse.likelihood.terms.ErrorTerms` or None). The
    inverse method is :func:`build_method`'s: ``StudySettings(method=build_method(cfg)).replace(**study_settings(cfg))``."""
    from fracid.inverse.likelihood.terms import ErrorTerms

    study = cfg.study
    return {"starts": study.starts, "replicates": study.replicates, "noise_seed": study.seed,
            "tolerance": study.tolerance, "prior": study.prior,
            "posterior": posterior_settings(cfg) if study.posterior else None,
            "error_terms": ErrorTerms.of(**error_terms(cfg)) if cfg.identify is not None else None}


def posterior_settings(cfg: Config):
    """The :class:`~fracid.inverse.sampling.posterior.PosteriorSettings` of ``[posterior]`` (its defaults when the
    section is absent)."""
    return cfg.posterior


def build_space(cfg: Config):
    """The parameter space of the identification: identified names, bounds, log flags."""
    from fracid.inverse.core.space import ParameterSpace

    identify = _require(cfg, "identify")
    return ParameterSpace(identify.parameters, lower=list(identify.lower), upper=list(identify.upper),
                          log=tuple(name in identify.log for name in identify.parameters))


def build_method(cfg: Config):
    """The configured inverse method: the class that ``[identify] method`` names in
    :data:`fracid.inverse.methods.registry.METHODS`, built by its ``from_config(tables, context)`` from the tables of
    the validated ``[identify]`` it reads (``identify.tables``; :func:`fracid.config.identify.method_from_config`).
    Give it to :func:`fracid.inverse.methods.strategy.identify_data` as ``method=``.

    Raises
    ------
    ConfigError
        When the method refuses its settings (checked already when the configuration was loaded).
    """
    from fracid.config.identify import method_from_config

    identify = _require(cfg, "identify")
    try:
        return method_from_config(identify, cfg.n_y)
    except SettingError as err:
        raise ConfigError(f"{cfg.path}: identify.{err.key} = {show(err.value)}: {err.allowed}") from None
    except (TypeError, ValueError) as err:
        raise ConfigError(f"{cfg.path}: identify.{identify.method}: {err}") from None


def error_terms(cfg: Config) -> dict:
    """The error terms of ``[identify]`` as keyword arguments of
    :func:`fracid.inverse.methods.strategy.identify_data`: ``discretisation_error`` and ``model_error`` (settings
    objects, or None when off)."""
    identify = _require(cfg, "identify")
    return {"discretisation_error": identify.discretisation_error, "model_error": identify.model_error}


def simulate_settings(cfg: Config) -> dict:
    """Keyword arguments of a forward run besides the specimen and parameters: ``control``,
    ``target``, ``stop_force_fraction``, ``damage_threshold`` and ``field_steps`` (the VTK steps, or
    ``"last"`` when none are listed), as taken by ``build_model(cfg).simulate``; for the damage
    models also ``regularization``, so that they are those of :func:`fracid.models.forward.simulate` too
    (drop it when calling the model's ``simulate``, which sets it itself)."""
    sim = cfg.simulate
    settings = {"control": cfg.specimen.control, "target": sim.target,
                "stop_force_fraction": sim.stop_force_fraction, "damage_threshold": sim.damage_threshold,
                "field_steps": list(cfg.output.vtk_steps) if cfg.output.vtk_steps else "last"}
    regularization = cfg.model.regularization
    return settings if regularization is None else {"regularization": regularization, **settings}
