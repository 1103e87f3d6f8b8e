"""Write bar.csv: the synthetic test of this example (the bar with a weak zone, 200 elements, gradient damage at
(c, beta) = (2 mm^2, 250), 12 points of its force-elongation curve up to 0.03 mm plus Gaussian noise of std 0.02 N,
seed 1): a twin, so that the truth is known.

    python make_data.py
"""

from pathlib import Path

import numpy as np

import fracid

TRUTH = {"c": 2.0, "beta": 250.0}
STD = 0.02  # N, as bar.toml's [[experiments]] std


def main() -> None:
    controls = np.linspace(0.0025, 0.03, 12)
    run = fracid.simulate(fracid.BarWithWeakZone(n_elements=200), fracid.DamageParameters(**TRUTH), target=0.03,
                          stop_force_fraction=None, checkpoints=controls)
    force = np.interp(controls, run.control, run.force) + np.random.default_rng(1).normal(0.0, STD, controls.size)
    lines = ["u_mm,F_N", *(f"{u:.6g},{f:.9g}" for u, f in zip(controls, force))]
    (Path(__file__).parent / "bar.csv").write_text("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
