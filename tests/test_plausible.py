"""The plausibility of what ``[model.parameters]`` fixes (fracid.config.plausible): the band's width each model
declares against the room each specimen declares, and the values far outside their usual ranges; the bundled
configurations (every ``fracid init`` template, the demo, the examples, the datasets') pass without these warnings."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from fracid.config import load_config
from fracid.config.checker import Checker
from fracid.config.plausible import (REFUSE, WARN, band_advice, band_verdict, check_band_room,
                                     warn_implausible_parameters)
from fracid.config.schema import ConfigError, ModelConfig, SpecimenConfig
from fracid.models import declared, model_from_type
from fracid.specimens import SPECIMENS, BarWithWeakZone, DogBone, NotchedBeam, TensionStrip, WedgeSplitting
from fracid.specimens.protocol import SpecimenDefaults, bounding_room

ROOT = Path(__file__).resolve().parents[1]


def _band(kind):
    return declared(model_from_type(kind)).band_width


# ---------------------------------------------------------------- what the models and specimens declare


def test_the_models_declare_their_bands_width():
    pf, gradient, integral = _band("pf-czm"), _band("gradient-damage"), _band("integral-damage")
    assert (pf.parameter, pf.unit, pf.warn) == ("l", "mm", 0.5)
    assert pf.width(2.5) == pytest.approx(math.pi * 2.5)  # d = 1 - sin(|x| / l) vanishes at |x| = pi l / 2
    for band in (gradient, integral):
        assert (band.parameter, band.unit, band.warn) == ("c", "mm^2", 0.5)
        assert band.width(9.0) == pytest.approx(2.0 * math.pi * 3.0)
        assert band.width(4.5) == pytest.approx(math.pi * math.sqrt(2.0) * math.sqrt(2.0 * 4.5))  # pi sqrt(2) l
    for kind in ("local-damage", "cohesive-crack", "crack-band"):
        assert _band(kind) is None


@pytest.mark.parametrize("kind", ["pf-czm", "gradient-damage"])
def test_value_for_inverts_width(kind):
    band = _band(kind)
    for value in (0.01, 1.0, 7.3, 400.0):
        assert band.value_for(band.width(value)) == pytest.approx(value, rel=1e-12)


def test_the_specimens_declare_their_room():
    assert BarWithWeakZone(length=80.0).band_room().length == 80.0
    assert TensionStrip(length=120.0).band_room().length == 120.0
    assert NotchedBeam(depth=100.0, notch_depth=50.0).band_room().length == 100.0
    assert DogBone(size=200.0).band_room().length == pytest.approx(120.0)  # the width 0.6 D at mid-height
    assert WedgeSplitting().band_room().length == 200.0
    for cls in SPECIMENS.values():
        instance = cls.default_instance()
        if instance is not None:
            room = instance.band_room()
            assert room.length > 0 and f"{room.length:g} mm" in room.text


def test_bounding_room_mirrors_symmetry_planes():
    quarter = np.array([[0.0, 0.0], [30.0, 0.0], [30.0, 75.0], [0.0, 75.0]])
    assert bounding_room(quarter) == 30.0
    assert bounding_room(quarter, ((0, 0.0),)) == 60.0  # mirrored about x = 0: the whole width
    assert bounding_room(quarter, ((0, 0.0), (1, 0.0))) == 60.0  # the height 150 is larger
    assert bounding_room(np.array([[0.0], [100.0]])) == 100.0  # a bar
    assert bounding_room(quarter, ((1, 0.0),), max) == 150.0  # the largest side


def test_the_default_mesh_specimen_room_is_its_bounding_box():
    """A specimen without a room of its own (a Gmsh mesh) gets the smallest side of its described bounding box."""
    beam = NotchedBeam()
    assert SpecimenDefaults.band_room(beam).length == pytest.approx(beam.depth)  # the half beam mirrored: 175 x 50


class _Plank(TensionStrip):
    """A strip that declares no room of its own: the default's, of its bounding box (as a Gmsh mesh)."""

    band_room = SpecimenDefaults.band_room


