"""Benchmark: the notched beam's default mesh on a long beam against a hand-tuned coarse size.

A beam of span 8 D (D = 100 mm deep, span 800 mm, length 900 mm, notch 50 mm deep, 10 mm plates, so
the overhang and the notch keep the Gregoire proportions) once with the default mesh settings (only
``h_fine`` given; ``h_coarse`` and ``fine_width`` derived from the depth) and once with a hand-tuned
``h_coarse`` (the rest the same), both traced with the gradient-damage model's default parameters
under CMOD control until the force falls to ``--stop`` of the peak. Per case it prints the mesh
settings, unknowns, steps, iterations, wall time and peak force, then the ratios of the default's to
the hand-tuned's wall time and peak force (measured in one run, one after the other).

Done when the default is within 2x of the hand-tuned time at a peak within 1 %.

    python benchmarks/mesh_defaults.py [--h-coarse 20] [--h-fine 1] [--stop 0.5] [--cases default,tuned,old]
                                       [--figure docs/mesh_defaults/meshes.png]

``old`` is the mesh the beam had before its defaults scaled with the depth (``h_coarse = 4``,
``fine_width = 10`` mm whatever the geometry). ``--figure`` draws the half meshes of the cases (no run).
"""

from __future__ import annotations

import argparse
import time

import fracid
from fracid.models import DamageModel
from fracid.specimens.beam import NotchedBeam

LONG = dict(depth=100.0, span=800.0, length=900.0, notch_depth=50.0, plate_width=10.0)


def specimens(h_fine: float, h_coarse: float) -> dict:
    """{case: NotchedBeam}: the default mesh, the hand-tuned coarse size and the former fixed mesh."""
    default = NotchedBeam(h_fine=h_fine, **LONG)
    return {"default": default,
            "tuned": NotchedBeam(h_fine=h_fine, h_coarse=h_coarse, fine_width=default.fine_width, **LONG),
            "old": NotchedBeam(h_fine=h_fine, h_coarse=4.0, fine_width=10.0, **LONG)}


def run(name: str, beam: NotchedBeam, stop: float) -> tuple[float, float]:
    """One forward run, printed; returns (wall [s], peak force [N])."""
    params = fracid.DamageParameters()
    unknowns = DamageModel().build(beam, params).n_free + 1
    start = time.perf_counter()
    result = fracid.simulate(beam, params, stop_force_fraction=stop)
    wall = time.perf_counter() - start
    s = result.stats
    print(f"{name:8s} h_coarse {beam.h_coarse:5.1f}  fine_width {beam.fine_width:5.1f} mm  unknowns {unknowns:6d}  "
          f"steps {s.steps:4d}  iterations {s.iterations:5d}  wall {wall:7.2f} s  "
          f"peak force {result.peak_force:10.2f} N  ({result.status})", flush=True)
    return wall, result.peak_force


def draw(beams: dict, path: str) -> None:
    """The element edges of each half beam, one above the other, saved to ``path``."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.collections import LineCollection

    fig, axes = plt.subplots(len(beams), 1, figsize=(8, 2.0 * len(beams)), sharex=True)
    for ax, (name, beam) in zip(axes, beams.items()):
        mesh = beam.mesh()
        corners = mesh.nodes[mesh.cells[:, [0, 1, 2, 3, 0]]]
        ax.add_collection(LineCollection(corners, linewidths=0.2, colors="k"))
        ax.set_aspect("equal")
        ax.autoscale()
        ax.set_title(f"{name}: h_coarse {beam.h_coarse:g} mm, fine_width {beam.fine_width:g} mm, "
                     f"{len(mesh.nodes)} nodes", fontsize=9)
    axes[-1].set_xlabel("x [mm] (half beam, the ligament at x = 0)")
    fig.tight_layout()
    fig.savefig(path, dpi=150)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--h-coarse", type=float, default=20.0, help="hand-tuned coarse size [mm]")
    parser.add_argument("--h-fine", type=float, default=1.0, help="process-zone element size [mm]")
    parser.add_argument("--stop", type=float, default=0.5, help="stop below this share of the peak force")
    parser.add_argument("--cases", default="default,tuned", help="comma-separated, from default, tuned, old")
    parser.add_argument("--figure", help="draw the meshes of --cases to this file instead of running them")
    args = parser.parse_args(argv)
    beams = specimens(args.h_fine, args.h_coarse)
    if args.figure:
        return draw({name: beams[name] for name in args.cases.split(",")}, args.figure)
    runs = {name: run(name, beams[name], args.stop) for name in args.cases.split(",")}
    if "tuned" in runs:
        wall, peak = runs["tuned"]
        for name, (w, p) in runs.items():
            if name != "tuned":
                print(f"{name:8s} / tuned: wall x {w / wall:5.2f}  peak force {100 * (p / peak - 1):+.3f} %")


if __name__ == "__main__":
    main()
