"""Hostile-input cases of issue 38 (dic); run by tests/test_hostile_inputs.py.

Each case copies examples/dic (the smallest DIC configuration: the demo's notched beam, 6 frames of about 300
points) into its directory and changes one thing: the placement (points off the mesh), a file (a truncated VTU
frame, a frame without a value, a per-point sigma too small to square), a std too small to square. ``fracid
check`` where the configuration is refused or warned; ``fracid identify`` too where it is refused (it stops while
the configuration loads: no forward run).
"""

from __future__ import annotations

import re
import shutil
from pathlib import Path

from hostile import case, check

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "dic"
CHECK = ("check", "cfg.toml", "--no-time")
IDENTIFY = ("identify", "cfg.toml", "--out", "out", "--workers", "1", "--quiet")


def _edited(config=(), frame=None):
    """The files of examples/dic with the config's lines edited (``config``: (pattern, replacement) regex pairs
    applied in turn, each must match) and ``frame(directory)`` changing the frames' files."""
    def files(d):
        for path in EXAMPLE.iterdir():
            if path.suffix in (".csv", ".toml"):
                shutil.copy(path, d / path.name)
        text = (d / "identify.toml").read_text(encoding="utf-8")
        for pattern, replacement in config:
            text, n = re.subn(pattern, replacement, text, flags=re.M)
            assert n == 1, pattern
        (d / "cfg.toml").write_text(text, encoding="utf-8")
        if frame is not None:
            frame(d)
    return files


def dic_case(status, words, config=(), frame=None, args=CHECK, values=None):
    """A case on examples/dic edited; ``values``: the field block's size that ``fracid check`` then prints
    (3444 values unchanged: fewer when points or frames were dropped)."""
    verify = None if values is None else _with_values(status, words, values)
    return case(status, words, config="", csv=None, files=_edited(config, frame), args=args, verify=verify)


def _with_values(status, words, values):
    def verify(proc, d):
        check(proc, d, status, words)
        assert re.search(rf"field block 'field': .*; {values} values", proc.stdout), proc.stdout
    return verify


def _cells(d, name: str, edit) -> None:
    """Frame file ``name`` with every data row's cells changed by ``edit(header, cells)``."""
    lines = (d / name).read_text(encoding="utf-8").splitlines()
    header = lines[0].split(",")
    rows = [",".join(edit(header, line.split(","))) for line in lines[1:]]
    (d / name).write_text("\n".join([lines[0], *rows]) + "\n", encoding="utf-8")


def _no_value(header, cells):
    cells[header.index("U")] = cells[header.index("V")] = "NaN"
    return cells


def _tiny_sigma(header, cells):
    cells[header.index("sigma")] = "1e-200"
    return cells


def _frame_4_empty(d):
    _cells(d, "frame_0004.csv", _no_value)


def _frame_2_tiny_sigma(d):
    _cells(d, "frame_0002.csv", _tiny_sigma)


