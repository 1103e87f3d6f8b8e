"""Benchmark: ``fracid check``'s time estimate against the measured ``fracid identify``.

For four configurations of different cost (a 40-element bar, the demo beam, the wedge-splitting test with
the cohesive crack, the DIC example) it runs ``fracid check CONFIG --workers W`` (its estimate: the likely
value and the upper one), then ``fracid identify CONFIG --workers W`` in a fresh output directory (no stored
runs), timed from outside (the command's wall time) and from inside (``result.json``'s ``wall_seconds``, the
identification alone), and prints a table with the ratio measured / estimate and the load of the machine
(``os.getloadavg()``, 1 min) before and after each. A loaded machine slows every run: compare on a quiet one.

    python benchmarks/check_estimate.py [--workers 2] [--only bar,demo] [--out docs/speed/check_estimate.md]
        [--measured docs/speed/check_estimate.json]   # reuse the identifications measured before (check only)
"""

from __future__ import annotations

import argparse
import json
import os
import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
DATASETS = ROOT / "src" / "fracid" / "datasets"
CONFIGS = {  # name -> (path or None for the generated bar, what it is)
    "bar": (None, "40-element bar, gradient damage, (c, beta), KNN 8 + Kalman 2 groups"),
    "demo beam": (DATASETS / "gregoire2013_beam4" / "demo.toml", "fracid demo: notched beam, 3 parameters"),
    "wedge (cohesive crack)": (DATASETS / "tinloi_que_wst" / "config.toml", "wedge splitting, cohesive crack, (ft, Gf)"),
    "DIC example": (ROOT / "examples" / "dic" / "identify.toml", "notched beam, force-CMOD and a DIC field"),
}
UNITS = {"s": 1.0, "min": 60.0, "h": 3600.0}
ENV = {**os.environ, "OMP_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1", "MKL_NUM_THREADS": "1"}


def bar_config(directory: Path) -> Path:
    """The bar's data (a synthetic curve, (c, beta) = (2, 250)) and configuration, written into ``directory``."""
    import fracid

    run = fracid.simulate(fracid.BarWithWeakZone(n_elements=40), fracid.DamageParameters(c=2.0, beta=250.0),
                          target=0.032, stop_force_fraction=None, checkpoints=np.linspace(0.001, 0.032, 40))
    rows = ["u_mm,F_N"] + [f"{c:.9g},{f:.9g}" for c, f in zip(run.control, run.force)]
    (directory / "bar.csv").write_text("\n".join(rows) + "\n")
    text = """[model]
type = "gradient-damage"
[model.parameters]
c = 1.0
beta = 300.0
[specimen]
type = "bar"
n_elements = 40
[[experiments]]
file = "bar.csv"
control_column = "u_mm"
control_unit = "mm"
force_unit = "N"
kind = "single"
force_columns = ["F_N"]
std = 0.02
n_points = 12
control_range = [0.004, 0.03]
[identify]
parameters = ["c", "beta"]
[identify.bounds]
c = [0.5, 4.0]
beta = [100.0, 500.0]
[identify.knn]
n = 8
k = 3
[identify.kalman]
groups = 2
max_iterations = 3
"""
    path = directory / "bar.toml"
    path.write_text(text)
    return path


def seconds_of(text: str) -> float:
    """``"34 s"``, ``"7 min"``, ``"1.2 h"`` in seconds."""
    value, unit = text.split()
    return float(value) * UNITS[unit]


def parse_estimate(out: str) -> dict:
    """The likely and upper values [s] of ``fracid check``'s estimate line (an estimate without a likely value
    gives its upper one as both), the timed run [s] and the load it states."""
    line = next((line for line in out.splitlines() if line.startswith("estimate for fracid identify")), "")
    number = r"([\d.]+ (?:s|min|h))"
    upper = re.findall(rf"at most {number}", line)
    likely = re.search(rf"about {number}", line)
    timed = re.search(r"took ([\d.]+) s", out)
    return {"likely": seconds_of(likely.group(1)) if likely else (seconds_of(upper[-1]) if upper else float("nan")),
            "upper": seconds_of(upper[-1]) if upper else float("nan"),
            "timed_run": float(timed.group(1)) if timed else float("nan"), "line": line.strip()}


def run(args, cwd) -> tuple[subprocess.CompletedProcess, float]:
    start = time.perf_counter()
    proc = subprocess.run([sys.executable, "-m", "fracid", *map(str, args)], cwd=cwd, capture_output=True, text=True,
                          env=ENV, stdin=subprocess.DEVNULL)
    return proc, time.perf_counter() - start


