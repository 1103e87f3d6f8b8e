"""``fracid compare CONFIG [--models M ...]``: the models that run on the configuration's specimen, each identified
on the same data with its own parameters and bounds, ranked by log evidence
(:func:`fracid.inverse.studies.model_comparison.compare`).

The configuration's own model keeps its ``[identify]`` parameters and bounds (and its ``[model] law``); every
other model gets what ``fracid init`` writes for it (:func:`fracid.cli.init.default_identification`: its
usual parameters, bounds a factor 3 around their values), its other parameters the configuration's values
where the names are shared (E, nu, and kappa_i, beta, c ... between the damage models), its class's defaults
elsewhere. Every model is identified with ``[identify] method`` and its settings, and sampled with
``[posterior]`` (:data:`DEFAULT_POSTERIOR` when the configuration leaves it at its defaults; ``--samples``,
``--rounds`` override). Writes compare.json, report.html and figures/compare_*.png
(:func:`fracid.report.compare.write_compare`) beside the run store.
"""

from __future__ import annotations

import sys
from dataclasses import replace
from pathlib import Path

from fracid.cli.common import command_executor, load, out_dir, provenance, say, warn, working_in, wrote
from fracid.inverse.sampling.posterior import PosteriorSettings

#: the sampler's settings when the configuration's [posterior] states nothing but the defaults (which are
#: sized for credible intervals, up to 2000 runs a model): the evidence of a model needs fewer draws
DEFAULT_POSTERIOR = PosteriorSettings(samples_per_round=60, max_rounds=4, target_ess=200.0)


def add_parser(sub, parents) -> None:
    """The ``compare`` subcommand's arguments."""
    p = sub.add_parser("compare", parents=[parents.stored],
                       help="identify every model that runs on the specimen and rank them by log evidence")
    p.add_argument("config", type=Path, help="TOML configuration file")
    p.add_argument("--models", nargs="+", metavar="MODEL",
                   help="[model] types to compare (default: every model that runs on the specimen)")
    p.add_argument("--samples", type=int, help="posterior draws per round (default: [posterior] samples_per_round)")
    p.add_argument("--rounds", type=int, help="posterior rounds at most (default: [posterior] max_rounds)")
    p.set_defaults(run=run_compare)


def model_types(cfg, named=None) -> tuple[list, list]:
    """The model types to compare: ``named`` (every one checked) or all of :data:`fracid.models.MODEL_TYPES`,
    those that run on every calibration specimen of ``cfg``; and (type, why not) of those left out.

    Raises
    ------
    UsageError
        For a name that is not a model type (the allowed ones named) or a named model that does not run on the
        specimen (exit 2).
    """
    from fracid.config import build_specimen
    from fracid.runtime.exits import UsageError
    from fracid.models.protocol import declared
    from fracid.models import MODEL_TYPES

    unknown = [name for name in named or () if name not in MODEL_TYPES]
    if unknown:
        raise UsageError(f"--models {' '.join(unknown)}: not a model type; choose among {', '.join(MODEL_TYPES)}")
    kept, left_out = [], []
    specimens = [build_specimen(cfg, exp) for exp in cfg.calibration]
    for name in dict.fromkeys(named or MODEL_TYPES):
        why = next(filter(None, (declared(MODEL_TYPES[name]()).why_not(s) for s in specimens)), None)
        if why is not None and named:
            raise UsageError(f"--models {name}: the {name} model does not run on the {cfg.specimen.type} "
                             f"specimen ({why}); `fracid init --list` gives the pairs that run")
        if why is None:
            kept.append(name)
        else:
            left_out.append((name, why))
    return kept, left_out


