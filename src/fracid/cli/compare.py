"""``fracid compare CONFIG [--models M ...]``: the models that run on the configuration's specimen, each identified
on the same data with its own parameters and bounds, ranked by log evidence
(:func:`fracid.inverse.studies.model_comparison.compare`).

One prior rule for every model (:data:`PRIOR_RULE`): bounds a factor 3 around the configuration's value of each
identified parameter (:func:`fracid.cli.init.default_identification`), the configuration's own model included
(its ``[identify]`` parameters and ``[model] law`` kept, its ``[identify.bounds]`` not: a model compared on a
narrower prior would gain evidence from its volume alone). Every other model identifies what ``fracid init``
writes for it, its other parameters the configuration's values where the names are shared (E, nu, and kappa_i,
beta, c ... between the damage models), its class's defaults elsewhere. The lower bound of the parameter that sets
a model's mesh length is raised to what the mesh resolves, and a model the mesh resolves nowhere in its bounds is
left out, both warned (:func:`fracid.config.mesh_bounds.fit_to_mesh`). A line per model every
``FRACID_PROGRESS_SECONDS`` (30 s) says its stage while the models run side by side. Every model is identified
with ``[identify] method`` and its settings, and sampled with
``[posterior]`` (:data:`DEFAULT_POSTERIOR` when the configuration leaves it at its defaults; ``--samples``,
``--rounds`` override). Writes compare.json, compare.html (its own name: identify's report.html in a shared
``--out`` stays) and
figures/compare_*.png
(:func:`fracid.report.compare.write_compare`) beside the run store.
"""

from __future__ import annotations

import sys
from dataclasses import replace
from pathlib import Path

from fracid.cli.common import command_executor, load, out_dir, provenance, say, warn, working_in, wrote
from fracid.inverse.sampling.posterior import PosteriorSettings

#: the one rule that gives every model its prior (said on stdout and in the report)
PRIOR_RULE = ("uniform between bounds a factor 3 around the configuration's value of each identified parameter "
              "(fracid init's rule, inside the usual and valid ranges; log-uniform for beta), for the configuration's "
              "model too, so that no model's evidence gains from its prior's volume; the lower bound of the "
              "parameter that sets the mesh length raised to what the mesh resolves")

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
    """``cfg`` for model type ``kind`` with the bounds of the one prior rule (module docstring): the configuration's
    own model keeps its ``[model]`` and its ``[identify]`` parameters; another gets ``[model]`` of that type with the
    shared parameter values and ``fracid init``'s parameters. Every identified parameter's bounds are
    :func:`fracid.cli.init.first_prior`'s around its value."""
    from fracid.cli.init import default_identification, first_prior
    from fracid.config import build_parameters
    from fracid.config.schema import ModelConfig
    from fracid.models import model_from_type

    if kind == cfg.model.type:
        names, model = list(cfg.identify.parameters), cfg.model
        bounds, log = first_prior(build_parameters(cfg), names)
    else:
        given = build_parameters(cfg)
        cls = model_from_type(kind).parameters
        shared = tuple((name, getattr(given, name)) for name in cls.names() if hasattr(given, name))
        names, bounds, log = default_identification(kind, cls(**dict(shared)))
        model = ModelConfig(type=kind, parameters=shared)
    identify = replace(cfg.identify, parameters=tuple(names), lower=tuple(bounds[n][0] for n in names),
                       upper=tuple(bounds[n][1] for n in names), log=tuple(log))
    return replace(cfg, model=model, identify=identify)


def _space_text(space) -> str:
    return ", ".join(f"{n} in [{lo:g}, {hi:g}]" + (" (log)" if lg else "")
                     for n, lo, hi, lg in zip(space.names, space.lower, space.upper, space.log))


def _contenders(args, cfg, data, kinds):
    """A Contender per model type with its bounds fitted to the mesh (:func:`fracid.config.mesh_bounds.fit_to_mesh`);
    the models left out (set-up failed, mesh too coarse) by label with why, and the bounds cut to the mesh."""
    from fracid.config import build_operator, build_space
    from fracid.config.mesh_bounds import fit_to_mesh
    from fracid.inverse.studies.model_comparison import Contender

    contenders, failures, cuts = [], {}, []
    for kind in kinds:
        try:
            own, text = fit_to_mesh(model_config(cfg, kind))
            if own is None:
                failures[kind] = f"its mesh is too coarse: {text}"
                continue
            contenders.append(Contender(kind, build_operator(own, data), build_space(own)))
        except (TypeError, ValueError) as err:
            failures[kind] = f"could not be set up: {err}"
            continue
        if text is not None:
            cuts.append(f"{kind}: bounds cut to the mesh: {text}")
        say(args, f"{kind}: {_space_text(contenders[-1].space)}")
    return contenders, failures, cuts


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
    """``fracid compare``: its exit status (3 when no model gave an estimated log evidence)."""
    from fracid.config import build_data, build_method
    from fracid.inverse.studies.model_comparison import compare
    from fracid.report.compare import REPORT, write_compare
    from fracid.runtime.exits import FAILED
    from fracid.runtime.progress import StageLines

    cfg = load(args, args.config, "identify")
    data = build_data(cfg)
    settings = posterior_settings(args, cfg)
    kinds, left_out = model_types(cfg, args.models)
    for kind, why in left_out:
        say(args, f"{kind}: left out, it does not run on the {cfg.specimen.type} specimen ({why})")
    say(args, f"prior of every model: {PRIOR_RULE}")
    contenders, failures, cuts = _contenders(args, cfg, data, kinds)
    for text in (*cuts, *(f"{kind}: not compared, {why}" for kind, why in failures.items())):
        warn(text)  # at once: the comparison may take long
    out = out_dir(args, cfg)
    rounds = f"{settings.max_rounds} round{'s' if settings.max_rounds != 1 else ''}"
    say(args, f"posterior of every model: at most {settings.samples_per_round * settings.max_rounds} forward runs "
              f"({rounds} of {settings.samples_per_round}), until ESS {settings.target_ess:g}")
    with working_in(args, out, store=True) as store, command_executor(args) as executor, \
            StageLines([c.label for c in contenders], lambda text: say(args, text)) as stages:
        result = compare(data, contenders, method=build_method(cfg), posterior=settings, executor=executor,
                         store=store, progress=False, log=stages.log, retry_failed=args.retry_failed,
                         tolerance=cfg.study.tolerance)
        record = provenance(args, cfg, contenders[0].operator, contenders[0].space, store) if contenders else {}
    result.failures.update(failures)
    result.setup_warnings[:0] = cuts
    result.settings["prior"] = PRIOR_RULE
    written = write_compare(out, result, title=f"fracid compare: {Path(cfg.path).name}", provenance=record)
    say(args, result.summary())
    wrote(args, out, [*written, "runs.sqlite"])
    for text in result.warnings()[len(cuts):]:
        if not any(text.startswith(f"{kind}: not compared") for kind in failures):  # said before the runs
            warn(text)
    for score in result.scores:
        if not score.posterior_status.startswith("converged") and score.estimated:
            warn(f"{score.label}: posterior {score.posterior_status}")
    if result.best is None:
        print(f"fracid: compare: no model gave an estimated log evidence; see {out / REPORT}", file=sys.stderr)
        return FAILED
    return 0
