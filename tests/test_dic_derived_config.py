"""[[experiments]] kind = "opening" | "fpz-width": local data derived from a field block of the configuration
(fracid.inverse.experiments.derived), on examples/dic (a twin of the notched beam at [model.parameters])."""

import re
from pathlib import Path

import numpy as np
import pytest

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "dic"
#: the twin's rigid motion per frame, (t_x [mm], t_y [mm], theta [rad]) (examples/dic/make_data.py RIGID)
RIGID = np.outer(np.linspace(0.2, 1.0, 6), [0.004, -0.012, 5e-5])
HEIGHTS = [30, 35, 40, 45]
OPENING = {"kind": '"opening"', "field": '"field"', "heights": str(HEIGHTS), "gauge": "6.0", "radius": "5.0"}
WIDTH = {"kind": '"fpz-width"', "field": '"field"', "heights": "[30, 40]", "offsets": "[4, 7, 10, 13, 16]",
         "radius": "5.0", "threshold": "3e-5"}
#: the field as the derived blocks' source only; its rigid-motion prior off: the twin's motion is known (RIGID)
SOURCE = {"role": '"source"', "rigid_motion": "false"}
#: a field quick to read (one frame, u only, no correlated errors): for the checks of the keys. Its rigid-motion
#: prior off: with it, the width's J C J^T (J free of rigid motion, C holding a 1 mm^2 prior) is refused as not
#: symmetric, to rounding (fracid.data.dic.derived.derived_block does not symmetrise it)
LIGHT = {**SOURCE, "frames": "[6]", "components": '"u"', "subset_size": None}
#: chi^2 quantiles at 99.9 %: 24 and 12 degrees of freedom
CHI2_24, CHI2_12 = 51.2, 32.9


def _block(keys: dict) -> str:
    return "[[experiments]]\n" + "".join(f"{key} = {value}\n" for key, value in keys.items()) + "\n"


def _config(tmp_path, field=SOURCE, derived=(OPENING,), before=False, name="cfg.toml") -> Path:
    """examples/dic/identify.toml in tmp_path, its files absolute, its field block's keys changed (``field``;
    None: removed) and the ``derived`` blocks (dicts of TOML values) after the field block (before it if
    ``before``)."""
    text = re.sub(r'"(load_cmod|frames)\.csv"', lambda m: f'"{EXAMPLE / m.group(0)[1:-1]}"',
                  (EXAMPLE / "identify.toml").read_text(encoding="utf-8"))
    preamble, curve, rest = text.split("[[experiments]]")
    rest, tail = rest.split("[identify]", 1)
    lines = [line for line in rest.splitlines() if line.split("=")[0].strip() not in field]
    lines += [f"{key} = {value}" for key, value in field.items() if value is not None]
    blocks = "".join(map(_block, derived))
    field_block = "[[experiments]]" + "\n".join(lines) + "\n\n"
    parts = (blocks, field_block) if before else (field_block, blocks)
    path = tmp_path / name
    path.write_text(preamble + "[[experiments]]" + curve + "".join(parts) + "[identify]" + tail, encoding="utf-8")
    return path


@pytest.fixture(scope="module")
def twin(tmp_path_factory):
    """(config, data, operator, model values at [model.parameters]) of the opening and width blocks."""
    from fracid.config import build_data, build_operator, build_parameters, load_config

    cfg = load_config(_config(tmp_path_factory.mktemp("twin"), derived=(OPENING, WIDTH)))
    data = build_data(cfg)
    operator = build_operator(cfg, data)
    params = build_parameters(cfg)
    record = operator(np.array([getattr(params, name) for name in operator.names]))
    assert record.ok
    return cfg, data, operator, record.y


def _chi2(data, name: str, residual) -> float:
    C = data.covariance.take(np.arange(data.n_y)[data.block(name)]).dense()
    return float(residual @ np.linalg.solve(C, residual))


