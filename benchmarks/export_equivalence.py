"""Benchmark: what an exported law reproduces on the specimen it was identified on, written to docs/export/.

1. Own law (cohesive crack, crack band; Hordijk, ft = 3 MPa, Gf = 0.1 N/mm) on the Grégoire beam: the model, then
   the same model with the law read back from ``fracid export --to csv`` (TabularSoftening): largest force
   difference over the curve in % of the peak (issue 42's verification; the test runs a coarser mesh).
2. Equivalent law (the bundled demo's gradient-damage estimate, docs/demo/result.json): the gradient damage model on
   the beam against the cohesive crack and the crack band running its equivalent law (the bar's): peak and
   largest force difference in % of the peak, dissipated energy. This measures the equivalence, not a defect: the
   continuum band in 2D is not the bar's.

    python benchmarks/export_equivalence.py [--out docs/export]
"""

from __future__ import annotations

import argparse
import json
import time
from dataclasses import replace
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from fracid.exchange.csv_law import read_law_csv, write_csv
from fracid.exchange.identified import read_identified
from fracid.exchange.units import UNIT_SYSTEMS
from fracid.fem.material.tabular_law import TabularSoftening
from fracid.models import CohesiveCrackModel, CrackBandModel
from fracid.report.figures import to_png
from fracid.specimens.beam import NotchedBeam

ROOT = Path(__file__).resolve().parents[1]
BEAM = NotchedBeam(h_fine=2.0, h_coarse=6.0)  # the demo's mesh
CRACK = {"E": 36250.0, "nu": 0.2, "ft": 3.0, "Gf": 0.1}


def tabular(model, table, E, nu, folder):
    """``model`` with the law read back from the CSV export of ``table``, and its parameters."""
    path = folder / f"{model.key}.csv"
    identified = read_identified(ROOT / "docs/demo/result.json")  # only for the header's lines
    path.write_text(write_csv(identified, table, UNIT_SYSTEMS["N-mm-MPa"]))
    w, sigma = read_law_csv(path)
    law = TabularSoftening.from_table(w, sigma)
    return replace(model, law=law), law.table_parameters(w, sigma, E=E, nu=nu)


def compared(reference, other) -> dict:
    """Peak and largest force difference of ``other`` against ``reference`` over the reference's controls."""
    upto = reference.control <= other.control[-1]
    force = np.interp(reference.control[upto], other.control, other.force)
    return {"peak_N": float(other.peak_force), "peak_ratio": float(other.peak_force / reference.peak_force),
            "max_difference_percent_of_peak": float(100 * np.max(np.abs(force - reference.force[upto]))
                                                    / reference.peak_force),
            "energy_Nmm": float(np.trapezoid(other.force, other.control))}


def timed_run(model, params, target=None):
    start = time.perf_counter()
    run = model.simulate(BEAM, params, target=target)
    return run, time.perf_counter() - start


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=ROOT / "docs/export")
    out = parser.parse_args().out
    out.mkdir(parents=True, exist_ok=True)
    figure = Figure(figsize=(11, 4.2))
    axes = figure.subplots(1, 2)
    summary = {"own_law": {}, "equivalent_law": {}}
    for model in (CohesiveCrackModel(), CrackBandModel()):
        params = model.parameters(**CRACK)
        reference, seconds = timed_run(model, params)
        again, params_again = tabular(model, model.cohesive_law(params), params.E, params.nu, out)
        run, seconds_tab = timed_run(again, params_again, target=reference.control[-1])
        summary["own_law"][model.key] = {**compared(reference, run), "seconds": seconds, "seconds_tabular": seconds_tab}
        axes[0].plot(reference.control, reference.force, label=f"{model.key}")
        axes[0].plot(run.control, run.force, "--", label=f"{model.key}, law from the CSV")
    identified = read_identified(ROOT / "docs/demo/result.json")
    reference, seconds = timed_run(identified.model, identified.params)
    table = identified.model.cohesive_law(identified.params)
    summary["equivalent_law"]["table"] = {"how": table.how, "strength_MPa": table.strength,
                                          "fracture_energy_Nmm": table.fracture_energy}
    summary["equivalent_law"][identified.model.key] = {**compared(reference, reference), "seconds": seconds}
    axes[1].plot(reference.control, reference.force, "k", label="gradient damage (demo estimate)")
    for model in (CohesiveCrackModel(), CrackBandModel()):
        again, params_again = tabular(model, table, identified.params.E, identified.params.nu, out)
        run, seconds_tab = timed_run(again, params_again, target=reference.control[-1])
        summary["equivalent_law"][model.key] = {**compared(reference, run), "seconds": seconds_tab}
        axes[1].plot(run.control, run.force, "--", label=f"{model.key}, equivalent law")
    for ax, title in zip(axes, ("own law, and read back from the CSV", "gradient damage and its equivalent law")):
        ax.set(xlabel="CMOD [mm]", ylabel="force [N]", title=title)
        ax.legend(fontsize=8)
    figure.tight_layout()
    (out / "beam.png").write_bytes(to_png(figure))
    (out / "summary.json").write_text(json.dumps(summary, indent=1))
    print(json.dumps(summary, indent=1))


if __name__ == "__main__":
    main()
