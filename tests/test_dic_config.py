"""DIC field data as a data block (fracid.data.dic.field_block) and its FieldObservation (issue 27, items 1-3)."""

from pathlib import Path

import numpy as np
import pytest

from fracid.data import DataError, stack
from fracid.data.covariance_matrix import Diagonal
from fracid.data.dic import CameraPlacement, DicData, field_block, read_dic_frames
from fracid.data.dic_noise import NUGGET, dic_kernel
from fracid.specimens.beam import NotchedBeam

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "dic"
PLACEMENT = CameraPlacement(scale=0.1, rotation=np.radians(1.5), origin_camera=(120.0, 80.0))


@pytest.fixture(scope="module")
def example():
    return read_dic_frames(EXAMPLE / "frames.csv", sigma="sigma", coordinate_unit="px", placement=PLACEMENT)


def _small(n_frames=3, n_points=12, seed=1):
    """A small DicData: points on a line 1 mm apart, random displacements, sigma growing with the point."""
    rng = np.random.default_rng(seed)
    points = np.column_stack([np.arange(n_points, dtype=float), np.full(n_points, 30.0)])
    u = rng.normal(size=(n_frames, n_points, 2))
    sigma = np.broadcast_to((1e-3 * (1 + np.arange(n_points)))[None, :, None], u.shape)
    load = {"cmod_mm": 0.01 * np.arange(1, n_frames + 1), "force_N": np.linspace(1, 2, n_frames)}
    return DicData(points, tuple(range(1, n_frames + 1)), u, sigma, load)


def test_the_example_field_block_holds_the_values_of_the_files(example):
    block = field_block(example)
    n_points = example.n_points - 10  # the 10 holes of every frame have no value: dropped
    assert block.data.n_y == 6 * 2 * n_points and block.keep.all() and len(block.points) == n_points
    values, missing = example.values()
    np.testing.assert_allclose(block.data.y, values[~missing])
    np.testing.assert_allclose(block.frames, [0.02, 0.034, 0.05, 0.08, 0.12, 0.2])
    np.testing.assert_allclose(block.data.control, np.repeat(block.frames, 2 * n_points))
    assert isinstance(block.data.covariance, Diagonal)
    np.testing.assert_allclose(block.data.std, 1e-3)  # 0.01 px at 0.1 mm/px
    assert block.data.blocks == (("field", 0, block.data.n_y),)
    assert any("missing dropped" in note for note in block.data.notes)


def test_holes_low_quality_and_sigma_define_the_kept_entries():
    dic = _small()
    u = dic.u.copy()
    u[0, 2, :] = np.nan  # point 2 missing in frame 1
    u[1, 5, 1] = np.nan  # v of point 5 missing in frame 2
    u[:, 7, :] = np.nan  # point 7 never measured: dropped from the points
    block = field_block(dic._replace(u=u), frames=[1, 2])
    assert len(block.points) == 11 and 7.0 not in block.points[:, 0]
    keep = block.keep.reshape(2, 2, 11)
    assert not keep[0, :, 2].any() and not keep[1, 1, 5] and keep.sum() == 44 - 3
    assert block.data.n_y == 41 and block.frame_numbers == (1, 2)
    expected = np.delete(u[:2], 7, axis=1).transpose(0, 2, 1).reshape(-1)
    np.testing.assert_array_equal(block.data.y, expected[block.keep])
    sigma = np.delete(dic.std[:2], 7, axis=1).transpose(0, 2, 1).reshape(-1)
    np.testing.assert_allclose(block.data.std, sigma[block.keep])
    only_v = field_block(dic, frames=[3], components="v", std=2e-3)
    np.testing.assert_array_equal(only_v.data.y, dic.u[2, :, 1])
    np.testing.assert_allclose(only_v.data.std, 2e-3)


def test_the_correlated_covariance_is_the_kernel_scaled_by_sigma():
    dic = _small(n_frames=2, n_points=10)
    u = dic.u.copy()
    u[1, 3, 0] = np.nan
    block = field_block(dic._replace(u=u), subset_size=3.0)
    C = np.asarray(block.data.covariance.dense())
    sigma = dic.std[0, :, 0]
    K = (dic_kernel(dic.points, dic.points, 1.0, 3.0) + NUGGET * np.eye(10)) * np.outer(sigma, sigma)
    zero = np.zeros_like(K)
    full = np.block([[K if i == j else zero for j in range(4)] for i in range(4)])  # frames x components
    expected = full[np.ix_(block.keep, block.keep)]
    np.testing.assert_allclose(C, expected, rtol=1e-10, atol=1e-14)  # the sparse kernel exactly
    assert np.all(C[:10, 10:] == 0)  # components (and frames) independent
    assert np.all(np.linalg.eigvalsh(C) > 0)


