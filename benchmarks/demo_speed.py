"""Benchmark: ``fracid demo`` against one ``fracid simulate`` of the demo configuration, in the same install.

It runs, interleaved and ``--repeats`` times, in a temporary directory with this interpreter (``python -m fracid``,
so the install or PYTHONPATH that runs this script is the one measured):

    fracid simulate <demo.toml> --out sim<i> --quiet
    fracid demo --out demo<i> --quiet                     # [identify.knn] screening: the configuration's default
    fracid identify <demo.toml, screening = S> ...        # per --screening S (1: the population on the configured mesh)

and prints a table of the wall times (from outside: the commands as a user runs them), the ratios to the best
simulate of the same repeat and over all repeats (best / best), and each identification's estimate against the
reference (``--reference`` result.json, else the first screening given, usually 1: today's demo) in the
reference's standard deviations. Timings on a shared machine are noisy: the load (``os.getloadavg()``) is printed
before each command; compare ratios measured in one run.

Thread variables: the solver is single-threaded; on a busy machine a multithreaded BLAS in the command's own
process (``fracid simulate`` runs its analysis there, an identification in its workers, which start with one
thread) slows it several times. ``--one-thread`` sets OMP/OPENBLAS/MKL_NUM_THREADS=1 for every command (the fair
comparison); without it the environment is left as it is.

    python benchmarks/demo_speed.py [--repeats 3] [--screening 1,2] [--one-thread] [--reference result.json]
        [--markdown docs/speed/demo_speed.md]
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

THREADS = ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS")


def demo_config() -> Path:
    from fracid.cli.common import demo_config_path

    return Path(demo_config_path())


def screened_config(directory: Path, screening: float) -> Path:
    """A copy of the demo configuration (and its data) with ``[identify.knn] screening`` set."""
    source = demo_config()
    for data in source.parent.glob("*.csv"):
        (directory / data.name).write_bytes(data.read_bytes())
    text = source.read_text().replace("[identify.knn]\n", f"[identify.knn]\nscreening = {screening:g}\n", 1)
    path = directory / f"screening{screening:g}.toml"
    path.write_text(text)
    return path


def timed(args, cwd: Path, env) -> tuple[float, float]:
    """(wall, CPU) seconds of ``fracid ARGS``: the CPU time (user + system) of the command and its workers, which a
    busy machine stretches less than the wall time."""
    before, start = resource.getrusage(resource.RUSAGE_CHILDREN), time.perf_counter()
    proc = subprocess.run([sys.executable, "-m", "fracid", *map(str, args)], cwd=cwd, env=env, capture_output=True,
                          text=True)
    seconds, after = time.perf_counter() - start, resource.getrusage(resource.RUSAGE_CHILDREN)
    if proc.returncode != 0:
        raise SystemExit(f"fracid {' '.join(map(str, args))} exited {proc.returncode}:\n{proc.stderr[-3000:]}")
    return seconds, (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def estimate(result: Path):
    data = json.loads(result.read_text())
    return np.asarray(data["x"], float), np.asarray(data["std"], float), data["names"]


def load() -> str:
    try:
        return f"{os.getloadavg()[0]:.2f}"
    except (AttributeError, OSError):
        return "?"


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--screening", default="1", help="comma-separated screening factors run besides fracid demo")
    parser.add_argument("--one-thread", action="store_true", help="OMP/OPENBLAS/MKL_NUM_THREADS=1 for every command")
    parser.add_argument("--reference", type=Path, help="result.json of the reference estimate")
    parser.add_argument("--markdown", type=Path, help="append the table to this file")
    args = parser.parse_args(argv)
    env = {**os.environ, **({name: "1" for name in THREADS} if args.one_thread else {})}
    factors = [float(s) for s in args.screening.split(",") if s.strip()]
    rows, results = [], {}
    with tempfile.TemporaryDirectory(prefix="fracid-demo-speed-") as tmp:
        tmp = Path(tmp)
        configs = {f: screened_config(tmp, f) for f in factors}
        for i in range(args.repeats):
            jobs = [("simulate", ["simulate", demo_config(), "--out", f"sim{i}", "--quiet"], None),
                    ("demo", ["demo", "--out", f"demo{i}", "--quiet"], f"demo{i}")]
            jobs += [(f"identify screening {f:g}", ["identify", configs[f], "--out", f"s{f:g}_{i}", "--quiet"],
                      f"s{f:g}_{i}") for f in factors]
            for name, command, out in jobs:
                before = load()
                seconds, cpu = timed(command, tmp, env)
                rows.append((i, name, seconds, before, cpu))
                if out is not None:
                    results.setdefault(name, []).append(estimate(tmp / out / "result.json"))
                print(f"repeat {i + 1}: {name:24s} {seconds:7.1f} s, CPU {cpu:7.1f} s (load {before})", flush=True)
    lines = table(rows, results, args, factors)
    print("\n".join(lines))
    if args.markdown is not None:
        with open(args.markdown, "a") as handle:
            handle.write("\n".join(lines) + "\n")
    return 0


def table(rows, results, args, factors) -> list[str]:
    """The markdown table: per command its times, best time, ratio to the best simulate, and the estimate's change."""
    if args.reference is not None:
        ref_x, ref_std, names = estimate(args.reference)
        ref_name = str(args.reference)
    else:
        first = f"identify screening {factors[0]:g}" if factors else "demo"
        ref_x, ref_std, names = results[first][0]
        ref_name = first
    best_sim = min(s for _, name, s, *_ in rows if name == "simulate")
    best_sim_cpu = min(c for _, name, _, _, c in rows if name == "simulate")
    threads = ", ".join(f"{n}={os.environ.get(n, 'unset')}" for n in THREADS)
    lines = [f"`python benchmarks/demo_speed.py --repeats {args.repeats} --screening {args.screening}"
             f"{' --one-thread' if args.one_thread else ''}` ({'one BLAS thread' if args.one_thread else threads}; "
             f"Python {sys.version.split()[0]}; reference estimate: {ref_name})", "",
             "| command | wall times [s] | best [s] | best / best simulate | CPU [s] (best) | CPU / simulate's CPU "
             "| estimate change [std of the reference] |",
             "|---|---|---|---|---|---|---|"]
    for name in dict.fromkeys(name for _, name, *_ in rows):
        times = [s for _, n, s, *_ in rows if n == name]
        cpu = min(c for _, n, _, _, c in rows if n == name)
        change = ""
        if name in results:
            shifts = [np.abs(x - ref_x) / ref_std for x, _, _ in results[name]]
            worst = np.max(shifts, axis=0)
            change = ", ".join(f"{n} {v:.3f}" for n, v in zip(names, worst))
        lines.append(f"| {name} | {', '.join(f'{t:.1f}' for t in times)} | {min(times):.1f} | "
                     f"{min(times) / best_sim:.1f} | {cpu:.1f} | {cpu / best_sim_cpu:.1f} | {change} |")
    lines.append(f"\nload (1-min average) before each command: {', '.join(load for _, _, _, load, _ in rows)}")
    return lines


if __name__ == "__main__":
    raise SystemExit(main())
