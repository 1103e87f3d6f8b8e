"""Benchmark: verification figures of the other failure models ([6/6]), written to docs/other_models/.

1. Crack band in tension (`TensionStrip`, three element sizes): dissipated energy at separation against
   Gf x crack area, with the law scaled by the element width and unscaled (one width for all meshes).
2. Notched beam (Gregoire geometry), one (ft, Gf): the discrete cohesive crack and the crack band at
   three element sizes along the ligament: peak, forces after the peak, dissipated energy, wall time.
3. Bar with a weak zone, 200 and 400 elements: integral nonlocal, implicit gradient and local damage
   (same parameters, l = sqrt(2 c)): peak, final force, dissipated energy, wall time.

    python benchmarks/other_models.py [--out docs/other_models]
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

import fracid
from fracid.fem.material.cohesive import CohesiveParameters
from fracid.fem.path.path_following import follow_path
from fracid.models import CohesiveCrackModel, CrackBandModel, DamageModel
from fracid.report.figures import to_png
from fracid.specimens.beam import NotchedBeam
from fracid.specimens.strip import TensionStrip

COHESIVE = CohesiveParameters(E=37000.0, nu=0.2, ft=3.0, Gf=0.1)
DAMAGE = fracid.DamageParameters(E=20000.0, kappa_i=1e-4, alpha=0.99, beta=300.0, c=2.0)


def _timed(fn):
    start = time.perf_counter()
    result = fn()
    return result, time.perf_counter() - start


def strip_energies():
    rows, curves = [], []
    area = TensionStrip().height * TensionStrip().thickness
    for n in (11, 21, 41):
        for band in (None, 4.8):
            strip = TensionStrip(n_elements=n)
            problem = CrackBandModel(band).build(strip, COHESIVE)
            target = CrackBandModel().default_target(strip, COHESIVE) * (1.0 if band is None else strip.element_size / band)
            result, wall = _timed(lambda: follow_path(problem, "band_opening", target, steps=strip.default_steps(target),
                                                      stop_force_fraction=None))
            energy = result.observables["dissipated_energy"][-1]
            rows.append({"h": strip.element_size, "band": "element width" if band is None else f"{band} mm for all",
                         "energy": energy, "error": energy / (COHESIVE.Gf * area) - 1.0, "steps": result.n_steps,
                         "wall": wall})
            curves.append((rows[-1], result.observables["elongation"], result.force))
    return rows, curves


def beam_curves():
    rows, curves = [], []
    for model in (CohesiveCrackModel(), CrackBandModel()):
        for h in (4.0, 2.0, 1.0):
            beam = NotchedBeam(h_fine=h, h_coarse=max(2 * h, 4.0))
            result, wall = _timed(lambda: model.simulate(beam, COHESIVE, target=0.3, stop_force_fraction=None))
            forces = np.interp([0.05, 0.1, 0.2, 0.3], result.control, result.force)
            rows.append({"model": model.key, "h": h, "peak": result.peak_force, "forces": forces,
                         "energy": result.observables["dissipated_energy"][-1], "steps": result.n_steps,
                         "iterations": result.stats.iterations, "wall": wall})
            curves.append((rows[-1], result.control, result.force))
    return rows, curves


def bar_objectivity():
    rows, curves = [], []
    for regularization in ("integral", "gradient", "local"):
        for n in (200, 400):
            bar = fracid.BarWithWeakZone(n_elements=n, profile="hat")
            result, wall = _timed(lambda: fracid.simulate(bar, DAMAGE, model=DamageModel(regularization),
                                                          control="weak_zone_elongation", target=0.03,
                                                          stop_force_fraction=None))
            rows.append({"model": regularization, "n": n, "peak": result.peak_force, "final": result.force[-1],
                         "energy": result.observables["dissipated_energy"][-1], "steps": result.n_steps, "wall": wall})
            curves.append((rows[-1], result.observables["end_displacement"], result.force))
    return rows, curves


def _figure(curves, label, xlabel, path):
    fig = Figure(figsize=(6.0, 4.0), layout="constrained")
    ax = fig.add_subplot()
    for row, x, force in curves:
        ax.plot(x, force, label=label(row))
    ax.set_xlabel(xlabel)
    ax.set_ylabel("force [N]")
    ax.legend(fontsize=7)
    path.write_bytes(to_png(fig))


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default="docs/other_models")
    args = parser.parse_args(argv)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    lines = ["# Other models: verification figures", "", "Written by `python benchmarks/other_models.py` "
             "(one run on a 2-core machine; wall times are that run's).", ""]

    rows, curves = strip_energies()
    lines += ["## Crack band in tension: energy per crack area", "",
              f"Strip 100 x 10 x 10 mm, E {COHESIVE.E:g} MPa, ft {COHESIVE.ft:g} MPa, Gf {COHESIVE.Gf:g} N/mm, "
              "weak middle column (0.98 ft, same Gf), crack opened to 0.99 wc. Gf x area = 10 N mm.", "",
              "| element [mm] | law scaled by | dissipated [N mm] | vs Gf x area | steps | wall [s] |", "|---|---|---|---|---|---|"]
    lines += [f"| {r['h']:.2f} | {r['band']} | {r['energy']:.4f} | {r['error']:+.2%} | {r['steps']} | {r['wall']:.1f} |"
              for r in rows]
    _figure(curves, lambda r: f"h {r['h']:.1f} mm, {r['band']}", "platen displacement [mm]", out / "strip.png")
    lines += ["", "![strip](strip.png)", ""]

    rows, curves = beam_curves()
    lines += ["## Notched beam: cohesive crack and crack band, same (ft, Gf)", "",
              "Gregoire geometry; the crack band lies in the element column on the symmetry line above the notch "
              "(band width 2 mm, the notch's); h is the element size along the ligament.", "",
              "| model | h [mm] | peak [N] | F at CMOD 0.05 / 0.1 / 0.2 / 0.3 mm [N] | dissipated to 0.3 mm [N mm] "
              "| steps | iterations | wall [s] |", "|---|---|---|---|---|---|---|---|"]
    lines += [f"| {r['model']} | {r['h']:g} | {r['peak']:.1f} | {' / '.join(f'{f:.1f}' for f in r['forces'])} | "
              f"{r['energy']:.2f} | {r['steps']} | {r['iterations']} | {r['wall']:.1f} |" for r in rows]
    _figure(curves, lambda r: f"{r['model']}, h {r['h']:g} mm", "CMOD [mm]", out / "beam.png")
    lines += ["", "![beam](beam.png)", ""]

    rows, curves = bar_objectivity()
    lines += ["## Bar with a weak zone: integral, gradient and local damage", "",
              f"L 100 mm, hat-shaped weak zone (10 mm, 0.9), {DAMAGE}; integral length l = sqrt(2 c). "
              "Weak-zone elongation to 0.03 mm.", "",
              "| model | elements | peak [N] | final force [N] | dissipated [N mm] | steps | wall [s] |",
              "|---|---|---|---|---|---|---|"]
    lines += [f"| {r['model']} | {r['n']} | {r['peak']:.5f} | {r['final']:.5f} | {r['energy']:.6f} | {r['steps']} | "
              f"{r['wall']:.2f} |" for r in rows]
    _figure(curves, lambda r: f"{r['model']}, {r['n']} elements", "end displacement [mm]", out / "bar.png")
    lines += ["", "![bar](bar.png)", ""]
    (out / "README.md").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