def test_a_field_stacks_beside_a_curve(example):
    from fracid.data import with_std
    from fracid.data.curves import Curve

    curve = with_std(Curve(np.linspace(0, 0.2, 21), 1000 * np.sin(np.linspace(0, 3, 21)) + 10), 10.0, 8, None,
                     name="global")
    data = stack(curve, field_block(example, frames=[1, 2], subset_size=6.0).data)
    assert [b[0] for b in data.blocks] == ["global", "field"]
    assert data.n_y == 8 + 2 * 2 * 291
    np.testing.assert_allclose(data.std[8:], 1e-3, rtol=1e-10)


@pytest.mark.parametrize("kwargs, message", [
    ({"frames": [1, 9]}, r"frames \[9\] are not in the data"),
    ({"control": "cmod"}, r"control = 'cmod' is not a load column.*'cmod_mm', 'force_N'"),
    ({"components": "w"}, r"components = 'w': give \"u\" \(x\), \"v\" \(y\) or both"),
    ({"frames": [2, 1]}, r"must increase strictly over the frames used, but frame 1"),
    ({"std": 0.0}, r"std = 0: every standard deviation must be > 0"),
    ({"std": 1e-320}, r"std = 1e-320: every standard deviation must be > 0 with a square that is a normal number"),
    ({"std": 1e200}, r"std = 1e\+200: every standard deviation must be > 0 .* between 1.49e-154 and 1.34e\+154"),
    ({"std": "1"}, r"std must be a number"),
    ({"subset_size": -1.0}, r"subset_size = -1.0 \[mm\]"),
    ({"region": lambda p: p[:, 0] > 100}, r"no value left"),
])
def test_bad_arguments_are_named(kwargs, message):
    with pytest.raises(DataError, match=message):
        field_block(_small(), **kwargs)


def test_no_sigma_and_no_std_is_refused():
    dic = _small()
    with pytest.raises(DataError, match="no per-point sigma: give std"):
        field_block(dic._replace(std=None))


def test_the_observation_matches_the_block(example):
    beam = NotchedBeam(h_fine=2.0, h_coarse=6.0)
    dic = example.region(lambda p: np.abs(p[:, 0]) > 3.0)  # away from the crack path x = 0
    u = dic.u.copy()
    u[2, 4, 1] = np.nan
    block = field_block(dic._replace(u=u), frames=[2, 3, 5], name="dic")
    from fracid.inverse.core.field_observations import field_observation

    field = field_observation(block, beam)
    assert field.size == block.data.n_y and field.name == "dic"
    np.testing.assert_array_equal(field.controls, block.data.control)
    c = field.coordinates()
    first = slice(0, len(block.points))
    np.testing.assert_array_equal(np.column_stack([c["x"][first], c["y"][first]]), block.points)
    assert np.count_nonzero(~field.keep) == 1


# ------------------------------------------------------------------------------------------------
# [[experiments]] kind = "field" in a configuration: examples/dic/identify.toml


CONFIG = EXAMPLE / "identify.toml"


@pytest.fixture(scope="module")
def config():
    from fracid.config import load_config

    return load_config(CONFIG)


def test_the_example_config_builds_data_and_operator(config):
    from fracid.config import build_data, build_operator
    from fracid.data.covariance_matrix import Block
    from fracid.inverse.core.forward_operator import FieldObservation

    field_cfg = config.experiments[1]
    assert field_cfg.kind == "field" and field_cfg.frames == (1, 2, 3, 4, 5, 6) and field_cfg.placement.scale == 0.1
    data = build_data(config)
    operator = build_operator(config, data)
    assert [b[0] for b in data.blocks] == ["global", "field"]
    assert config.n_y == data.n_y == operator.n_outputs == 20 + field_cfg.n_points
    field = operator.observations[1]
    assert isinstance(field, FieldObservation) and field.size == data.n_y - 20
    np.testing.assert_array_equal(field.controls, data.control[data.block("field")])
    assert isinstance(data.covariance, Block)  # the field's correlated errors (low rank + diagonal) kept
    # the points kept are at least exclude_near = 4 mm from the crack line x = 0 (the notch and the ligament)
    assert np.abs(field.points[:, 0]).min() >= 4.0
    dic = read_dic_frames(EXAMPLE / "frames.csv", sigma="sigma", coordinate_unit="px", placement=PLACEMENT)
    assert len(field.points) == np.count_nonzero(np.abs(dic.points[:, 0]) >= 4.0) < dic.n_points


def test_fracid_check_lists_the_field_block(capsys):
    from fracid import cli

    assert cli.main(["check", str(CONFIG), "--no-time"]) == 0
    out = capsys.readouterr().out
    assert "data block 'global': 20 points" in out and "field block 'field': 6 frames" in out