def model_config(cfg, kind: str):
    """``cfg`` for model type ``kind``: the configuration itself for its own model; for another, ``[model]`` of
    that type with the shared parameter values and ``[identify]`` of ``fracid init`` (module docstring)."""
    from fracid.cli.init import default_identification
    from fracid.config import build_parameters
    from fracid.config.schema import ModelConfig
    from fracid.models import model_from_type

    if kind == cfg.model.type:
        return cfg
    given = build_parameters(cfg)
    cls = model_from_type(kind).parameters
    shared = tuple((name, getattr(given, name)) for name in cls.names() if hasattr(given, name))
    names, bounds, log = default_identification(kind, cls(**dict(shared)))
    identify = replace(cfg.identify, parameters=tuple(names), lower=tuple(bounds[n][0] for n in names),
                       upper=tuple(bounds[n][1] for n in names), log=tuple(log))
    return replace(cfg, model=ModelConfig(type=kind, parameters=shared), identify=identify)


def _contenders(args, cfg, data, kinds):
    """A Contender per model type (those whose set-up fails are said and left out)."""
    from fracid.config import build_operator, build_space
    from fracid.inverse.studies.model_comparison import Contender

    contenders, failures = [], {}
    for kind in kinds:
        try:
            own = model_config(cfg, kind)
            contenders.append(Contender(kind, build_operator(own, data), build_space(own)))
        except (TypeError, ValueError) as err:
            failures[kind] = f"could not be set up: {err}"
            continue
        space = contenders[-1].space
        say(args, f"{kind}: " + ", ".join(f"{n} in [{lo:g}, {hi:g}]" + (" (log)" if lg else "")
                                         for n, lo, hi, lg in zip(space.names, space.lower, space.upper, space.log)))
    return contenders, failures


def posterior_settings(args, cfg) -> PosteriorSettings:
    """The sampler's settings: ``[posterior]`` (or :data:`DEFAULT_POSTERIOR` when it states only the defaults),
    ``--samples`` and ``--rounds`` replacing theirs."""
    from fracid.runtime.exits import UsageError

    base = DEFAULT_POSTERIOR if cfg.posterior == PosteriorSettings() else cfg.posterior
    changes = {key: value for key, value in (("samples_per_round", args.samples), ("max_rounds", args.rounds))
               if value is not None}
    try:
        return base.replace(**changes)
    except ValueError as err:
        raise UsageError(f"--samples {args.samples} / --rounds {args.rounds}: {err} (samples >= 2, rounds >= 1)") from None


def run_compare(args) -> int:
    """``fracid compare``: its exit status (3 when no model gave a log evidence)."""
    from fracid.config import build_data, build_method
    from fracid.runtime.exits import FAILED
    from fracid.inverse.studies.model_comparison import compare
    from fracid.report.compare import write_compare

    cfg = load(args, args.config, "identify")
    data = build_data(cfg)
    settings = posterior_settings(args, cfg)
    kinds, left_out = model_types(cfg, args.models)
    for kind, why in left_out:
        say(args, f"{kind}: left out, it does not run on the {cfg.specimen.type} specimen ({why})")
    contenders, failures = _contenders(args, cfg, data, kinds)
    out = out_dir(args, cfg)
    rounds = f"{settings.max_rounds} round{'s' if settings.max_rounds != 1 else ''}"
    say(args, f"posterior of every model: at most {settings.samples_per_round * settings.max_rounds} forward runs "
              f"({rounds} of {settings.samples_per_round}), until ESS {settings.target_ess:g}")
    with working_in(args, out, store=True) as store, command_executor(args) as executor:
        result = compare(data, contenders, method=build_method(cfg), posterior=settings, executor=executor,
                         store=store, progress=False, log=lambda text: say(args, text), retry_failed=args.retry_failed,
                         tolerance=cfg.study.tolerance)
        record = provenance(args, cfg, contenders[0].operator, contenders[0].space, store) if contenders else {}
    result.failures.update(failures)
    written = write_compare(out, result, title=f"fracid compare: {Path(cfg.path).name}", provenance=record)
    say(args, result.summary())
    wrote(args, out, [*written, "runs.sqlite"])
    for score in result.scores:
        if not score.posterior_status.startswith("converged"):
            warn(f"{score.label}: posterior {score.posterior_status}")
    if result.best is None:
        print(f"fracid: compare: no model gave a log evidence; see {out / 'report.html'}", file=sys.stderr)
        return FAILED
    return 0
