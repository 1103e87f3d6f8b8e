"""``[model] law``: a crack model's traction-separation law named in the configuration (the parameters are then
the law's), refused by name where it does not apply, and run by ``fracid simulate``."""

import csv
from pathlib import Path

import numpy as np
import pytest

from fracid import cli
from fracid.config import ConfigError, build_model, build_parameters, load_config
from fracid.fem.material.laws import BilinearSoftening, HordijkLaw, LinearSoftening

BASE = (Path(__file__).parent / "configs" / "beam_cohesive_simulate.toml").read_text(encoding="utf-8")
HORDIJK_CONSTANTS = "c1 = 3.0                            # Hordijk's constants\nc2 = 6.93\n"


def _config(tmp_path, law_line, *, keep_constants=False, model="cohesive-crack"):
    text = BASE.replace('type = "cohesive-crack"\n', f'type = "{model}"\n{law_line}\n')
    if not keep_constants:
        text = text.replace(HORDIJK_CONSTANTS, "")
    path = tmp_path / "cfg.toml"
    path.write_text(text, encoding="utf-8")
    return path


@pytest.mark.parametrize("name, law", [("hordijk", HordijkLaw), ("linear", LinearSoftening),
                                       ("bilinear", BilinearSoftening)])
def test_the_named_law_builds_the_model_and_its_parameters(tmp_path, name, law):
    cfg = load_config(_config(tmp_path, f'law = "{name}"', keep_constants=name == "hordijk"), purpose="simulate")
    model = build_model(cfg)
    assert isinstance(model.law, law) and model.key == f"cohesive-crack-{name}"
    params = build_parameters(cfg)
    assert isinstance(params, law().parameters) and (params.ft, params.Gf) == (3.0, 0.1)


def test_without_a_law_the_crack_model_keeps_hordijks():
    from fracid.models import model_from_type

    assert isinstance(model_from_type("crack-band").law, HordijkLaw)
    assert model_from_type("crack-band", "linear").key.startswith("crack-band-linear")


@pytest.mark.parametrize("law_line, model, keep, words", [
    ('law = "cubic"', "cohesive-crack", False, ("model.law = 'cubic'", "'hordijk'", "'linear'", "'bilinear'")),
    ('law = "linear"', "gradient-damage", False, ("model.law = 'linear'", "must be one of 'exponential'")),
    ('law = "linear"', "cohesive-crack", True, ("model.parameters.c1", "LinearSofteningParameters")),
])
def test_a_law_that_does_not_apply_is_refused_by_name(tmp_path, law_line, model, keep, words):
    path = _config(tmp_path, law_line, keep_constants=keep, model=model)
    if model == "gradient-damage":  # its parameters are the damage model's: drop the cohesive ones
        path.write_text(path.read_text().split("[model.parameters]")[0] + "[specimen]" +
                        path.read_text().split("[specimen]")[1])
    with pytest.raises(ConfigError) as info:
        load_config(path, purpose="simulate")
    assert all(word in str(info.value) for word in words), str(info.value)


def test_the_damage_models_name_their_laws_from_the_registry(tmp_path, monkeypatch):
    """The damage models declare the damage laws of DAMAGE_LAWS: the exponential law by name, and a law
    registered there is accepted by [model] law with no change to the models or the configuration."""
    from dataclasses import replace

    from fracid.fem.material import laws
    from fracid.models import model_from_type

    assert model_from_type("gradient-damage", "exponential") == model_from_type("gradient-damage")
    monkeypatch.setitem(laws.DAMAGE_LAWS, "steep", lambda: replace(laws.DamageLaw(), name="steep"))
    model = model_from_type("local-damage", "steep")
    assert model.key == "local-damage-steep" and model.regularization == "local"
    path = tmp_path / "cfg.toml"
    path.write_text(BASE.split("[model.parameters]")[0].replace('type = "cohesive-crack"\n',
                                                                 'type = "gradient-damage"\nlaw = "steep"\n')
                    + "[specimen]" + BASE.split("[specimen]")[1], encoding="utf-8")
    assert build_model(load_config(path, purpose="simulate")).key == "gradient-damage-steep"


def test_fracid_simulate_runs_the_linear_law_with_its_higher_peak(tmp_path):
    peaks = {}
    for name in ("hordijk", "linear"):
        directory = tmp_path / name
        directory.mkdir()
        config = _config(directory, f'law = "{name}"', keep_constants=name == "hordijk")
        assert cli.main(["simulate", str(config), "--out", str(directory / "out"), "--quiet"]) == 0
        with open(directory / "out" / "curve.csv", newline="") as handle:
            rows = list(csv.reader(handle))
        force = np.array([float(row[1]) for row in rows[1:]])
        peaks[name] = float(force.max())
    # at equal ft and Gf the linear law starts softening with the slope ft^2 / (2 Gf), Hordijk's with about
    # 1.35 ft^2 / Gf: the ligament carries more just after cracking starts, so the beam's peak is higher
    assert peaks["linear"] > 1.05 * peaks["hordijk"], peaks
