"""Regenerate examples/dic/: synthetic DIC data of the demo's notched beam with gradient damage.

Run from anywhere: ``python examples/dic/make_data.py`` (about 5 s). It writes frame_0001.csv ...
frame_0006.csv and frames.csv beside this file, and load_cmod.csv (the force-CMOD curve of the same run
settings, 40 points, with 5 N noise), and prints what it made (README.md describes it).
"""

from pathlib import Path

import numpy as np

from fracid.fem.material.parameters import DamageParameters
from fracid.data.dic import CameraPlacement
from fracid.inverse.studies.dic_twin import synthetic_dic, write_dic
from fracid.specimens.beam import NotchedBeam

HERE = Path(__file__).resolve().parent

#: the demo's mesh and parameters (src/fracid/datasets/gregoire2013_beam4/demo.toml)
BEAM = NotchedBeam(h_fine=2.0, h_coarse=6.0)
PARAMS = DamageParameters(E=36250.0, nu=0.2, kappa_i=6.6e-5, alpha=0.99, beta=600.0, c=9.0, eta=10.0)
#: CMOD of the frames [mm]: rising branch, the peak (0.034 mm), softening
FRAMES = [0.02, 0.034, 0.05, 0.08, 0.12, 0.2]
#: the camera: 0.1 mm per pixel, turned by 1.5 degrees, pixel (120, 80) on the notch mouth's centre
PLACEMENT = CameraPlacement(scale=0.1, rotation=np.radians(1.5), origin_camera=(120.0, 80.0),
                            origin_specimen=(0.0, 0.0))
#: the specimen settles on its supports: a rigid motion growing with the frames (tx, ty [mm], theta [rad])
RIGID = np.outer(np.linspace(0.2, 1.0, len(FRAMES)), [0.004, -0.012, 5e-5])
#: the force-CMOD curve: CMOD of its points [mm] and the std of its noise [N]
CURVE_CMOD = np.linspace(0.005, 0.2, 40)
CURVE_STD = 5.0


def write_curve() -> Path:
    """Write load_cmod.csv: the force [N] against CMOD [mm] of a run at PARAMS, plus Gaussian noise of CURVE_STD."""
    from fracid.models.forward import simulate

    run = simulate(BEAM, PARAMS, target=float(CURVE_CMOD[-1]), checkpoints=CURVE_CMOD)
    force = np.interp(CURVE_CMOD, run.control, run.force)
    noisy = force + np.random.default_rng(2028).normal(0.0, CURVE_STD, CURVE_CMOD.size)
    path = HERE / "load_cmod.csv"
    rows = "".join(f"{c:.10g},{f:.10g}\n" for c, f in zip(CURVE_CMOD, noisy))
    path.write_text("cmod_mm,force_N\n" + rows)
    return path


def main() -> None:
    data = synthetic_dic(BEAM, PARAMS, frames=FRAMES, spacing=3.8, std=1e-3, subset_size=6.0, holes=3.0,
                         rigid_body=RIGID, placement=PLACEMENT, seed=2027)
    files = write_dic(HERE, data)
    size = sum(f.stat().st_size for f in files)
    print(f"{len(data.X)} points ({int(data.holes.sum())} holes), {len(FRAMES)} frames, "
          f"{len(files)} files, {size / 1e3:.0f} kB in {HERE}")
    for cmod, force in zip(data.control, data.force):
        print(f"  CMOD {cmod:.3f} mm  force {force:7.1f} N")
    print(f"force-CMOD curve: {write_curve()}")


if __name__ == "__main__":
    main()
