"""``fracid compare`` on the Grégoire demo: every model that runs on the notched beam, ranked by log evidence.

Runs ``fracid compare src/fracid/datasets/gregoire2013_beam4/demo.toml --out OUT --samples S --rounds R`` (the demo's
[identify] for gradient damage, ``fracid init``'s parameters and bounds for the others, the demo's [posterior]
with S draws per round and R rounds at most), times it, and writes OUT/README.md: the settings, the wall time, the
ranking table, the evidence with its error bars, the estimates, the failures and what to read in them. The run
store (OUT/runs.sqlite, not committed) makes a rerun reuse every run: ``--readme-only`` rewrites the README from
OUT/compare.json and OUT/run.json (the computing run's wall times) without computing.

    python benchmarks/compare_demo.py [--out docs/compare] [--workers 2] [--samples 40] [--rounds 3] [--readme-only]
"""

from __future__ import annotations

import argparse
import datetime
import json
import platform
import time
from pathlib import Path

from fracid.cli.dispatch import demo_config_path, main
from fracid.report.compare import DEFINITIONS
from fracid.report.cross_model import markdown_table

ROOT = Path(__file__).resolve().parents[1]


def _command(args) -> list:
    command = ["compare", str(demo_config_path()), "--out", str(args.out), "--samples", str(args.samples),
               "--rounds", str(args.rounds)]
    return command + (["--workers", str(args.workers)] if args.workers else [])


def run(args) -> dict:
    """Run the command; its exit status, wall time and settings (OUT/run.json)."""
    start = time.perf_counter()
    status = main(_command(args))
    saved = json.loads((args.out / "compare.json").read_text(encoding="utf-8"))
    record = {"status": status, "wall_seconds": time.perf_counter() - start,
              "model_seconds": {m["label"]: m["seconds"] for m in saved["models"]}, "failed_runs": failed_runs(args.out),
              "command": "fracid " + " ".join(_command(args)).replace(str(ROOT) + "/", ""),
              "date": datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC"),
              "machine": f"{platform.machine()}, {args.workers or 'one worker per core'} workers"}
    (args.out / "run.json").write_text(json.dumps(record, indent=1) + "\n", encoding="utf-8")
    return record


def failed_runs(out: Path) -> list:
    """The failed forward runs of OUT/runs.sqlite: their parameters and the reason (its first sentence)."""
    from fracid.store.runs import RunStore

    if not (out / "runs.sqlite").is_file():
        return []
    with RunStore(out / "runs.sqlite", readonly=True) as store:
        keys = [key for key, status in store.statuses(store.keys()).items() if status != "ok"]
        records = [store.get(key) for key in keys]
    return [{"x": [float(v) for v in r["x"]], "error": str(r.get("error", "")).split(": no convergence")[0]}
            for r in records if r is not None]


def _rows(saved) -> tuple[list, list]:
    header = ["rank", "model", "p", "RMS [% of peak]", "chi2", "AIC", "BIC", "log Z +- MC error", "log Z Laplace",
              "delta log Z", "ESS", "draws"]
    rows = []
    for m in saved["models"]:
        post = m["posterior"] or {}
        z = "n/a" if m["log_evidence"] is None else f"{m['log_evidence']:.2f} +- {m['log_evidence_error']:.2f}"
        rows.append([f"{m['rank']}" + (" (tie)" if m["tied_with_best"] else ""), m["label"], m["p"],
                     f"{m['rms_percent']:.2f}", f"{m['chi2']:.1f}", f"{m['aic']:.1f}", f"{m['bic']:.1f}", z,
                     _number(m["log_evidence_laplace"]), _number(m["delta_log_evidence"]),
                     f"{post.get('ess', float('nan')):.0f}", post.get("draws", 0)])
    return header, rows


def _number(value) -> str:
    return "n/a" if value is None else f"{value:.2f}"


