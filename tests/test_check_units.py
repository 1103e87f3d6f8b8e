"""`fracid check` prints a curve block in the units the block gives (control_unit, force_unit), not mm and N
hard-coded (issue 41, item 4)."""

import re
import shutil
from pathlib import Path

import numpy as np
import pytest

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "dic"


def _example_in(d: Path, control_unit: str, force_unit: str, c_scale: float, f_scale: float) -> Path:
    """examples/dic copied to ``d`` with its force-CMOD curve written in ``control_unit`` and ``force_unit``
    (``c_scale``, ``f_scale``: the units' size in mm and N)."""
    for path in EXAMPLE.iterdir():
        if path.suffix in (".csv", ".toml"):
            shutil.copy(path, d / path.name)
    curve = np.loadtxt(EXAMPLE / "load_cmod.csv", delimiter=",", skiprows=1)
    np.savetxt(d / "load_cmod.csv", curve / [c_scale, f_scale], delimiter=",", header="cmod_mm,force_N",
               comments="", fmt="%.10g")
    text = (EXAMPLE / "identify.toml").read_text()
    text = text.replace('control_unit = "mm"\nforce_unit = "N"',
                        f'control_unit = "{control_unit}"\nforce_unit = "{force_unit}"')
    text = text.replace("std = 5.0                           # N", f"std = {5.0 / f_scale:g}")
    (d / "identify.toml").write_text(text)
    return d / "identify.toml"


@pytest.mark.parametrize("control_unit, force_unit, c_scale, f_scale, words", [
    ("mm", "N", 1.0, 1.0, r"control 0\.005 to 0\.2 mm, peak 1016 N, std 5 to 5 N"),
    ("um", "kN", 1e-3, 1e3, r"control 5 to 200 um \(0\.005 to 0\.2 mm\), peak 1\.016 kN, std 0\.005 to 0\.005 kN"),
    ("m", "kN", 1e3, 1e3, r"control 5e-06 to 0\.0002 m \(0\.005 to 0\.2 mm\), peak 1\.016 kN"),
])
def test_a_curve_block_is_printed_in_its_own_units(tmp_path, capsys, control_unit, force_unit, c_scale, f_scale,
                                                   words):
    from fracid.cli.dispatch import main

    config = _example_in(tmp_path, control_unit, force_unit, c_scale, f_scale)
    assert main(["check", str(config), "--no-time", "--out", str(tmp_path / "out")]) == 0
    line = next(line for line in capsys.readouterr().out.splitlines() if line.startswith("data block 'global'"))
    assert re.search(words, line), line


def test_a_block_without_given_units_is_printed_in_mm_and_its_quantitys_unit():
    from fracid.cli.check import curve_block_line

    class Local:  # a block of lengths that declares no units of its own (a derived block)
        measures_force = False

    line = curve_block_line("opening", Local(), np.array([0.01, 0.2]), np.array([0.003, -0.004]),
                            np.array([1e-3, 2e-3]))
    assert line == ("data block 'opening': 2 points, control 0.01 to 0.2 mm, peak 0.004 mm, std 0.001 to 0.002 mm "
                    "(mean 0.0015)")


# ------------------------------------------------------------------------ the frame ranking skipped, saying why


@pytest.fixture(scope="module")
def example():
    from fracid.config import build_data, load_config

    cfg = load_config(EXAMPLE / "identify.toml")
    return cfg, build_data(cfg)


def test_no_time_says_the_frames_are_not_ranked(example, tmp_path, capsys):
    from fracid.cli.check_frames import skipped_ranking_lines
    from fracid.cli.dispatch import main

    assert main(["check", str(EXAMPLE / "identify.toml"), "--no-time", "--out", str(tmp_path / "out")]) == 0
    assert "frames ranked: not computed (--no-time; it costs one run with exact sensitivities" in capsys.readouterr().out
    cfg, data = example
    curve_only = type("Data", (), {"blocks": [b for b in data.blocks if b[0] == "global"]})()
    assert skipped_ranking_lines(cfg, curve_only) == []  # no block with frames: no line


def test_a_model_without_exact_sensitivities_is_not_ranked_by_differences(example, space=None):
    from fracid.cli.check_frames import frame_ranking_lines

    cfg, data = example

    class Operator:  # no differentiated version: central differences, 2 p + 1 runs
        names = ["kappa_i", "beta", "c"]

        def __call__(self, x):
            raise AssertionError("no forward run may be made")

    lines = frame_ranking_lines(cfg, data, Operator(), space)
    assert lines == ["frames ranked: not computed (the model has no exact sensitivities: 7 runs by central "
                     "differences; fracid sensitivity gives the information)"]
