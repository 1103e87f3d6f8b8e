"""Benchmark: the demo's posterior by coarse-mesh screening and fine-mesh correction, against a long single-level
run on the fine mesh.

Runs ``fracid posterior`` on the bundled demo (beam 4 of Gregoire et al. 2013, gradient damage, kappa_i, beta and c)
with ``[posterior] screening``, ``fine_runs`` and ``target_ess`` from the options, then compares its posterior.json
with a reference posterior.json (a long run with ``screening = 1``: every draw a fine run, e.g.
``target_ess = 2000``): the means and the 90 % interval ends in reference stds, the stds in %, the equivalent
independent draws, the fine and coarse runs, the wall time.

    python benchmarks/posterior_screened.py --reference docs/posterior/demo_reference.json [--screening 2]
        [--target 1000] [--fine-runs 300] [--samples 100] [--rounds 15] [--workers 2]
    python benchmarks/posterior_screened.py --make-reference docs/posterior/demo_reference.json [--target 2000]
"""

from __future__ import annotations

import argparse
import json
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

DEMO = Path(__file__).resolve().parents[1] / "src" / "fracid" / "datasets" / "gregoire2013_beam4"


def demo_config(directory: Path, posterior: dict) -> Path:
    """The demo's configuration in ``directory`` with its [posterior] section replaced by ``posterior``."""
    for name in ("demo.toml", "load_cmod.csv"):
        shutil.copy(DEMO / name, directory / name)
    text = (directory / "demo.toml").read_text()
    section = "[posterior]\n" + "".join(f"{k} = {v}\n" for k, v in posterior.items())
    path = directory / "bench.toml"
    path.write_text(text[:text.index("[posterior]")] + section)
    return path


def run_posterior(posterior: dict, workers: int) -> tuple[dict, float, str]:
    """posterior.json of ``fracid posterior`` on the demo with ``posterior``, its wall time [s] and its output."""
    with tempfile.TemporaryDirectory() as tmp:
        config = demo_config(Path(tmp), posterior)
        start = time.perf_counter()
        proc = subprocess.run([sys.executable, "-m", "fracid", "posterior", str(config), "--out", str(Path(tmp) / "out"),
                               "--workers", str(workers)], capture_output=True, text=True)
        seconds = time.perf_counter() - start
        if proc.returncode not in (0, 3):
            raise SystemExit(f"fracid posterior exited {proc.returncode}:\n{proc.stderr[-3000:]}")
        return json.loads((Path(tmp) / "out" / "posterior.json").read_text()), seconds, proc.stdout


def compare(result: dict, reference: dict) -> list[str]:
    """Rows of the comparison per parameter (markdown)."""
    post, ref = result.get("posterior", result), reference.get("posterior", reference)
    rows = ["| parameter | mean (ref) | (mean - ref) / ref std | std / ref std - 1 | 90 % interval (ref) | "
            "(ends - ref) / ref std | Monte-Carlo error of the mean / ref std |", "|---|---|---|---|---|---|---|"]
    for j, name in enumerate(post["names"]):
        std = ref["std"][j]
        ends = [(a - b) / std for a, b in zip(post["interval_90"][j], ref["interval_90"][j])]
        rows.append(f"| {name} | {post['mean'][j]:.4g} ({ref['mean'][j]:.4g}) | {(post['mean'][j] - ref['mean'][j]) / std:+.3f} "
                    f"| {post['std'][j] / std - 1:+.1%} | [{post['interval_90'][j][0]:.4g}, {post['interval_90'][j][1]:.4g}] "
                    f"([{ref['interval_90'][j][0]:.4g}, {ref['interval_90'][j][1]:.4g}]) | {ends[0]:+.3f}, {ends[1]:+.3f} "
                    f"| {post['mean_error'][j] / std:.3f} |")
    return rows


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--reference", type=Path, help="the reference posterior.json to compare with")
    parser.add_argument("--make-reference", type=Path, help="write a single-level reference posterior.json here")
    parser.add_argument("--screening", type=float, default=2.0)
    parser.add_argument("--target", type=float, default=1000.0)
    parser.add_argument("--fine-runs", type=int, default=300)
    parser.add_argument("--samples", type=int, default=100)
    parser.add_argument("--rounds", type=int, default=15)
    parser.add_argument("--workers", type=int, default=2)
    args = parser.parse_args(argv)
    if args.make_reference:
        settings = {"samples_per_round": 250, "max_rounds": 12, "target_ess": args.target, "screening": 1, "seed": 7}
        result, seconds, _ = run_posterior(settings, args.workers)
        args.make_reference.write_text(json.dumps(result, indent=1))
        print(f"reference: ESS {result['ess']:.0f}, {result['draws']} fine runs, {seconds:.0f} s")
        return
    settings = {"samples_per_round": args.samples, "max_rounds": args.rounds, "target_ess": args.target,
                "screening": args.screening, "fine_runs": args.fine_runs}
    result, seconds, out = run_posterior(settings, args.workers)
    levels = result.get("screening") or {}
    print("\n".join(line for line in out.splitlines() if line.startswith(("posterior", "coarse", "fine"))))
    print(f"\nscreening {args.screening:g}: {levels.get('coarse_draws')} coarse draws (ESS "
          f"{levels.get('coarse_ess', float('nan')):.0f}), {levels.get('fine_runs')} fine runs, spread "
          f"{levels.get('spread', float('nan')):.3f}; equivalent draws {result['ess']:.0f}; status {result['status']}; "
          f"log Z {result['log_evidence']:.4g} +- {result['log_evidence_error']:.2g}; the command {seconds:.0f} s")
    if args.reference:
        reference = json.loads(args.reference.read_text())
        print(f"reference: ESS {reference['ess']:.0f}, {reference['draws']} fine runs, log Z "
              f"{reference['log_evidence']:.4g} +- {reference['log_evidence_error']:.2g}")
        print("\n".join(compare(result, reference)))


if __name__ == "__main__":
    main()