def _estimates(saved, seconds: dict) -> list:
    """Per model: the estimate, the bounds, the verdict, the statuses and the wall time of the computing run."""
    lines = []
    for m in saved["models"]:
        values = "; ".join(f"{n} = {p['value']:.4g} +- {p['std']:.2g} {p['unit'] if p['unit'] != '-' else ''}".rstrip()
                           for n, p in m["parameters"].items())
        bounds = ", ".join(f"{n} [{lo:.3g}, {hi:.3g}]" + (" log" if lg else "")
                           for n, lo, hi, lg in zip(m["parameters"], *m["bounds"], m["log"]))
        verdict = ", ".join(f"{v['name']} {v['status']}" for v in m["verdict"]["parameters"])
        failed = [f"{c['failed']} of {c['runs']} {stage}" for stage, c in m["stage_runs"].items() if c["failed"]]
        failed += [f"{m['posterior']['failed']} posterior draws"] if (m["posterior"] or {}).get("failed") else []
        lines.append(f"- **{m['label']}** ({m['model']}): {values}; bounds {bounds}; verdict: {verdict}; "
                     f"identification {m['identification_status'].split(';')[0]}; posterior {m['posterior_status']}; "
                     f"{m['forward_runs']} identification runs ({', '.join(failed) or 'none'} failed), "
                     f"{seconds.get(m['label'], m['seconds']) / 60:.0f} min")
    return lines


def readme(out: Path) -> str:
    """OUT/README.md from OUT/compare.json and OUT/run.json."""
    saved = json.loads((out / "compare.json").read_text(encoding="utf-8"))
    run_record = json.loads((out / "run.json").read_text(encoding="utf-8"))
    post = saved["settings"]["posterior"]
    header, rows = _rows(saved)
    failures = [f"- **{label}**: not compared: {why}" for label, why in saved["failures"].items()]
    failed = [f"- x = {', '.join(f'{v:.4g}' for v in run['x'])}: {run['error']}"
              for run in run_record.get("failed_runs") or failed_runs(out)]
    return "\n".join([
        "# Models compared by evidence on the Grégoire beam (`fracid compare`)", "",
        "Every model that runs on the notched beam identified on the demo's data (Grégoire et al. 2013, beam 4: 24 "
        "load-CMOD points from 0.004 to 0.2 mm, std from the scatter band) and ranked by log evidence. Gradient "
        "damage keeps the demo's [identify] parameters and bounds; the other models get `fracid init`'s (their "
        "usual parameters, bounds a factor 3 around the values, E = 36 250 MPa and nu = 0.2 of the demo, the "
        "damage models also its kappa_i, beta, c). Every model: the demo's KNN population (32) and Kalman filter, "
        f"then the posterior by adaptive importance sampling on the exact model, {post['samples_per_round']} draws "
        f"a round, {post['max_rounds']} rounds at most (target ESS {post['target_ess']:g}, seed {post['seed']}).", "",
        f"Command: `{run_record['command']}` (`python benchmarks/compare_demo.py`), {run_record['date']}, "
        f"{run_record['machine']} on a shared 2-core machine: wall time {run_record['wall_seconds'] / 60:.0f} min.",
        "", "## Ranking", "", markdown_table(header, rows), "", *[f"- {n}" for n in saved["notes"]], "",
        "![log evidence with Monte-Carlo error bars](figures/compare_evidence.png)", "",
        "![the data and every model's fit](figures/compare_fits.png)", "",
        "## Estimates and verdicts", "", *_estimates(saved, run_record.get("model_seconds", {})),
        *(["", "Failed forward runs (their models by the counts above; the identification and the posterior go on "
           "without them):", "", *failed] if failed else []), *([""] + failures if failures else []), "",
        "## Definitions", "", DEFINITIONS, "",
        "The error bars of the figure are +- 2 Monte-Carlo standard errors. The Monte-Carlo error of log Z is the "
        "delta-method error of the importance-sampling mean, sqrt(1/ESS - 1/N): with an effective sample size "
        "below the sampler's floor it is itself rough. Files: `compare.json` (every number, the posteriors' "
        "statistics, the fits), `report.html`, `figures/`. What the ranking says: the main README, \"Comparing models\".",
        ""])


def main_script(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=ROOT / "docs" / "compare")
    parser.add_argument("--workers", type=int)
    parser.add_argument("--samples", type=int, default=40)
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--readme-only", action="store_true")
    args = parser.parse_args(argv)
    if not args.readme_only:
        record = run(args)
        print(f"fracid compare: exit {record['status']}, {record['wall_seconds'] / 60:.1f} min")
    (args.out / "README.md").write_text(readme(args.out), encoding="utf-8")
    return 0


if __name__ == "__main__":
    raise SystemExit(main_script())
