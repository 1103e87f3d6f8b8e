"""An external sampler driving fracid through UM-Bridge: emcee's affine-invariant ensemble on the posterior of the
bar's (c, beta), every likelihood a forward run of ``fracid serve`` (examples/umbridge/README.md).

The likelihood and the prior come from what the server says of its model (UM-Bridge's ModelInfo, fracid's entry):
Gaussian with the data's std, uniform on the configuration's bounds, so that the target is the one
``fracid posterior`` samples. A failed forward run (the protocol's error) counts as zero likelihood, and is counted.

    fracid serve bar.toml --port 4242 &
    python sampler.py [--url http://localhost:4242] [--start fracid-out/result.json] [--walkers 16] [--steps 600]
                      [--burn 200] [--out emcee.csv]
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import emcee
import numpy as np
import requests
import umbridge


def served_target(url: str, name: str = "fracid"):
    """(log probability, the model's description, the calls' counter) of the served model."""
    model = umbridge.HTTPModel(url, name)
    info = requests.post(f"{url}/ModelInfo", json={"name": name}, timeout=60).json()["fracid"]
    data, std = np.asarray(info["data"]), np.asarray(info["std"])
    lower = np.array([i["lower"] for i in info["inputs"]])
    upper = np.array([i["upper"] for i in info["inputs"]])
    counts = {"calls": 0, "failed": 0}

    def log_probability(x):
        if np.any(x <= lower) or np.any(x >= upper):
            return -np.inf
        counts["calls"] += 1
        try:
            y = np.asarray(model([x.tolist()])[0])
        except Exception:  # noqa: BLE001 -- the server's error object: a failed forward run, no likelihood there
            counts["failed"] += 1
            return -np.inf
        return -0.5 * float(np.sum(((y - data) / std) ** 2))

    return log_probability, info, counts


def starting_ball(info, walkers: int, start, rng) -> np.ndarray:
    """Walkers in a ball around an estimate (``result.json``: x +- std / 2) or, without one, uniform in the bounds."""
    lower = np.array([i["lower"] for i in info["inputs"]])
    upper = np.array([i["upper"] for i in info["inputs"]])
    if start is None:
        return lower + (upper - lower) * rng.random((walkers, lower.size))
    result = json.loads(Path(start).read_text())
    x, std = np.asarray(result["x"]), np.asarray(result["std"])
    return np.clip(x + 0.5 * std * rng.standard_normal((walkers, x.size)), lower, upper)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--url", default="http://localhost:4242")
    parser.add_argument("--start", help="result.json of fracid identify (or posterior) to start the walkers near")
    parser.add_argument("--walkers", type=int, default=16)
    parser.add_argument("--steps", type=int, default=600)
    parser.add_argument("--burn", type=int, default=200, help="steps dropped at the start of every chain")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--out", type=Path, default=Path("emcee.csv"))
    args = parser.parse_args()
    log_probability, info, counts = served_target(args.url)
    names = [i["name"] for i in info["inputs"]]
    rng = np.random.default_rng(args.seed)
    sampler = emcee.EnsembleSampler(args.walkers, len(names), log_probability, moves=emcee.moves.StretchMove())
    sampler.random_state = np.random.RandomState(args.seed).get_state()  # emcee's own generator, seeded
    start = time.perf_counter()
    sampler.run_mcmc(starting_ball(info, args.walkers, args.start, rng), args.steps, progress=False)
    seconds = time.perf_counter() - start
    draws = sampler.get_chain(discard=args.burn, flat=True)
    np.savetxt(args.out, draws, delimiter=",", header=",".join(names), comments="")
    with np.errstate(invalid="ignore", divide="ignore"):  # a chain too short for it gives NaN, said as such
        tau = sampler.get_autocorr_time(discard=args.burn, quiet=True)
    print(f"{counts['calls']} forward runs through UM-Bridge ({counts['failed']} failed) in {seconds:.0f} s; "
          f"acceptance {np.mean(sampler.acceptance_fraction):.2f}; autocorrelation time {np.round(tau, 1)} steps: "
          f"about {draws.shape[0] / max(np.nanmax(tau, initial=1.0), 1.0):.0f} independent draws")
    for j, name in enumerate(names):
        low, high = np.quantile(draws[:, j], [0.05, 0.95])
        print(f"  {name}: mean {draws[:, j].mean():.4g}, std {draws[:, j].std(ddof=1):.3g}, "
              f"90 % interval [{low:.4g}, {high:.4g}]")
    print(f"draws in {args.out}")


if __name__ == "__main__":
    main()