def estimate(config: Path, workers: int) -> dict:
    load = os.getloadavg()[0]
    proc, wall = run(["check", config, "--workers", workers], config.parent)
    if proc.returncode != 0:
        raise SystemExit(f"fracid check {config} failed ({proc.returncode}):\n{proc.stdout}\n{proc.stderr}")
    return {**parse_estimate(proc.stdout), "check_seconds": wall, "load_check": load}


def measure(config: Path, workers: int) -> dict:
    """``fracid identify`` timed, in a fresh output directory."""
    with tempfile.TemporaryDirectory(prefix="fracid-bench-") as out:
        before = os.getloadavg()[0]
        proc, wall = run(["identify", config, "--workers", workers, "--quiet", "--out", out], config.parent)
        after = os.getloadavg()[0]
        runs = {}
        result = Path(out) / "result.json"
        if result.is_file():
            runs = json.loads(result.read_text()).get("runs", {})
    return {"status": proc.returncode, "measured": wall, "identification": float(runs.get("wall_seconds", float("nan"))),
            "load_before": before, "load_after": after, "runs": runs,
            "error": proc.stderr[-800:] if proc.returncode else ""}


def _minutes(seconds: float) -> str:
    return "-" if not np.isfinite(seconds) else (f"{seconds:.0f} s" if seconds < 90 else f"{seconds / 60:.1f} min")


def table(rows: list, workers: int) -> str:
    """The Markdown table of the rows."""
    lines = [f"| configuration | estimate: likely | upper | measured `fracid identify --workers {workers}` "
             "(identification alone) | measured / likely | measured / upper | runs (failed) | load before / after |",
             "|---|---|---|---|---|---|---|---|"]
    for r in rows:
        runs = r.get("runs", {})
        counts = " + ".join(f"{runs[k]} ({runs.get(k + '_failed', 0)})" for k in runs
                            if not k.startswith(("wall", "kalman_", "knn_", "gauss_newton_")) and isinstance(runs[k], int))
        lines.append(f"| {r['name']} | {_minutes(r['likely'])} | {_minutes(r['upper'])} | {_minutes(r['measured'])} "
                     f"({_minutes(r['identification'])}) | {r['measured'] / r['likely']:.2f} | "
                     f"{r['measured'] / r['upper']:.2f} | {counts or '-'} | "
                     f"{r['load_before']:.2f} / {r['load_after']:.2f} |")
    return "\n".join(lines)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--only", help="comma-separated names among: " + ", ".join(CONFIGS))
    parser.add_argument("--out", type=Path, default=ROOT / "docs" / "speed" / "check_estimate.md")
    parser.add_argument("--measured", type=Path, help="JSON of an earlier run: reuse its identifications, check again")
    args = parser.parse_args(argv)
    names = [n.strip() for n in args.only.split(",")] if args.only else list(CONFIGS)
    before = {r["name"]: r for r in json.loads(args.measured.read_text())["rows"]} if args.measured else {}
    rows = []
    with tempfile.TemporaryDirectory(prefix="fracid-bench-bar-") as scratch:
        for name in names:
            path, what = CONFIGS[name]
            config = path if path is not None else bar_config(Path(scratch))
            row = {"name": name, "what": what, **estimate(config, args.workers)}
            row.update({k: v for k, v in before[name].items() if k not in row} if name in before
                       else measure(config, args.workers))
            rows.append(row)
            print(f"{name}: {row['line']}\n  measured {row['measured']:.1f} s (identification "
                  f"{row['identification']:.1f} s), load {row['load_before']:.2f} / {row['load_after']:.2f}", flush=True)
    text = table(rows, args.workers)
    print(text)
    args.out.parent.mkdir(parents=True, exist_ok=True)
    stamp = time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime())
    args.out.write_text(f"# `fracid check`'s estimate against the measured identification\n\n"
                        f"`python benchmarks/check_estimate.py --workers {args.workers}`, {stamp}, "
                        f"{os.cpu_count()} cores. Load: `os.getloadavg()` (1 min) before and after each identification.\n\n"
                        + text + "\n\nThe estimates' lines:\n\n"
                        + "\n".join(f"- {r['name']}: `{r['line']}`" for r in rows) + "\n")
    args.out.with_suffix(".json").write_text(json.dumps({"workers": args.workers, "date": stamp, "rows": rows},
                                                        indent=1, default=float))
    print(f"wrote {args.out} and {args.out.with_suffix('.json')}")


if __name__ == "__main__":
    main()
