"""The DIC codes' layouts fracid reads by name (fracid.data.dic.formats): DICe's solution files, from a fixture
written in the layout its source documents (tests/fixtures/dic/dice/README.md)."""

import re
import shutil
from pathlib import Path

import numpy as np
import pytest

from fracid.data.dic import CameraPlacement, read_dic_frames
from fracid.data.dic.formats import FORMATS
from fracid.data.errors import DataError

DICE = Path(__file__).resolve().parent / "fixtures" / "dic" / "dice"
EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "dic"
PLACEMENT = CameraPlacement(scale=0.1, rotation=np.radians(1.5), origin_camera=(120.0, 80.0))
FAILED = {0: [3, 17], 1: [3, 25, 31]}  # the fixture's failed subsets (SIGMA = -1), per frame


def _dice(**options):
    return read_dic_frames(DICE / "frames.csv", **FORMATS["dice"].columns, coordinate_unit="px",
                           placement=PLACEMENT, **options)


def test_a_dice_export_reads_in_mm_with_its_failed_subsets_dropped_and_counted():
    data = _dice(failed_sigma=True)
    assert data.n_frames == 2 and data.n_points == 40
    for frame, failed in FAILED.items():
        assert np.all(np.isnan(data.u[frame, failed])) and np.all(np.isnan(data.std[frame, failed]))
        others = np.setdiff1d(np.arange(40), failed)
        assert np.all(np.isfinite(data.u[frame, others])) and np.allclose(data.std[frame, others], 1e-3)  # 0.01 px
    assert any(re.search(r"5 of 80 point values over 2 frames dropped: failed correlation \(sigma < 0 in column "
                         r"'SIGMA'\); per frame \[2, 3\]", note) for note in data.notes)
    # the same points as the example's own export, to DICe's 5 significant digits
    example = read_dic_frames(EXAMPLE / "frames.csv", sigma="sigma", coordinate_unit="px", placement=PLACEMENT)
    rows = [np.flatnonzero(np.all(np.isclose(example.points, p, atol=1e-3), axis=1))[0] for p in data.points]
    ok = ~np.isnan(data.u[0, :, 0])
    np.testing.assert_allclose(data.u[0, ok], example.u[0, rows][ok], rtol=1e-3, atol=1e-5)


def test_without_the_rule_a_negative_sigma_is_refused_naming_row_and_column():
    with pytest.raises(DataError, match=r"DICe_solution_01.txt: row \d+, column 'SIGMA': -1 is negative"):
        _dice()


def _config(tmp_path, lines: str) -> Path:
    folder = tmp_path / "d"
    shutil.copytree(DICE, folder)
    shutil.copy(EXAMPLE / "load_cmod.csv", folder / "load_cmod.csv")
    text = (EXAMPLE / "identify.toml").read_text(encoding="utf-8")
    head, field = text.split('kind = "field"\n', 1)
    field, tail = field.split("[identify]", 1)
    kept = [line for line in field.splitlines() if line.split("=")[0].strip() in
            ("frames_file", "control_column", "scale", "rotation_deg", "origin_camera", "origin_specimen",
             "subset_size")]
    (folder / "cfg.toml").write_text(head + 'kind = "field"\n' + "\n".join(kept) + "\n" + lines + "\n\n[identify]" +
                                     tail, encoding="utf-8")
    return folder / "cfg.toml"


def test_format_dice_in_the_configuration_sets_the_columns_and_unit(tmp_path):
    from fracid.config import build_data, load_config

    cfg = load_config(_config(tmp_path, 'format = "dice"\nframes = [1, 2]\nexclude_near = 0.0'))
    field = cfg.experiments[1]
    assert field.format == "dice" and field.coordinate_unit == "px"
    assert dict(field.columns)["x"] == "COORDINATE_X" and dict(field.columns)["sigma"] == "SIGMA"
    data = build_data(cfg)
    assert any("dropped: failed correlation" in note for note in data.notes)


@pytest.mark.parametrize("lines, words", [
    ('format = "vic"', r"format = 'vic'.*\"generic\" \| \"dice\"|format = 'vic'.*generic.*dice"),
    ('format = "dice"\ncoordinate_unit = "mm"', r"coordinate_unit = 'mm'.*format = 'dice' writes px"),
])
def test_bad_format_keys_are_named(tmp_path, lines, words):
    from fracid.config import load_config
    from fracid.config.schema import ConfigError

    with pytest.raises(ConfigError, match=words):
        load_config(_config(tmp_path, lines))


def test_fracid_check_says_how_many_subsets_were_dropped_and_why(tmp_path, capsys):
    from fracid import cli

    assert cli.main(["check", str(_config(tmp_path, 'format = "dice"\nframes = [1, 2]')), "--no-time"]) == 0
    out = capsys.readouterr().out
    assert "read: 5 of 80 point values over 2 frames dropped: failed correlation (sigma < 0 in column 'SIGMA')" in out
    assert "field block 'field': 2 frames" in out
