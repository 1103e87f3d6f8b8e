"""The field block (and its correlated-noise covariance, the costly part) is built once per process: not again
by the data, the operator, nor a second load of the same configuration (issue 41); a changed key, specimen or
frame table builds it afresh."""

import os
import shutil
from pathlib import Path

import pytest

import fracid.inverse.experiments.built_once as built_once
import fracid.inverse.experiments.field as field_kind
import fracid.inverse.experiments.field_build as field_build

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "dic"


@pytest.fixture
def builds(monkeypatch):
    """The number of field-block builds, counted from a fresh cache."""
    monkeypatch.setattr(built_once, "_BUILT", {})
    count = []
    build = field_build._build_placed_field_block
    monkeypatch.setattr(field_build, "_build_placed_field_block", lambda *a: count.append(1) or build(*a))
    return count


@pytest.fixture(scope="module")
def example_copy(tmp_path_factory):
    folder = tmp_path_factory.mktemp("dic")
    for item in EXAMPLE.iterdir():
        if item.is_file():
            shutil.copy(item, folder / item.name)
    config = folder / "identify.toml"  # two frames, one component: a cheap block, the same path
    text = config.read_text(encoding="utf-8").replace("frames = [1, 2, 3, 4, 5, 6]", "frames = [1, 2]")
    config.write_text(text.replace('components = ["u", "v"]', 'components = ["u"]'), encoding="utf-8")
    return config


def test_check_then_identify_build_the_field_block_once(builds, example_copy):
    from fracid.config import build_data, build_operator, load_config

    for _ in range(2):  # `check`, then `identify` in the same process
        config = load_config(example_copy)
        build_operator(config, build_data(config))
    assert len(builds) == 1


def test_a_changed_frame_table_or_key_builds_it_again(builds, example_copy):
    from dataclasses import replace

    from fracid.config import load_config

    config = load_config(example_copy)
    exp = config.experiments[1]
    assert len(builds) == 1
    table = example_copy.parent / "frames.csv"
    info = os.stat(table)
    os.utime(table, ns=(info.st_atime_ns, info.st_mtime_ns + 10**9))  # the table rewritten
    field_kind.placed_field_block(exp, key_of_last()[1])
    assert len(builds) == 2
    key = key_of_last()
    field_kind.placed_field_block(replace(exp, exclude_near=5.0), key[1])  # another key: another block
    assert len(builds) == 3
    field_kind.placed_field_block(replace(exp, n_points=7), key[1])  # n_points is derived: the same block
    assert len(builds) == 3 and len(built_once._BUILT) <= built_once.KEPT


def key_of_last() -> tuple:
    """(config, specimen, file stat) of the block built last."""
    return next(reversed(built_once._BUILT))


def test_a_rewritten_frame_file_builds_it_again(builds, example_copy):
    from fracid.config import load_config

    config = load_config(example_copy)
    exp = config.experiments[1]
    frame = sorted(example_copy.parent.glob("frame_*.csv"))[0]
    info = os.stat(frame)
    os.utime(frame, ns=(info.st_atime_ns, info.st_mtime_ns + 10**9))  # one frame's file rewritten, not the table
    field_kind.placed_field_block(exp, key_of_last()[1])
    assert len(builds) == 2