def test_the_derived_blocks_are_data_and_observations(twin):
    from fracid.config import build_specimen
    from fracid.inverse.experiments.field import field_block
    from fracid.data.dic.derived import opening_profile
    from fracid.inverse.core.derived_observations import DerivedFieldObservation

    cfg, data, operator, _ = twin
    field, opening, width = cfg.experiments[1:]
    assert (opening.kind, opening.n_points, width.kind, width.n_points) == ("opening", 6 * 4, "fpz-width", 6 * 2)
    assert cfg.warnings == () and opening.file == field.file  # the field has role "source": no warning
    assert [b[0] for b in data.blocks] == ["global", "opening", "fpz_width"]  # not the field
    assert cfg.n_y == data.n_y == operator.n_outputs == 20 + 24 + 12
    for observation, name in zip(operator.observations[1:], ("opening", "fpz_width")):
        assert isinstance(observation, DerivedFieldObservation) and observation.name == name
        np.testing.assert_array_equal(observation.controls, data.control[data.block(name)])
    direct = opening_profile(field_block(field, build_specimen(cfg)), build_specimen(cfg), HEIGHTS, 6.0, radius=5.0)
    np.testing.assert_array_equal(data.y[data.block("opening")], direct.data.y)
    np.testing.assert_allclose(data.std[data.block("opening")], direct.data.std)


def test_the_opening_is_the_twins_once_its_rigid_motion_is_removed(twin):
    """On the half x >= 0, w = 2 u_x(+gauge) carries 2 (t_x - theta y) of the camera's rigid motion, which the
    model (fixed supports) has not: removed, data - model is noise (chi^2 of 24 values); kept, it is not."""
    _, data, _, model = twin
    block = data.block("opening")
    residual = data.y[block] - model[block]
    rigid = 2.0 * (RIGID[:, [0]] - RIGID[:, [2]] * np.array(HEIGHTS, float))  # (frames, heights) [mm]
    assert _chi2(data, "opening", residual - rigid.ravel()) < CHI2_24
    assert _chi2(data, "opening", residual) > CHI2_24  # the rigid motion is seen: a 2 um noise, up to 7 um motion
    assert np.abs(model[block]).max() > 0.07  # the opening of the last frame, 35 times the noise


def test_with_the_fields_rigid_prior_the_opening_needs_no_correction(twin, tmp_path):
    """The default rigid_motion = true: the field's covariance carries the rigid motion into the opening's,
    whose mean and tilt along the heights become uninformative at every frame (2 of the 4 values)."""
    from fracid.config import build_data, load_config

    _, data, _, model = twin
    prior = build_data(load_config(_config(tmp_path, field={"role": '"source"'})))
    block = prior.block("opening")
    np.testing.assert_array_equal(prior.y[block], data.y[data.block("opening")])  # the same values
    assert prior.std[block].min() > 1.0  # mm: the vague prior of the rigid motion (rigid_std = 1 mm)
    assert _chi2(prior, "opening", prior.y[block] - model[data.block("opening")]) < CHI2_12


def test_the_derived_block_and_its_calibration_field_are_warned_about(tmp_path):
    from fracid.config import load_config

    cfg = load_config(_config(tmp_path, field={**LIGHT, "role": None}))
    assert any("experiments[2] (opening 'opening') is derived from experiments[1]" in w and "counted twice" in w
               for w in cfg.warnings), cfg.warnings


def test_a_derived_block_may_come_before_its_field(tmp_path):
    from fracid.config import load_config

    cfg = load_config(_config(tmp_path, field=LIGHT, derived=(OPENING, {**WIDTH, "name": '"width"'}), before=True))
    assert [e.kind for e in cfg.experiments] == ["single", "opening", "fpz-width", "field"]
    assert [e.n_points for e in cfg.experiments[1:3]] == [4, 2] and cfg.experiments[2].name == "width"
    assert cfg.experiments[1].source is cfg.experiments[3] and cfg.warnings == ()


