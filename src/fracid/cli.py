"""The ``fracid`` command. A thin layer over the Python API.

Subcommands
-----------
demo
    The bundled default job: for now, a forward analysis of the bar with a weak zone under the
    default gradient-damage parameters, printing its force-displacement curve.
"""

from __future__ import annotations

import argparse
import sys

from fracid.forward import simulate
from fracid.model.parameters import DamageParameters
from fracid.model.path_following import ConvergenceError
from fracid.specimens.bar import BarWithWeakZone


def _demo(args) -> int:
    params = DamageParameters()
    bar = BarWithWeakZone(n_elements=args.elements)
    print(f"fracid demo: bar with a weak zone, L = {bar.length:g} mm, W = {bar.weak_zone_width:g} mm, "
          f"E reduced to {bar.weak_zone_factor:g} E in the zone, {bar.n_elements} elements")
    print("parameters: " + ", ".join(f"{n} = {getattr(params, n):g} {u}" for n, u in params.units().items()))
    try:
        result = simulate(bar, params, stop_force_fraction=0.1)
    except ConvergenceError as err:
        print(f"fracid demo: the analysis failed: {err}", file=sys.stderr)
        return 1
    print(f"{'step':>4} {'u_end [mm]':>12} {'F [N]':>10} {'damaged zone [mm]':>18} {'dissipated [N mm]':>18}")
    width, energy = result.observables["damaged_zone_width"], result.observables["dissipated_energy"]
    for i in range(result.n_steps + 1):
        print(f"{i:4d} {result.control[i]:12.6f} {result.force[i]:10.5f} {width[i]:18.3f} {energy[i]:18.6f}")
    s = result.stats
    print(f"peak force {result.peak_force:.5f} N; {result.status}; {s.steps} steps, {s.iterations} Newton iterations, "
          f"{s.time_total:.3f} s ({s.time_linear / s.time_total:.0%} in sparse factorizations and solves)")
    return 0


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="fracid", description="Parameter identification for localized-failure models.")
    sub = parser.add_subparsers(dest="command", required=True)
    demo = sub.add_parser("demo", help="run the bundled default job and print its result")
    demo.add_argument("--elements", type=int, default=200, help="number of bar elements (default 200)")
    args = parser.parse_args(argv)
    if args.command == "demo":
        if args.elements < 3:
            parser.error(f"--elements = {args.elements}: at least 3 are needed")
        return _demo(args)
    return 2  # unreachable: argparse rejects unknown commands


if __name__ == "__main__":
    sys.exit(main())
