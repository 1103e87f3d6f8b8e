"""Benchmark: the gradient model on triangles (T6/T3) against quadrilaterals (Q8/Q4), and mesh objectivity.

The notched beam of the OOFEM comparison (E 37000, nu 0.2, kappa_i 1.1e-4, alpha 0.99, beta 500, c 4, eta
10, 5 mm plates) to CMOD 0.08 mm: built-in Q8 meshes at h_fine = 2, 1, 0.5 mm, and the same meshes written
with ``write_gmsh`` as linear triangles (each quadrilateral split in two) and read back as a mesh specimen
(T6). Prints, per h_fine, the unknowns, the peak forces, their ratio and the largest difference of the
force-CMOD curves relative to the peak, and the change of each family's peak and curve from h to h/2
(its own discretization error, to compare the difference between the families with).

    python benchmarks/triangles.py [--h 2,1,0.5] [--c 4]
"""

from __future__ import annotations

import argparse
import tempfile
import time
from pathlib import Path

import numpy as np

import fracid
from fracid.models import DamageModel
from fracid.specimens.beam import NotchedBeam
from fracid.specimens.mesh import MeshSpecimen, write_gmsh

POINTS = np.linspace(0.01, 0.08, 15)


def triangle_beam(beam, path):
    write_gmsh(beam.describe(), path, triangles=True)
    return MeshSpecimen(str(path), thickness=beam.thickness, supports=(("support", "y"),),
                        loads=(("loading_plate", "y", True, -0.5),), symmetry=(("ligament", "x"),),
                        controls=(("cmod", (("mouth", "x", 2.0),)),), symmetry_factor=2.0,
                        crack=("ligament", "x", beam.h_fine))


def run(specimen, params):
    start = time.perf_counter()
    result = DamageModel().simulate(specimen, params, target=POINTS[-1], stop_force_fraction=None, control="cmod",
                                    checkpoints=POINTS)
    return result, time.perf_counter() - start


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--h", default="2,1,0.5")
    parser.add_argument("--c", type=float, default=4.0)
    args = parser.parse_args(argv)
    params = fracid.DamageParameters(E=37000.0, nu=0.2, kappa_i=1.1e-4, alpha=0.99, beta=500.0, c=args.c, eta=10.0)
    peaks = {"Q8": [], "T6": []}
    curves_of = {"Q8": [], "T6": []}  # force at POINTS, per h
    with tempfile.TemporaryDirectory() as tmp:
        for h in [float(v) for v in args.h.split(",")]:
            beam = NotchedBeam(h_fine=h, h_coarse=10.0)
            q8, t_q8 = run(beam, params)
            t6, t_t6 = run(triangle_beam(beam, Path(tmp) / f"beam_{h:g}.msh"), params)
            curves = np.max(np.abs(np.interp(POINTS, t6.control, t6.force) - np.interp(POINTS, q8.control, q8.force)))
            n_q8 = DamageModel().build(beam, params).n_free
            print(f"h_fine {h:4g} mm  Q8: {n_q8:6d} unknowns, peak {q8.peak_force:8.2f} N ({t_q8:5.1f} s)  "
                  f"T6: peak {t6.peak_force:8.2f} N ({t_t6:5.1f} s)  T6/Q8 - 1 = {t6.peak_force / q8.peak_force - 1:+.4f}  "
                  f"curves differ by {curves / q8.peak_force:.4f} of the peak", flush=True)
            for family, result in (("Q8", q8), ("T6", t6)):
                peaks[family].append(result.peak_force)
                curves_of[family].append(np.interp(POINTS, result.control, result.force))
    for family, values in peaks.items():
        changes = ", ".join(f"{b / a - 1:+.4f}" for a, b in zip(values[:-1], values[1:]))
        own = ", ".join(f"{np.max(np.abs(b - a)) / peak:.4f}"
                        for a, b, peak in zip(curves_of[family][:-1], curves_of[family][1:], values[1:]))
        print(f"{family}: peak change from h to h/2: {changes}; largest curve change / peak: {own}")


if __name__ == "__main__":
    main()
