"""Camera-resolution DIC field through ``fracid check`` (fracid issue 41, item 1): set-up time and peak memory.

The twin case of the issue: the DIC example's beam, parameters, frames, camera placement and rigid motion
(examples/dic/make_data.py) with subset centres on a 1 mm grid (about 8 700 points a frame: the camera sees both halves of the beam), 6 frames, u and v,
noise correlated over ``--subset`` mm (:mod:`fracid.data.dic_noise`), loaded unthinned (no ``point_spacing``).
The data are written to ``--out`` (a temporary folder by default) with the example's configuration, then
``fracid check`` runs as a child process; the script prints its wall time (reading, placement and the
covariance's set-up: the set-up is nearly all of it at this size), the child's peak resident memory
(``resource.getrusage(RUSAGE_CHILDREN).ru_maxrss``) and the load average. The issue's bounds: set-up <= 60 s and
peak <= 2 GB on 2 cores. The machine is shared: read the time with the load printed beside it. With
``--identify METHOD`` (e.g. knn-gauss-newton, knn-kalman) ``fracid identify`` follows in another child (that
method, the example's settings otherwise), and the script prints its wall time, peak memory, the estimate and
the truth's squared Mahalanobis distance in the estimate's covariance against chi^2(3) at 99 % (11.34).

    python benchmarks/dic_camera.py [--spacing 1.0] [--subset 6.0] [--half] [--out DIR] [--identify METHOD]
"""

from __future__ import annotations

import argparse
import importlib.util
import os
import resource
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
EXAMPLE = ROOT / "examples" / "dic"


def _example_settings():
    """examples/dic/make_data.py as a module (its beam, parameters, frames, placement, rigid motion)."""
    spec = importlib.util.spec_from_file_location("dic_make_data", EXAMPLE / "make_data.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def write_case(folder: Path, spacing: float, subset: float, both_halves: bool = True, method=None) -> int:
    """Write the twin case's frames and configuration in ``folder``; return the number of points a frame."""
    from fracid.inverse.studies.dic_twin import synthetic_dic, write_dic

    ex = _example_settings()
    data = synthetic_dic(ex.BEAM, ex.PARAMS, frames=ex.FRAMES, spacing=spacing, std=1e-3, subset_size=subset,
                         holes=3.0, rigid_body=ex.RIGID, placement=ex.PLACEMENT, seed=2027,
                         both_halves=both_halves)
    write_dic(folder, data)
    shutil.copy(EXAMPLE / "load_cmod.csv", folder / "load_cmod.csv")
    text = (EXAMPLE / "identify.toml").read_text(encoding="utf-8")
    text = text.replace("subset_size = 6.0", f"subset_size = {subset:g}")
    if method is not None:
        text = text.replace("[identify]\n", f'[identify]\nmethod = "{method}"\n', 1)
    (folder / "identify.toml").write_text(text, encoding="utf-8")
    return len(data.X)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--spacing", type=float, default=1.0, help="grid step of the subset centres [mm]")
    parser.add_argument("--subset", type=float, default=6.0, help="DIC subset size [mm]")
    parser.add_argument("--half", action="store_true",
                        help="the camera sees the modelled half only (about 4 400 points); default: both halves")
    parser.add_argument("--out", type=Path, default=None, help="folder for the data (default: a temporary one)")
    parser.add_argument("--identify", default=None, metavar="METHOD", help="then fracid identify with this method")
    args = parser.parse_args()
    folder = args.out or Path(tempfile.mkdtemp(prefix="dic_camera_"))
    folder.mkdir(parents=True, exist_ok=True)
    start = time.perf_counter()
    n_points = write_case(folder, args.spacing, args.subset, both_halves=not args.half, method=args.identify)
    print(f"data: {n_points} points a frame, 6 frames, u and v, written in {time.perf_counter() - start:.1f} s "
          f"to {folder}")
    load = os.getloadavg()
    start = time.perf_counter()
    child = subprocess.run([sys.executable, "-m", "fracid", "check", str(folder / "identify.toml"), "--no-time"],
                           capture_output=True, text=True)
    wall = time.perf_counter() - start
    peak = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss / 1024**2  # kB -> GB (Linux)
    print(child.stdout[-1500:], child.stderr[-1500:], sep="\n")
    print(f"fracid check: exit {child.returncode}, {wall:.1f} s wall (bound 60 s), child peak {peak:.2f} GB "
          f"(bound 2 GB); load average before {load[0]:.2f}, after {os.getloadavg()[0]:.2f}; "
          f"OPENBLAS_NUM_THREADS={os.environ.get('OPENBLAS_NUM_THREADS', 'unset (fracid: 1)')}")
    if args.identify:
        identify(folder)


def identify(folder: Path) -> None:
    """``fracid identify`` in a child (wall time, peak memory through /usr/bin/time's counterpart: the child's
    rusage) and the truth's squared Mahalanobis distance in the estimate's covariance."""
    import json

    import numpy as np

    ex = _example_settings()
    start, load = time.perf_counter(), os.getloadavg()[0]
    before = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss
    child = subprocess.run([sys.executable, "-m", "fracid", "identify", "identify.toml"], cwd=folder,
                           capture_output=True, text=True)
    wall = time.perf_counter() - start
    peak = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss / 1024**2
    print(child.stdout[-1200:])
    result = json.loads((folder / "fracid-dic" / "result.json").read_text(encoding="utf-8"))
    x, C = np.array(result["x"]), np.array(result["C"])
    truth = np.array([getattr(ex.PARAMS, name) for name in result["names"]])
    d = x - truth
    r = C / np.sqrt(np.outer(np.diag(C), np.diag(C)))
    print(f"fracid identify: exit {child.returncode}, {result['status']}, {wall:.1f} s wall, child peak "
          f"{peak:.2f} GB{' (the check child was larger)' if before / 1024**2 >= peak else ''}; load before {load:.2f}")
    print(f"estimate {dict(zip(result['names'], x.round(8).tolist()))}, truth {truth.tolist()}, std "
          f"{np.sqrt(np.diag(C)).tolist()}; relative error {(d / truth).round(4).tolist()}; squared Mahalanobis "
          f"distance of the truth {float(d @ np.linalg.solve(C, d)):.2f} (chi^2(3) 99 %: 11.34); correlations "
          f"{r[np.triu_indices(len(x), 1)].round(3).tolist()}")


if __name__ == "__main__":
    main()
