"""``fracid posterior CONFIG``: ``fracid identify``, then weighted samples of the parameters given the data
(adaptive importance sampling on the exact model): CSV, JSON, figures and an HTML page."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

from fracid.cli.common import command_executor, out_dir, progress_choice, say, warn, working_in, wrote
from fracid.cli.identify import identification, identify_job, write_identification


def add_parser(sub, parents) -> None:
    """The ``posterior`` subcommand's arguments."""
    p = sub.add_parser("posterior", parents=[parents.stored],
                       help="identify, then sample the parameters given the data on the exact model")
    p.add_argument("config", type=Path, help="TOML configuration file")
    p.set_defaults(run=run_posterior_command)


def run_posterior_command(args) -> int:
    """``fracid identify``, then the posterior of the parameters sampled from its Gaussian on the exact model."""
    from fracid.config import posterior_settings
    from fracid.runtime.exits import FAILED
    from fracid.inverse.core.runs import StoredOperator
    from fracid.inverse.sampling.sample import sample_posterior
    from fracid.report.posterior import write_posterior

    job = identify_job(args, args.config)
    settings = posterior_settings(job.cfg)
    out = out_dir(args, job.cfg)
    with working_in(args, out, store=True) as store, command_executor(args) as executor:
        result = identification(args, job, store, executor)
        write_identification(args, job, out, result)
        if not (np.all(np.isfinite(result.x)) and np.all(np.isfinite(result.C))):
            print(f"fracid: posterior: the identification gave no finite estimate and covariance ({result.status}), "
                  f"and the sampler starts from them; see {out / 'report.html'}", file=sys.stderr)
            return FAILED
        evaluate = StoredOperator(job.operator, store, study="posterior", retry_failed=args.retry_failed)
        post = sample_posterior(evaluate, job.data, job.space, result, settings, executor=executor,
                                progress=progress_choice(args), log=lambda text: say(args, text))
    written = write_posterior(out, post, data=job.data, fit=result, provenance=result.provenance,
                              title=f"fracid posterior: {Path(job.cfg.path).name}")
    say(args, post.summary())
    coarse = "" if post.levels is None else f" on the fine mesh, and {len(post.levels.x)} on the screening mesh"
    say(args, f"posterior forward runs: {len(np.unique(post.x, axis=0))}{coarse} ({evaluate.computed} computed, "
              f"{evaluate.reused} reused from the run store, {post.failed} failed)")
    wrote(args, out, written)
    if post.sampling_failed:
        print(f"fracid: posterior {post.status}. The draws are in {out / 'posterior.csv'}, without credible "
              "intervals.", file=sys.stderr)
        return FAILED
    if not post.converged:
        warn(f"posterior: {post.status}")
    return 0
