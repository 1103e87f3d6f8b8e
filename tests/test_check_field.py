"""What `fracid check` says of a field block (its frames, points, noise as given, placement) and of a curve
block (its unit), and the frames it advises (issue 41, item 4)."""

import re
from pathlib import Path

import numpy as np
import pytest

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "dic"


@pytest.fixture(scope="module")
def example():
    from fracid.config import build_data, build_operator, build_space, load_config

    cfg = load_config(EXAMPLE / "identify.toml")
    data = build_data(cfg)
    return cfg, data, build_operator(cfg, data), build_space(cfg)


def test_the_field_block_is_described_by_frames_points_noise_and_placement(example):
    from fracid.cli.check import data_lines

    cfg, data, _, _ = example
    text = "\n".join(data_lines(data, cfg))
    assert "data block 'global': 20 points" in text and "peak 1016 N, std 5 to 5 N" in text
    assert re.search(r"field block 'field': 6 frames at cmod_mm = 0\.02, 0\.034, 0\.05, 0\.08, 0\.12, 0\.2 mm; "
                     r"287 points, 287 to 287 with a value a frame; components u, v; 3444 values", text)
    assert "noise: std 0.001 to 0.001 mm (the files' sigma)" in text  # not the rigid prior's 1 mm
    assert "errors correlated over the subset size 6 mm" in text and "GB at its peak, estimated" in text
    assert "placement: camera point (120.0, 80.0) at specimen point (0.0, 0.0) mm, scale 0.1 mm" in text
    assert "rotation 1.5 deg" in text
    assert "std 1 to" not in text


def test_the_frames_are_ranked_and_the_prediction_is_the_identifications_std(example):
    from fracid.cli.check_frames import frame_ranking_lines

    cfg, data, operator, space = example
    lines = frame_ranking_lines(cfg, data, operator, space)
    assert lines[0].startswith("frames of 'field' ranked by their information at [model.parameters]")
    assert len([line for line in lines if re.match(r"  \d\. frame \d \(cmod_mm", line)]) == 6
    assert lines[-1].startswith("frames advised: frame 6 (cmod_mm 0.2 mm)")  # the last frame first
    all_frames = re.search(r"  6\. .*std kappa_i ([\d.e-]+), beta ([\d.]+), c ([\d.]+)", "\n".join(lines))
    # the identification of the example (docs/dic/README.md): stds 1.29e-6, 27.9, 0.82 at its estimate
    np.testing.assert_allclose([float(v) for v in all_frames.groups()], [1.29e-6, 27.9, 0.82], rtol=0.1)
