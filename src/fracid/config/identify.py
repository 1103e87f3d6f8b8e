"""Validation of the ``[identify]`` section: identified parameters, their bounds and log flags,
the inverse method, ``[identify.knn]`` (with the population limit), ``[identify.kalman]`` and
``[identify.gauss-newton]``."""

from __future__ import annotations

import dataclasses

from fracid.config.checker import _bytes, _Checker
from fracid.config.registry import _model_of
from fracid.config.schema import (
    _GAUSS_NEWTON_KEYS,
    _IDENTIFY_KEYS,
    _KALMAN_KEYS,
    _KNN_KEYS,
    _METHODS,
    _RESTARTS,
    DEFAULT_INVERSE_METHOD,
    MAX_POPULATION,
    GaussNewtonConfig,
    IdentifyConfig,
    KalmanConfig,
    KnnConfig,
    ModelConfig,
)
from fracid.config.sections import _range_text, _valid_parameter


def _check_plausible(ck: _Checker, key: str, pair, name: str, bounds, units: dict) -> None:
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
    from fracid.inverse.methods import METHODS

    inverse = ck.choice("identify.method", raw.get("method", DEFAULT_INVERSE_METHOD), tuple(METHODS))

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
        _check_plausible(ck, key, pair, name, (lo, hi), cls.units())
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
        max_starts=ck.integer("identify.kalman.max_starts", raw_kf.get("max_starts", 3),
                              "must be an integer >= 1 (starts of the filter in all)", lambda v: v >= 1),
    )
    raw_gn = ck.table("identify.gauss-newton", raw.get("gauss-newton", {}), _GAUSS_NEWTON_KEYS)
    gauss_newton = GaussNewtonConfig(
        max_iterations=ck.integer("identify.gauss-newton.max_iterations", raw_gn.get("max_iterations", 20),
                                  "must be an integer >= 1 (linearisations at most)", lambda v: v >= 1),
        tol=ck.number("identify.gauss-newton.tol", raw_gn.get("tol", 0.01),
                      "must be a number > 0 [standard deviations]", lambda v: v > 0),
    )
    if raw_gn and inverse != "knn-gauss-newton":
        ck.warn(f"[identify.gauss-newton] is given but identify.method = {inverse!r}: its settings are not used "
                "(set method = \"knn-gauss-newton\" to use them)")
    return IdentifyConfig(parameters=names, lower=tuple(lower), upper=tuple(upper), log=log, knn=knn, kalman=kalman,
                          method=inverse, gauss_newton=gauss_newton)