def test_a_specimen_of_unknown_crack_direction_is_refused_only_beyond_its_largest_side(monkeypatch):
    """The default room warns against the smallest side (a beam's depth) and refuses only beyond the largest (a
    strip's band lies along its length): read through the registry, a specimen registered from a test too."""
    room = _Plank().band_room()
    assert (room.length, room.limit.length) == (10.0, 100.0)
    assert "smallest side" in room.text and "largest side" in room.limit.text
    monkeypatch.setitem(SPECIMENS, "plank", _Plank)
    plank = SpecimenConfig(type="plank", control="band_opening")
    (warning,) = _checked(ModelConfig(type="gradient-damage", parameters=(("c", 4.0),)), plank)
    assert "1.26 times" in warning and "smallest side of its bounding box, 10 mm" in warning
    assert _checked(ModelConfig(type="gradient-damage", parameters=(("c", 0.6),)), plank) == []
    with pytest.raises(ConfigError, match=r"largest side of its bounding box, 100 mm: the band cannot form"):
        _checked(ModelConfig(type="gradient-damage", parameters=(("c", 260.0),)), plank)


# ---------------------------------------------------------------- the verdict, both directions


@pytest.mark.parametrize("fraction, warn, verdict", [(1.01, 0.25, REFUSE), (31.4, 0.25, REFUSE), (1.0, 0.25, WARN),
                                                     (0.26, 0.25, WARN), (0.25, 0.25, None), (0.1, 0.25, None),
                                                     (0.51, 0.5, WARN), (0.49, 0.5, None)])
def test_band_verdict(fraction, warn, verdict):
    assert band_verdict(fraction, warn) == verdict


def test_band_advice_gives_the_values_that_fit():
    text = band_advice(_band("pf-czm"), 100.0)
    assert "lower l below 31.8 mm" in text and "15.9 mm or less" in text and "50%" in text
    text = band_advice(_band("gradient-damage"), 100.0)
    assert "lower c below 253 mm^2" in text and "63.3 mm^2 or less" in text and "50%" in text


def _checked(model: ModelConfig, specimen: SpecimenConfig, identify=None) -> list:
    ck = Checker(Path("cfg.toml"))
    check_band_room(ck, model, specimen, (), identify)
    return ck.warnings


def test_check_band_room_refuses_warns_and_passes():
    bar = SpecimenConfig(type="bar", control="end_displacement", options=(("length", 100.0),))
    with pytest.raises(ConfigError, match=r"model.parameters.l = 1000 mm: .*31.4 times.*lower l below 31.8 mm"):
        _checked(ModelConfig(type="pf-czm", parameters=(("l", 1000.0),)), bar)
    (warning,) = _checked(ModelConfig(type="pf-czm", parameters=(("l", 16.0),)), bar)
    assert "model.parameters.l = 16 mm" in warning and "50.3% of" in warning and "more than the 50%" in warning
    assert _checked(ModelConfig(type="pf-czm", parameters=(("l", 15.9),)), bar) == []
    assert _checked(ModelConfig(type="pf-czm"), bar) == []
    assert _checked(ModelConfig(type="local-damage", parameters=(("c", 1e6),)), bar) == []  # no band: nothing
    with pytest.raises(ConfigError, match=r"model.parameters.c = 1 mm\^2 \(default\).*its length = 5 mm"):
        _checked(ModelConfig(type="gradient-damage"), SpecimenConfig(type="bar", control="end_displacement", options=(("length", 5.0),
                                                                                           ("weak_zone_width", 1.0))))


def test_an_experiments_smaller_specimen_is_checked_and_named():
    """An experiment that overrides the specimen's fields is checked with its own room, and named."""
    from types import SimpleNamespace

    bar = SpecimenConfig(type="bar", control="end_displacement", options=(("length", 100.0),))
    short = SimpleNamespace(index=1, specimen=(("length", 20.0), ("weak_zone_width", 2.0)))
    model = ModelConfig(type="gradient-damage", parameters=(("c", 4.0),))
    ck = Checker(Path("cfg.toml"))
    check_band_room(ck, model, bar, (SimpleNamespace(index=0, specimen=()), short), None)
    (warning,) = ck.warnings  # 12.6 mm: 12.6 % of the 100 mm bar, 62.8 % of the 20 mm one
    assert "of experiments[1].specimen" in warning and "62.8% of" in warning and "its length = 20 mm" in warning