def _truncated_vtu(d):
    """Frame 3 as a VTU file cut in the middle (an interrupted copy), listed in the frame table."""
    import meshio
    import numpy as np

    rows = np.genfromtxt(d / "frame_0003.csv", delimiter=",", names=True)
    points = np.column_stack([rows["X"], rows["Y"], np.zeros(len(rows))])
    u = np.column_stack([rows["U"], rows["V"], np.zeros(len(rows))])
    meshio.write(d / "frame_0003.vtu", meshio.Mesh(points, [("vertex", np.arange(len(points))[:, None])],
                                                    point_data={"displacement": u, "sigma": rows["sigma"]}))
    data = (d / "frame_0003.vtu").read_bytes()
    (d / "frame_0003.vtu").write_bytes(data[:len(data) // 2])
    table = (d / "frames.csv").read_text(encoding="utf-8")
    (d / "frames.csv").write_text(table.replace("frame_0003.csv", "frame_0003.vtu"), encoding="utf-8")


SCALE_1000 = [(r"^scale = 0\.1 ", "scale = 100.0 ")]  # mm per px: 1000 times too large
ORIGIN = r"^origin_specimen = \[0\.0, 0\.0\]"
SHIFTED = [(ORIGIN, "origin_specimen = [500.0, 0.0]")]  # the origin 500 mm off
MIRRORED = [(r"^rotation_deg = 1\.5", "rotation_deg = 181.5")]  # the image upside down
CURVE_STD = [(r"^std = 5\.0 ", "std = 1e-320 ")]
FIELD_STD = [(r"^subset_size = 6\.0 ", "std = 1e-320\nsubset_size = 6.0 ")]
ALL_OUTSIDE = ["experiments[1].frames_file", "301 of 301 points of the field fall outside the specimen's mesh",
               "the mesh x 0 to 87.5, y 0 to 50 mm", "every point is outside"]

CASES: dict = {
    # ---- DIC points outside the specimen's mesh: found while the configuration is checked
    "dic-few-points-outside-dropped": dic_case(0, [
        "warning: experiments[1].frames_file: 19 of 301 points", "(6.3% of the points; more than 10% is refused",
        "are dropped", "up to 2.92 mm beyond the mesh's box"],
        [(ORIGIN, "origin_specimen = [0.0, 3.0]")], values=3228),
    "dic-many-points-outside": dic_case(2, [
        "experiments[1].frames_file", "244 of 301 points", "more than 10% outside is a placement error"],
        [(ORIGIN, "origin_specimen = [0.0, 40.0]")]),
    "dic-all-outside-scale-1000": dic_case(2, [*ALL_OUTSIDE, "977 times the specimen's size", "check the units",
                                               "scale = 100 mm per camera unit"], SCALE_1000),
    "dic-all-outside-scale-1000-identify": dic_case(2, [*ALL_OUTSIDE, "check the units"], SCALE_1000,
                                                    args=IDENTIFY),
    "dic-all-outside-shifted-origin": dic_case(2, [*ALL_OUTSIDE, "offset by (499.3, 0.01534) mm",
                                                   "check the origin"], SHIFTED),
    "dic-all-outside-shifted-origin-identify": dic_case(2, [*ALL_OUTSIDE, "check the origin"], SHIFTED,
                                                        args=IDENTIFY),
    "dic-all-outside-mirrored": dic_case(2, [*ALL_OUTSIDE, "mirrored about the line y = 0 mm fall inside",
                                             "negate the camera's Y column"], MIRRORED),
    # ---- files meshio cannot read: a bad input, never meshio's sys.exit
    "dic-truncated-vtu-frame": dic_case(2, ["experiments[1].frames_file", "frame_0003.vtu",
                                            "not a readable VTU/VTK file", "truncated"], frame=_truncated_vtu),
    "dic-truncated-vtu-frame-identify": dic_case(2, ["frame_0003.vtu", "not a readable VTU/VTK file"],
                                                 frame=_truncated_vtu, args=IDENTIFY),
    # ---- a std whose square is not a positive normal float, named by its key
    "dic-curve-std-1e-320": dic_case(2, ["experiments[0].std = 1e-320", "a square that is a normal number",
                                         "between 1.49e-154 and 1.34e+154"], CURVE_STD),
    "dic-curve-std-1e-320-identify": dic_case(2, ["experiments[0].std = 1e-320"], CURVE_STD, args=IDENTIFY),
    "dic-field-std-1e-320": dic_case(2, ["experiments[1].std = 1e-320", "a square that is a normal number"],
                                     FIELD_STD),
    "dic-field-std-1e-320-identify": dic_case(2, ["experiments[1].std = 1e-320"], FIELD_STD, args=IDENTIFY),
    "dic-field-sigma-1e-200": dic_case(2, ["experiments[1].sigma = 'sigma'", "the per-point sigma of the files",
                                           "= 1e-201", "a square that is a normal number"],
                                       frame=_frame_2_tiny_sigma),
    # ---- a frame without any valid value: dropped at load, named
    "dic-frame-without-values-dropped": dic_case(0, [
        "warning: experiments[1].frames_file: field 'field': 1 frame(s) without any valid value",
        "frame 4 (cmod_mm = 0.08 mm", "frame_0004.csv"], frame=_frame_4_empty, values=3444 - 574),
}