def _field_config(tmp_path, **changes) -> Path:
    """identify.toml in tmp_path with its field block's keys changed (None: removed), its files absolute."""
    text = CONFIG.read_text(encoding="utf-8")
    head, field = text.split('kind = "field"\n', 1)
    field, tail = field.split("[identify]", 1)
    lines = [line for line in field.splitlines() if line.split("=")[0].strip() not in changes]
    lines += [f"{key} = {value}" for key, value in changes.items() if value is not None]
    text = head.replace('"load_cmod.csv"', f'"{EXAMPLE / "load_cmod.csv"}"') + 'kind = "field"\n' \
        + "\n".join(lines).replace('"frames.csv"', f'"{EXAMPLE / "frames.csv"}"') + "\n[identify]" + tail
    path = tmp_path / "cfg.toml"
    path.write_text(text, encoding="utf-8")
    return path


@pytest.mark.parametrize("changes, key, message", [
    ({"frames_file": None}, "frames_file is missing", "the frame table"),
    ({"frames_file": '"nope.csv"'}, "frames_file", "nope.csv"),
    ({"x": '"Xpos"'}, "experiments[1].x = 'Xpos'", "has no column 'Xpos'"),
    ({"control_column": '"cmod"'}, "experiments[1].control_column = 'cmod'", "did you mean 'cmod_mm'"),
    ({"scale": "-0.1"}, "experiments[1].scale = -0.1", "must be a number > 0"),
    ({"scale": None}, "experiments[1].scale is missing", "a number > 0"),
    ({"marked_camera": "[[0, 0], [1, 1], [2, 2]]", "marked_specimen": "[[0, 0], [1, 1], [2, 2]]"},
     "experiments[1].scale", "either by scale"),
    ({"marked_camera": "[[0, 0], [1, 1], [2, 2]]", "marked_specimen": "[[0, 0], [1, 1], [2, 2]]", "scale": None,
      "rotation_deg": None, "origin_camera": None, "origin_specimen": None},
     "experiments[1].marked_camera", "collinear"),
    ({"sigma": None}, "experiments[1].sigma", "no per-point sigma: give std"),
    ({"frames": "[1, 9]"}, "experiments[1].frames = [1, 9]", r"frames \[9\] are not in the data"),
    ({"frames": "[2, 1]"}, "experiments[1].frames = [2, 1]", "must increase strictly"),
    ({"frames": '["1"]'}, "experiments[1].frames", "list of distinct frame numbers"),
    ({"components": '"w"'}, "experiments[1].components = 'w'", 'must be "u" \\(x\\), "v" \\(y\\)'),
    ({"std": "0"}, "experiments[1].std = 0", "must be a number > 0"),
    ({"subset_size": '"6"'}, "experiments[1].subset_size", "number"),
    ({"exclude_near": "500.0"}, "experiments[1].exclude_near = 500", "no value left"),
    ({"coordinate_unit": '"cm"'}, "experiments[1].coordinate_unit = 'cm'", "'mm', 'px'"),
    ({"min_quality": "0.5"}, "experiments[1].min_quality", "needs quality"),
    ({"n_points": "3"}, "experiments[1]", "n_points"),
    ({"rigid_motion": '"yes"'}, "experiments[1].rigid_motion = 'yes'", "must be true"),
    ({"rigid_motion": "false", "rigid_std": "1.0"}, "experiments[1].rigid_std = 1", "needs rigid_motion = true"),
    ({"rigid_std": "0"}, "experiments[1].rigid_std = 0", "must be a number > 0"),
])
def test_bad_field_keys_are_named(tmp_path, changes, key, message):
    from fracid.config import ConfigError, load_config

    with pytest.raises(ConfigError) as err:
        load_config(_field_config(tmp_path, **changes))
    text = str(err.value)
    assert key in text and re_search(message, text), text


def re_search(pattern, text):
    import re

    return re.search(pattern, text) is not None


def test_a_fitted_placement_is_the_given_one(tmp_path):
    from fracid.config import load_config

    camera = np.array([[0.0, 0.0], [400.0, 0.0], [0.0, 300.0], [350.0, 280.0]])
    specimen = PLACEMENT.to_specimen(camera)
    marked = {"marked_camera": str(camera.tolist()), "marked_specimen": str(specimen.tolist()),
              "scale": None, "rotation_deg": None, "origin_camera": None, "origin_specimen": None}
    fitted = load_config(_field_config(tmp_path, **marked)).experiments[1].placement
    np.testing.assert_allclose(fitted.to_specimen(camera), specimen, atol=1e-9)
    assert fitted.scale == pytest.approx(0.1) and fitted.fit_rms < 1e-9