@pytest.mark.parametrize("changes, key, message", [
    ({"field": '"dic"'}, "experiments[2].field = 'dic'", "its field blocks: 'field'"),
    ({"field": None}, "experiments[2].field is missing", 'kind = "field" block'),
    ({"heights": None}, "experiments[2].heights is missing", "increasing positions"),
    ({"heights": "[45, 30]"}, "experiments[2].heights = [45, 30]", "increasing positions along the ligament"),
    ({"heights": '["30"]'}, "experiments[2].heights", "must be a list"),
    ({"heights": "[10, 30]"}, "experiments[2].heights = [10, 30]", r"\[10.0\] mm lie outside the ligament"),
    ({"gauge": "0"}, "experiments[2].gauge = 0", "must be a number > 0"),
    ({"radius": "3.0"}, "experiments[2].radius = 3.0", "2 DIC point.s. within radius = 3 mm"),
    ({"pairs": '"yes"'}, "experiments[2].pairs = 'yes'", "must be true"),
    ({"pairs": "true"}, "experiments[2].pairs = True", "offset -6 mm .*: 0 DIC point"),  # the field covers a half
    ({"gage": "6.0"}, "experiments[2]", "gage"),
    ({"offsets": "[5, 8]"}, "experiments[2]", "offsets"),  # not a key of the opening
    ({"weight": "-1"}, "experiments[2].weight = -1", "> 0"),
    ({"role": '"check"'}, "experiments[2].role = 'check'", "'source'"),
    ({"kind": '"fpz-width"', "gauge": None, "offsets": "[5, 8]", "threshold": "3e-5", "radius": "1"},
     "experiments[2].radius = 1", "DIC point.s. within radius"),
    ({"kind": '"fpz-width"', "gauge": None, "offsets": "[5]", "threshold": "3e-5"}, "experiments[2].offsets = [5]",
     "at least 2"),
    ({"kind": '"fpz-width"', "gauge": None, "offsets": "[-5, 5]", "threshold": "3e-5"},
     "experiments[2].offsets = [-5, 5]", "offset -5 mm"),  # no points on the other side of the crack
    ({"kind": '"fpz-width"', "gauge": None, "offsets": "[5, 8, 11, 14]"}, "experiments[2].threshold is missing",
     "strain above which"),
    ({"kind": '"fpz-width"', "gauge": None, "offsets": "[5, 8, 11, 14]", "threshold": "1e-3"},
     "experiments[2].threshold = 0.001", "has no variance"),
])
def test_bad_derived_keys_are_named(tmp_path, changes, key, message):
    from fracid.config import ConfigError, load_config

    derived = {k: v for k, v in {**OPENING, **changes}.items() if v is not None}
    with pytest.raises(ConfigError) as err:
        load_config(_config(tmp_path, field=LIGHT, derived=(derived,)))
    text = str(err.value)
    assert key in text and re.search(message, text), text


def test_a_field_name_given_twice_is_refused(tmp_path):
    from fracid.config import ConfigError, load_config

    path = _config(tmp_path, field=LIGHT, derived=())
    text = path.read_text(encoding="utf-8").split("[identify]")
    field = "[[experiments]]" + text[0].split("[[experiments]]")[2]
    path.write_text(text[0] + field + _block(OPENING) + "[identify]" + text[1], encoding="utf-8")
    with pytest.raises(ConfigError, match=r"experiments\[3\].field = 'field': names 2 field blocks"):
        load_config(path)


def test_fracid_check_lists_the_derived_block(tmp_path, capsys):
    from fracid import cli

    assert cli.main(["check", str(_config(tmp_path, field=LIGHT)), "--no-time"]) == 0
    out = capsys.readouterr().out
    assert "data block 'opening': 4 points, control 0.2 to 0.2 mm" in out and "data block 'field'" not in out
    assert cli.main(["check", str(_config(tmp_path, field=LIGHT, derived=({**OPENING, "gauge": "-6"},))),
                     "--no-time"]) == 2
    err = capsys.readouterr().err
    assert "experiments[2].gauge = -6" in err and "Traceback" not in err
