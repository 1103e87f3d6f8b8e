"""Validation of the ``[identify]`` section: identified parameters, their bounds and log flags,
the inverse method and the sections of the registered methods' settings: ``[identify.knn]`` (with the
population limit), ``[identify.kalman]``, ``[identify.gauss-newton]`` and a registered method's own
``[identify.<name>]`` table, checked by the method's ``from_config`` (:func:`method_from_config`)."""

from __future__ import annotations

import dataclasses

from fracid.config.checker import Checker, bytes_text
from fracid.config.registry import model_of
from fracid.config.schema import (
    MAX_POPULATION,
    GaussNewtonConfig,
    IdentifyConfig,
    KalmanConfig,
    KnnConfig,
    ModelConfig,
)
from fracid.config.sections import range_text, valid_parameter
from fracid.config.vocabulary import (
    DEFAULT_INVERSE_METHOD,
    GAUSS_NEWTON_KEYS,
    IDENTIFY_KEYS,
    KALMAN_KEYS,
    KNN_KEYS,
    KNN_METHODS,
    RESTARTS,
    SECTION_METHODS,
)


def _check_plausible(ck: Checker, key: str, pair, name: str, bounds, units: dict) -> None:
    """Refuse a bound of ``name`` far outside its usual range (:func:`fracid.models.implausible`): the
    message names the parameter, the bound and the usual range, before any data are read (a kappa_i
    1000 times too large would otherwise make the data look 1000 times too short)."""
    from fracid.models import IMPLAUSIBLE_FACTOR, implausible

    for which, value in zip(("lower", "upper"), bounds):
        reason = implausible(name, value, units)
        if reason is not None:
            ck.fail(key, pair, f"the {which} bound is implausible for a quasi-brittle material: {reason} (more than "
                               f"{IMPLAUSIBLE_FACTOR:g} times outside it); check its unit and scale (e.g. kappa_i "
                               f"~ 1e-4 for concrete, about ft / E; E in MPa, c in mm^2)")


def read_identify(ck: Checker, raw, n_y: int | None, needed: bool, model: ModelConfig) -> IdentifyConfig | None:
    if raw is None:
        if needed:
            ck.missing("identify", "an [identify] section with parameters and [identify.bounds]")
        return None
    from fracid.inverse.methods.registry import METHODS

    ck.table("identify", raw, (*IDENTIFY_KEYS, *(name for name in METHODS if name not in IDENTIFY_KEYS)))
    cls = model_of(model.type, model.law).parameters
    names = _identified(ck, raw, cls, model)
    inverse = ck.choice("identify.method", raw.get("method", DEFAULT_INVERSE_METHOD), tuple(METHODS))
    lower, upper, log = _bounds(ck, raw, cls, names)
    identify = IdentifyConfig(parameters=names, lower=lower, upper=upper, log=log, knn=_knn(ck, raw, names, n_y),
                              kalman=_kalman(ck, raw, n_y), method=inverse,
                              gauss_newton=_gauss_newton(ck, raw, inverse), methods=_method_tables(ck, raw, inverse))
    try:
        method_from_config(identify, n_y)
    except (TypeError, ValueError) as err:
        ck.fail(f"identify.{inverse}", raw.get(inverse, inverse), str(err))
    return identify


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
    bounds = ck.table("identify.bounds", raw["bounds"], (*names, "log"))
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


def _knn(ck: Checker, raw, names: tuple, n_y: int | None) -> KnnConfig:
    """``[identify.knn]``, with the population limit."""
    raw_knn = ck.table("identify.knn", raw.get("knn", {}), KNN_KEYS)
    n = ck.integer("identify.knn.n", raw_knn.get("n", 64), "must be an integer >= 2", lambda v: v >= 2)
    method = ck.choice("identify.knn.method", raw_knn.get("method", "sobol"), KNN_METHODS)
    seed = ck.integer("identify.knn.seed", raw_knn.get("seed", 0), "must be an integer >= 0", lambda v: v >= 0)
    knn = KnnConfig(n=n, method=method, k=5, seed=seed)
    population = knn.population(len(names))
    how = f"n**p = {n}**{len(names)}" if method == "grid" else f"n = {n}"
    if population > MAX_POPULATION:
        values = population * (len(names) + (n_y or 0))
        ck.fail("identify.knn.n", n, f"the population of {population:,} points ({how}, method {method!r}) is above the "
                                     f"limit of {MAX_POPULATION:,}: each point is one forward run (seconds to minutes "
                                     f"each), and the points and their outputs alone take {values:,} x 8 bytes = "
                                     f"{bytes_text(8.0 * values)} (p = {len(names)} parameters + n_y = {n_y or 0} outputs "
                                     "per point); a few hundred points are enough to start the Kalman filter")
    k = ck.integer("identify.knn.k" + ("" if "k" in raw_knn else " (default)"), raw_knn.get("k", 5),
                   f"must be an integer with 1 <= k <= the population size {population} ({how}, method {method!r})",
                   lambda v: 1 <= v <= population)
    return dataclasses.replace(knn, k=k)