@pytest.mark.parametrize("changes, key", [({"frames_file": None}, "frames_file"), ({"x": '"Xpos"'}, "x"),
                                          ({"scale": "0"}, "scale"), ({"frames": "[7]"}, "frames"),
                                          ({"components": '"w"'}, "components")])
def test_fracid_check_exits_2_naming_the_key(tmp_path, capsys, changes, key):
    from fracid import cli

    assert cli.main(["check", str(_field_config(tmp_path, **changes)), "--no-time"]) == 2
    err = capsys.readouterr().err
    assert f"experiments[1].{key}" in err and "Traceback" not in err


def _remove_rigid_motion(residual, field):
    """The residual minus its least-squares rigid motion (fracid.data.dic.rigid.fit_rigid_motion) per frame, and
    those motions."""
    from fracid.data.dic.rigid import fit_rigid_motion

    full = np.full(field.keep.size if field.keep is not None else residual.size, np.nan)
    full[slice(None) if field.keep is None else field.keep] = residual
    frames = full.reshape(len(field.frames), -1)
    fits = [fit_rigid_motion(field.points, field.components, frame) for frame in frames]
    removed = (frames - np.array([fitted for _, fitted in fits])).reshape(-1)
    return removed[np.isfinite(removed)], np.array([motion for motion, _ in fits])


def test_the_configured_field_is_the_twin_at_its_true_parameters(config):
    """Twin check of the whole chain (reader, placement, frames, kept entries, covariance, observation): at
    make_data.py's parameters the field differs from the data by make_data.py's rigid motion and its noise."""
    from fracid.config import build_data, build_operator

    data = build_data(config)
    operator = build_operator(config, data)
    record = operator(np.array([getattr(operator.base, n) for n in operator.names]))
    assert record.ok
    field, block = operator.observations[1], data.block("field")
    residual, motions = _remove_rigid_motion((data.y - record.y)[block], field)
    rigid = np.outer(np.linspace(0.2, 1.0, 6), [0.004, -0.012, 5e-5])  # make_data.RIGID
    assert np.all(np.abs(motions - rigid) <= [5e-4, 5e-4, 1e-5])  # mm, mm, rad
    white = data.covariance.take(np.arange(block.start, block.stop)).whiten(residual)
    assert 0.9 < white @ white / residual.size < 1.1  # the noise, as its covariance says (1 um, correlated)
    white = data.covariance.take(np.arange(0, 20)).whiten((data.y - record.y)[:20])
    assert white @ white / 20 < 2.0
    # the covariance marginalises the rigid motion (rigid_motion = true, the default): the raw residual is noise
    field_cov = data.covariance.take(np.arange(block.start, block.stop))
    assert 0.9 < field_cov.quadratic((data.y - record.y)[block]) / residual.size < 1.1


def test_a_field_in_vtu_files_reads_as_the_csv_one(tmp_path):
    """frames_file may list VTU files (displacement, sigma: point-data arrays): the same data block as the CSV."""
    meshio = pytest.importorskip("meshio")
    from fracid.config import build_data, load_config

    table = (EXAMPLE / "frames.csv").read_text().splitlines()
    rows = [table[0]]
    for line in table[1:]:
        cells = line.split(",")
        cloud = np.genfromtxt(EXAMPLE / cells[1], delimiter=",", names=True)
        points = np.column_stack([cloud["X"], cloud["Y"], np.zeros(cloud.size)])
        meshio.write(str(tmp_path / cells[1].replace(".csv", ".vtu")),
                     meshio.Mesh(points, [("vertex", np.arange(cloud.size)[:, None])],
                                 point_data={"disp": np.column_stack([cloud["U"], cloud["V"]]), "sigma": cloud["sigma"]}))
        rows.append(",".join([cells[0], cells[1].replace(".csv", ".vtu"), *cells[2:]]))
    (tmp_path / "frames.csv").write_text("\n".join(rows) + "\n")
    path = _field_config(tmp_path, displacement='"disp"')
    path.write_text(path.read_text().replace(str(EXAMPLE / "frames.csv"), str(tmp_path / "frames.csv")))
    vtu, csv = build_data(load_config(path)), build_data(load_config(CONFIG))
    np.testing.assert_allclose(vtu.y, csv.y, rtol=1e-12)
    np.testing.assert_allclose(vtu.std, csv.std, rtol=1e-12)
    from fracid.config import ConfigError

    path.write_text(path.read_text().replace('displacement = "disp"', 'displacement = "U"'))
    with pytest.raises(ConfigError, match=r"experiments\[1\].displacement = 'U'.*arrays found: 'disp'"):
        load_config(path)
