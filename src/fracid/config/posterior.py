"""Validation of the ``[posterior]`` section: the settings of the sampler of ``fracid posterior``
(:class:`~fracid.inverse.sampling.posterior.PosteriorSettings`); every key is optional."""

from __future__ import annotations

from fracid.config.checker import Checker
from fracid.config.schema import PosteriorConfig
from fracid.config.vocabulary import POSTERIOR_KEYS
from fracid.inverse.sampling.posterior import MAX_SCREENING, MIN_ESS, ess_floor, floor_text


def read_posterior(ck: Checker, raw) -> PosteriorConfig:
    raw = ck.table("posterior", {} if raw is None else raw, POSTERIOR_KEYS)
    default = PosteriorConfig()

    def given(name):
        return raw.get(name, getattr(default, name))

    config = PosteriorConfig(
        samples_per_round=ck.integer("posterior.samples_per_round", given("samples_per_round"),
                                     "must be an integer >= 2 (forward runs per round)", lambda v: v >= 2),
        max_rounds=ck.integer("posterior.max_rounds", given("max_rounds"), "must be an integer >= 1 (rounds at most)",
                              lambda v: v >= 1),
        target_ess=ck.number("posterior.target_ess", given("target_ess"),
                             "must be a number > 1 (effective sample size at which the sampler stops)",
                             lambda v: v > 1),
        components=ck.integer("posterior.components", given("components"),
                              "must be an integer >= 1 (Gaussian components of the adapted proposals)",
                              lambda v: v >= 1),
        defensive=ck.number("posterior.defensive", given("defensive"),
                            "must be a number with 0 <= d < 1 (share of the prior in every proposal)",
                            lambda v: 0 <= v < 1),
        inflation=ck.number("posterior.inflation", given("inflation"),
                            "must be a number > 0 (std multiplier of the first proposal around the Kalman estimate)",
                            lambda v: v > 0),
        seed=ck.integer("posterior.seed", given("seed"), "must be an integer >= 0", lambda v: v >= 0),
        screening=ck.number("posterior.screening", given("screening"),
                            f"must be a number with 1 <= s <= {MAX_SCREENING:g} (element sizes of the screening mesh "
                            "over the configured mesh's; 1: no screening, every draw a fine run)",
                            lambda v: 1 <= v <= MAX_SCREENING),
        fine_runs=ck.integer("posterior.fine_runs", given("fine_runs"),
                             "must be an integer >= 2 (fine-mesh runs at most, with screening)", lambda v: v >= 2),
    )
    _warn_floor(ck, config)
    return config


def _warn_floor(ck: Checker, config: PosteriorConfig) -> None:
    """Warn of settings that cannot give an effective sample size at the floor or the target."""
    total = config.samples_per_round * config.max_rounds
    floor = ess_floor(config.target_ess)
    if total < floor:
        floor_words = floor_text(config.target_ess, "posterior.target_ess")
        ck.warn(f"posterior.samples_per_round {config.samples_per_round} x posterior.max_rounds {config.max_rounds} = "
                f"{total} draws at most, below the floor of {floor:g} effective samples ({floor_words}): the "
                "effective sample size never exceeds the number of draws, so the "
                "posterior fails whatever the data (exit status 3) and gives no credible intervals; raise "
                "samples_per_round or max_rounds")
    elif config.target_ess > total:
        ck.warn(f"posterior.target_ess = {config.target_ess:g} is above the {total} draws at most "
                f"(samples_per_round {config.samples_per_round} x max_rounds {config.max_rounds}): the effective "
                "sample size never exceeds the number of draws, so the sampler runs every round and reports "
                "the target as not reached; raise max_rounds or samples_per_round, or lower target_ess")
    if config.target_ess < MIN_ESS:
        ck.warn(f"posterior.target_ess = {config.target_ess:g} is below {MIN_ESS:g}, the effective sample size below "
                "which credible intervals are those of a few draws: the sampler stops there and its intervals are "
                f"rough; raise target_ess to {MIN_ESS:g} or more")