def _kalman(ck: Checker, raw, n_y: int | None) -> KalmanConfig:
    """``[identify.kalman]``."""
    raw_kf = ck.table("identify.kalman", raw.get("kalman", {}), KALMAN_KEYS)
    groups = None
    if "groups" in raw_kf:
        top = n_y if n_y else None
        allowed = (f"must be an integer with 1 <= groups <= n_y = {top} (the total n_points of the experiments)"
                   if top else "must be an integer >= 1")
        groups = ck.integer("identify.kalman.groups", raw_kf["groups"], allowed,
                            lambda v: v >= 1 and (top is None or v <= top))
    return KalmanConfig(
        groups=groups,
        max_iterations=ck.integer("identify.kalman.max_iterations", raw_kf.get("max_iterations", 10),
                                  "must be an integer >= 1", lambda v: v >= 1),
        tol=ck.number("identify.kalman.tol", raw_kf.get("tol", 0.01), "must be a number > 0 [standard deviations]",
                      lambda v: v > 0),
        restart=ck.choice("identify.kalman.restart", raw_kf.get("restart", "linearize"), RESTARTS),
        max_starts=ck.integer("identify.kalman.max_starts", raw_kf.get("max_starts", 3),
                              "must be an integer >= 1 (starts of the filter in all)", lambda v: v >= 1),
    )


def _gauss_newton(ck: Checker, raw, inverse: str) -> GaussNewtonConfig:
    """``[identify.gauss-newton]``."""
    raw_gn = ck.table("identify.gauss-newton", raw.get("gauss-newton", {}), GAUSS_NEWTON_KEYS)
    if raw_gn:
        _warn_if_unused(ck, "gauss-newton", inverse)
    return GaussNewtonConfig(
        max_iterations=ck.integer("identify.gauss-newton.max_iterations", raw_gn.get("max_iterations", 20),
                                  "must be an integer >= 1 (linearisations at most)", lambda v: v >= 1),
        tol=ck.number("identify.gauss-newton.tol", raw_gn.get("tol", 0.01),
                      "must be a number > 0 [standard deviations]", lambda v: v > 0),
    )


def _method_tables(ck: Checker, raw, inverse: str) -> dict:
    """The registered methods' own tables ``[identify.<name>]``, as read (the method's ``from_config``
    checks its own); a warning for one of a method not chosen."""
    from fracid.inverse.methods.registry import METHODS

    methods = {}
    for name in (name for name in METHODS if name in raw):
        if not isinstance(raw[name], dict):
            ck.fail(f"identify.{name}", raw[name], f"must be a table (section) of the settings of the method {name!r}")
        methods[name] = dict(raw[name])
        _warn_if_unused(ck, name, inverse)
    return methods


def _warn_if_unused(ck: Checker, section: str, inverse: str) -> None:
    """Warn that ``[identify.<section>]`` is given for a method other than the chosen ``inverse``: a built-in
    section is read by its method of :data:`~fracid.config.vocabulary.SECTION_METHODS`, a registered method's
    own table by the method of its name."""
    method = SECTION_METHODS.get(section, section)
    if method != inverse:
        ck.warn(f"[identify.{section}] is given but identify.method = {inverse!r}: its settings are not used "
                f"(set method = \"{method}\" to use them)")


def method_from_config(identify: IdentifyConfig, n_y: int | None):
    """The inverse method of a validated ``[identify]``: ``METHODS[identify.method].from_config(identify,
    n_y)``; a method class without ``from_config`` is built with its defaults (and takes no table).

    Raises
    ------
    ValueError, TypeError
        The method's refusal of its settings (the message names the setting and what is allowed).
    """
    from fracid.inverse.methods.registry import METHODS

    cls = METHODS[identify.method]
    from_config = getattr(cls, "from_config", None)  # an optional hook of the method
    if from_config is not None:
        return from_config(identify, n_y)
    if identify.methods.get(identify.method):
        raise ValueError(f"the method {identify.method!r} takes no settings from the configuration")
    return cls()
