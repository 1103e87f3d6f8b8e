"""Twin-experiment matrix on the dog-bone: which data identify (c, beta)? Figures for docs/twin_matrix.

Synthetic data at (c, beta) = (25 mm^2, 300) with 2 % noise on the forces and 2 mm on the FPZ width
(damage > 0.5), identified back by the full study (KNN, Kalman filter, multi-start, stability under
noise) from four data sets: the force curve of one size (D = 100 mm); of three sizes (50, 100,
200 mm); of one size plus its FPZ width; all of them. Writes a table (twin_matrix.json, .md), a
summary figure and each case's valley and stability figures.

    python benchmarks/twin_matrix.py [--h-fine 2.5] [--population 32] [--replicates 4] [--out docs/twin_matrix]
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np

import fracid
from fracid.inverse.core.space import ParameterSpace
from fracid.inverse.studies.twin import dogbone_cases, twin_matrix
from fracid.runtime.executors import make_executor
from fracid.report.figures import _new_figure, to_png
from fracid.report.study import stability_figure, valley_figure

BASE = fracid.DamageParameters(E=30000.0, nu=0.2, kappa_i=1e-4, alpha=0.99, beta=300.0, c=25.0)
TRUTH = np.array([25.0, 300.0])
SPACE = ParameterSpace(("c", "beta"), [5.0, 100.0], [80.0, 900.0], log=(True, True))
NOISE = {"force D50:relative": 0.02, "force D100:relative": 0.02, "force D200:relative": 0.02, "fpz D100": 2.0}


def summary_figure(outcomes):
    """|correlation(c, beta)|, expected and realised relative errors per case."""
    names = list(outcomes)
    fig = _new_figure(11.0, 3.8)
    left, mid, right = fig.subplots(1, 3)
    x = np.arange(len(names))
    left.bar(x, [abs(outcomes[n].correlation[0, 1]) for n in names], color="#1f77b4")
    left.axhline(0.9, color="k", ls="--", lw=0.8)
    left.set_ylim(0.8, 1.0)
    left.set_ylabel("|correlation(c, beta)| [-]")
    for j, (ax, name) in enumerate(((mid, "c"), (right, "beta"))):
        rel_std = [outcomes[n].relative_std[j] for n in names]
        err = [abs(outcomes[n].relative_error[j]) for n in names]
        ax.bar(x - 0.2, rel_std, 0.4, label="posterior std / estimate")
        ax.bar(x + 0.2, err, 0.4, label="|estimate - truth| / truth")
        scatter = [outcomes[n].study.stability.relative_scatter[j] for n in names
                   if outcomes[n].study.stability is not None]
        if len(scatter) == len(names):
            ax.plot(x, scatter, "kD", ms=6, label="scatter over noisy replicates")
        ax.set_yscale("log")
        ax.set_ylabel(f"relative error of {name} [-]")
        ax.legend(fontsize="x-small")
    for ax in (left, mid, right):
        ax.set_xticks(x, names, rotation=20, fontsize=8)
        ax.grid(alpha=0.3, axis="y")
    fig.suptitle("Twin experiments on dog-bones: (c, beta) = (25 mm^2, 300), 2 % force noise, 2 mm FPZ noise",
                 fontsize="medium")
    return fig


def markdown(rows, seconds):
    lines = ["# Twin matrix: every parameter subset and data set, identified back from synthetic data", "",
             "| case | values | corr(c, beta) | c: estimate, error, std | beta: estimate, error, std | "
             "scatter c, beta (replicates) | verdict c / beta | wall |",
             "|---|---|---|---|---|---|---|---|"]
    for row in rows:
        scatter = row.get("scatter") or ["-", "-"]
        scatter = ", ".join(f"{s:.1%}" if isinstance(s, float) else s for s in scatter)
        lines.append(
            f"| {row['case']} | {row['n_y']} | {row['corr_c_beta']:+.4f} | {row['c_estimate']:.3g}, "
            f"{row['c_error']:+.1%}, {row['c_rel_std']:.1%} | {row['beta_estimate']:.4g}, {row['beta_error']:+.1%}, "
            f"{row['beta_rel_std']:.1%} | {scatter} | {row['c_verdict']} / {row['beta_verdict']} | "
            f"{seconds[row['case']]:.0f} s |")
    return "\n".join(lines) + "\n"


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--h-fine", type=float, default=2.5)
    parser.add_argument("--population", type=int, default=32)
    parser.add_argument("--replicates", type=int, default=4)
    parser.add_argument("--starts", type=int, default=3)
    parser.add_argument("--out", type=Path, default=Path("docs/twin_matrix"))
    args = parser.parse_args(argv)
    args.out.mkdir(parents=True, exist_ok=True)
    cases = dogbone_cases(BASE, h_fine=args.h_fine)
    outcomes, seconds = {}, {}
    with make_executor(2) as executor:
        for name, operator in cases.items():
            start = time.perf_counter()
            outcomes.update(twin_matrix({name: operator}, TRUTH, NOISE, SPACE, seed=1, n=args.population, k=4, groups="all", prior="bounds",
                                        max_iterations=8, starts=args.starts, replicates=args.replicates,
                                        executor=executor, log=print))
            seconds[name] = time.perf_counter() - start
            print(f"  {seconds[name]:.0f} s; " + outcomes[name].study.verdict.text().splitlines()[0])
    rows = []
    for name, outcome in outcomes.items():
        row = outcome.row()
        if outcome.study.stability is not None:
            row["scatter"] = outcome.study.stability.relative_scatter.tolist()
        row["seconds"] = seconds[name]
        row["verdict"] = outcome.study.verdict.text()
        rows.append(row)
        slug = name.replace(" ", "_").replace("+", "plus")
        (args.out / f"valley_{slug}.png").write_bytes(to_png(valley_figure(outcome.study.maps, outcome.study.multi_start,
                                                                           TRUTH, outcome.study.names)))
        if outcome.study.stability is not None:
            ident = outcome.study.identification
            (args.out / f"stability_{slug}.png").write_bytes(
                to_png(stability_figure(outcome.study.stability, outcome.study.names, ident.x, ident.std)))
    (args.out / "summary.png").write_bytes(to_png(summary_figure(outcomes)))
    settings = {"h_fine": args.h_fine, "population": args.population, "replicates": args.replicates,
                "starts": args.starts, "truth": TRUTH.tolist(), "noise": NOISE}
    (args.out / "twin_matrix.json").write_text(json.dumps({"settings": settings, "cases": rows}, indent=1))
    (args.out / "twin_matrix.md").write_text(markdown(rows, seconds))
    print(markdown(rows, seconds))


if __name__ == "__main__":
    main()