@pytest.mark.parametrize("upper, warned", [(300.0, True), (254.0, True), (252.0, False), (4.0, False)])
def test_an_upper_bound_whose_band_cannot_form_is_warned(upper, warned):
    """2 pi sqrt(c) = 100 mm at c = 253 mm^2: the bound's upper end beyond it is warned (not refused), below not."""
    from types import SimpleNamespace

    bar = SpecimenConfig(type="bar", control="end_displacement", options=(("length", 100.0),))
    identify = SimpleNamespace(parameters=("c", "beta"), upper=(upper, 500.0))
    warnings = _checked(ModelConfig(type="gradient-damage"), bar, identify)
    assert len(warnings) == warned
    if warned:
        assert f"identify.bounds.c: the upper bound {upper:g} mm^2" in warnings[0] and "below 253 mm^2" in warnings[0]


def test_warn_implausible_parameters_names_the_key_both_directions():
    ck = Checker(Path("cfg.toml"))
    warn_implausible_parameters(ck, ModelConfig(type="gradient-damage", parameters=(("E", 30.0), ("kappa_i", 0.05),
                                                                                    ("c", 9.0))))
    assert len(ck.warnings) == 2
    assert "model.parameters.E = 30 is implausible" in ck.warnings[0] and "1/167" in ck.warnings[0]
    assert "model.parameters.kappa_i = 0.05" in ck.warnings[1] and "50 times" in ck.warnings[1]
    ck = Checker(Path("cfg.toml"))
    warn_implausible_parameters(ck, ModelConfig(type="gradient-damage", parameters=(("E", 600.0), ("eta", 290.0))))
    assert ck.warnings == []  # within 10 times of the usual ranges


# ---------------------------------------------------------------- the bundled configurations


def _bundled(tmp_path) -> list:
    from fracid.cli.common import demo_config_path
    from fracid.cli.init import config_text, runnable_pairs

    paths = []
    for specimen, model in runnable_pairs():
        path = tmp_path / f"{specimen}-{model}.toml"
        path.write_text(config_text(specimen, model))
        paths.append((path, "simulate"))
    paths.append((demo_config_path(), "identify"))
    paths += [(path, "identify") for path in sorted((ROOT / "examples").rglob("*.toml"))]
    paths += [(path, "identify") for path in sorted((ROOT / "src" / "fracid" / "datasets").rglob("*.toml"))]
    return paths


def _sections(path: Path, ck: Checker):
    """[model], [specimen] and [identify] of a configuration read as load_config reads them; the experiments' data
    are not read (a DIC example's take a minute: they change nothing here, no example overrides its specimen)."""
    from fracid.config.checker import read_toml
    from fracid.config.identify import read_identify
    from fracid.config.sections import read_model, read_specimen

    raw = read_toml(path)
    assert not any("specimen" in e for e in raw.get("experiments", [])), path
    model = read_model(ck, raw.get("model"))
    return model, read_specimen(ck, raw.get("specimen"), path.parent), read_identify(ck, raw.get("identify"), None,
                                                                                     False, model)


def test_the_bundled_configurations_pass_without_these_warnings(tmp_path):
    """Each template of ``fracid init --list``, the demo, the examples and the datasets' configurations: neither
    the band's room nor an implausible value is warned about (in-process, nothing simulated)."""
    bundled = _bundled(tmp_path)
    assert len(bundled) >= 27
    for path, _ in bundled:
        ck = Checker(path)
        model, specimen, identify = _sections(path, ck)
        warn_implausible_parameters(ck, model)
        check_band_room(ck, model, specimen, (), identify)
        assert ck.warnings == [], (path, ck.warnings)


def test_the_templates_load_without_these_warnings(tmp_path):
    """The templates through load_config itself (its other warnings, a mesh's resolution, are not these)."""
    for path, purpose in (item for item in _bundled(tmp_path) if item[1] == "simulate"):
        cfg = load_config(path, purpose=purpose)
        assert not [text for text in cfg.warnings if "room of the specimen" in text or "implausible" in text], path
