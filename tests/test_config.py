"""fracid.config: TOML configurations are validated when loaded; every error names the file, key and value.

No forward runs: loading, building data, operator, space and settings only.
"""

import dataclasses
import shutil
from pathlib import Path

import numpy as np
import pytest

from fracid import datasets
from fracid.config import (
    ConfigError,
    build_data,
    build_operator,
    build_parameters,
    build_space,
    build_specimen,
    build_method,
    load_config,
    simulate_settings,
)
from fracid.inverse.core.forward_operator import ForwardOperator
from fracid.inverse.core.space import ParameterSpace
from fracid.inverse.methods.knn_settings import DEFAULT_SCREENING, KnnSettings
from fracid.fem.material.parameters import DamageParameters
from fracid.models import DamageModel
from fracid.specimens.bar import BarWithWeakZone
from fracid.specimens.beam import NotchedBeam
from fracid.specimens.description import conditions

CONFIGS = Path(__file__).parent / "configs"

# The valid beam identification (bundled Gregoire data copied next to the file as load_cmod.csv).
BEAM = """\
[model]
type = "gradient-damage"
[model.parameters]
E = 37000.0
kappa_i = 6.6e-5
c = 9.0

[specimen]
type = "notched-beam"
control = "cmod"
h_fine = 2.0

[[experiments]]
file = "load_cmod.csv"
control_column = "cmod_mm"
control_unit = "mm"
force_unit = "N"
kind = "envelope"
mean_column = "load_mean_N"
lower_column = "load_min_N"
upper_column = "load_max_N"
n_points = 40

[identify]
parameters = ["kappa_i", "beta", "c"]
[identify.bounds]
kappa_i = [4e-5, 1.2e-4]
beta = [100.0, 2000.0]
c = [1.0, 30.0]
log = ["beta"]
[identify.knn]
n = 64
method = "sobol"
k = 5
seed = 0
[identify.kalman]
groups = 4
max_iterations = 10
tol = 0.01
restart = "linearize"

[output]
directory = "results"
vtk_steps = []
"""

BAR_SIMULATE = """\
[model]
type = "local-damage"
[model.parameters]
E = 20000.0
kappa_i = 1e-4
c = 2.0

[specimen]
type = "bar"
control = "weak_zone_elongation"
length = 100
weak_zone_width = 10.0
profile = "hat"
n_elements = 120

[simulate]
target = 0.05
stop_force_fraction = 0.2
damage_threshold = 0.1

[output]
directory = "/tmp/fracid-bar-out"
vtk_steps = [20, 10]
"""


def write(tmp_path, text, name="study.toml"):
    """The configuration in tmp_path, with the bundled Gregoire data beside it."""
    shutil.copy(datasets.path("gregoire2013-beam4"), tmp_path / "load_cmod.csv")
    path = tmp_path / name
    path.write_text(text)
    return path


def variant(old, new, base=BEAM):
    assert old in base, old
    return base.replace(old, new, 1)


# ------------------------------------------------------------------------------------ valid configs


def test_valid_beam_config_loads_and_builds_everything(tmp_path):
    path = write(tmp_path, BEAM)
    cfg = load_config(path)
    with pytest.raises(dataclasses.FrozenInstanceError):
        cfg.purpose = "simulate"

    params = build_parameters(cfg)
    assert params == DamageParameters(E=37000.0, kappa_i=6.6e-5, c=9.0)
    specimen = build_specimen(cfg)
    assert specimen == NotchedBeam(h_fine=2.0)

    data = build_data(cfg)
    assert data.y.shape == (40,) and data.covariance.shape == (40, 40)
    assert data.blocks == (("global", 0, 40),)

    operator = build_operator(cfg, data)
    assert isinstance(operator, ForwardOperator)
    assert operator.n_outputs == 40
    assert operator.names == ("kappa_i", "beta", "c") and operator.regularization == "gradient"
    assert operator.base == params
    (obs,) = operator.observations
    assert obs.quantity == "force" and obs.control == "cmod" and obs.specimen == specimen
    np.testing.assert_array_equal(obs.control_points, data.control)

    space = build_space(cfg)
    assert isinstance(space, ParameterSpace) and len(space.names) == 3
    np.testing.assert_allclose(space.lower, [4e-5, 100.0, 1.0])
    np.testing.assert_allclose(space.upper, [1.2e-4, 2000.0, 30.0])
    assert space.log == (False, True, False)

    method = build_method(cfg)
    # the configuration's default population runs on a screening mesh; KnnSettings() (the library's) does not
    assert method.knn == KnnSettings(n=64, method="sobol", seed=0, k=5, screening=DEFAULT_SCREENING)
    assert (method.kalman.max_iterations, method.kalman.tol, method.kalman.restart) == (10, 0.01, "linearize")
    groups = method.kalman.groups
    assert len(groups) == 4  # DEFAULT_GROUPS consecutive steps
    np.testing.assert_array_equal(np.concatenate(groups), np.arange(40))

    assert cfg.output.directory == tmp_path / "results"
    assert cfg.output.vtk_steps == ()


def test_valid_bar_simulate_config(tmp_path):
    cfg = load_config(write(tmp_path, BAR_SIMULATE), purpose="simulate")
    assert cfg.experiments == () and cfg.identify is None
    bar = build_specimen(cfg)
    assert bar == BarWithWeakZone(length=100.0, weak_zone_width=10.0, profile="hat", n_elements=120)
    assert isinstance(bar.length, float) and isinstance(bar.n_elements, int)
    assert build_parameters(cfg) == DamageParameters(E=20000.0, kappa_i=1e-4, c=2.0)
    assert simulate_settings(cfg) == {
        "regularization": "local", "control": "weak_zone_elongation", "target": 0.05,
        "stop_force_fraction": 0.2, "damage_threshold": 0.1, "field_steps": [10, 20]}
    assert cfg.output.directory == Path("/tmp/fracid-bar-out")
    # the same file is not enough for an identification
    with pytest.raises(ConfigError, match=r"experiments is missing"):
        load_config(tmp_path / "study.toml")


def test_defaults_fill_optional_sections(tmp_path):
    text = 'specimen = { type = "dogbone", size = 200.0 }\n'
    cfg = load_config(write(tmp_path, text), purpose="simulate")
    assert cfg.specimen.control == "elongation"
    assert cfg.model.regularization == "gradient" and build_parameters(cfg) == DamageParameters()
    assert cfg.output.directory == tmp_path / "results"
    assert simulate_settings(cfg)["target"] is None and simulate_settings(cfg)["field_steps"] == "last"


@pytest.mark.parametrize("name, purpose", [("beam_identify.toml", "identify"), ("bar_simulate.toml", "simulate")])
def test_example_files_load(name, purpose):
    cfg = load_config(CONFIGS / name, purpose=purpose)
    build_specimen(cfg)
    if purpose == "identify":
        data = build_data(cfg)
        assert build_operator(cfg, data).n_outputs == data.n_y == 40


def test_units_scale_and_blocks_stack(tmp_path):
    """Repeats in kN against um, plus a local block in um with an absolute std: scaled to N and mm."""
    control_um = np.linspace(0.0, 200.0, 21)
    rows = ["u_um,F1_kN,F2_kN,width_um"] + [
        f"{u},{1e-3 * u},{1.1e-3 * u},{10 * u}" for u in control_um]
    (tmp_path / "bar.csv").write_text("\n".join(rows) + "\n")
    text = """\
[specimen]
type = "bar"
n_elements = 100

[[experiments]]
file = "bar.csv"
control_column = "u_um"
control_unit = "um"
force_unit = "kN"
kind = "repeats"
force_columns = ["F1_kN", "F2_kN"]
n_points = 5
control_range = [40.0, 200.0]

[[experiments]]
file = "bar.csv"
control_column = "u_um"
control_unit = "um"
force_unit = "um"
kind = "single"
force_columns = ["width_um"]
std = 50.0
n_points = 3
control_range = [100.0, 200.0]
quantity = "damaged_zone_width"

[identify]
parameters = ["c"]
bounds = { c = [0.5, 4.0] }
knn = { method = "grid", n = 5, k = 5 }
"""
    cfg = load_config(write(tmp_path, text))
    data = build_data(cfg)
    assert [b[0] for b in data.blocks] == ["global", "damaged_zone_width"]
    np.testing.assert_allclose(data.control, [0.04, 0.08, 0.12, 0.16, 0.2, 0.1, 0.15, 0.2])
    np.testing.assert_allclose(data.y[:5], 1.05 * np.array([40.0, 80.0, 120.0, 160.0, 200.0]))  # N
    np.testing.assert_allclose(data.y[5:], [1.0, 1.5, 2.0])  # mm
    np.testing.assert_allclose(data.std[5:], 0.05)  # 50 um
    operator = build_operator(cfg, data)
    assert [o.quantity for o in operator.observations] == ["force", "damaged_zone_width"]
    assert [o.control for o in operator.observations] == ["end_displacement"] * 2
    assert operator.n_outputs == 8
    method = build_method(cfg)
    assert method.knn.method == "grid"  # default grouping: DEFAULT_GROUPS = 4 consecutive steps
    assert [g.tolist() for g in method.kalman.groups] == [[0, 1], [2, 3], [4, 5], [6, 7]]


def test_specimen_maps_match_the_specimens():
    """The controls and observables the config accepts are those the specimens provide."""
    from fracid.config.registry import SPECIMEN_DEFAULTS, specimen_class

    params = DamageParameters()
    for kind, (controls, observables) in SPECIMEN_DEFAULTS.items():
        cls = specimen_class(kind)
        assert cls.default_control == controls[0]
        assert set(DamageModel().observers(cls().describe(), params)) == set(observables)
    problem = DamageModel().build(BarWithWeakZone(n_elements=20), params)
    assert set(problem.functionals) == set(SPECIMEN_DEFAULTS["bar"][0])


def test_restart_is_a_setting_of_the_built_method(tmp_path):
    cfg = load_config(write(tmp_path, variant('restart = "linearize"', 'restart = "prior-mean"')))
    assert build_method(cfg).kalman.restart == "prior-mean"


def test_single_curve_with_relative_std(tmp_path):
    text = variant('kind = "envelope"\nmean_column = "load_mean_N"\nlower_column = "load_min_N"\n'
                   'upper_column = "load_max_N"',
                   'kind = "single"\nforce_columns = ["load_mean_N"]\nrelative_std = 0.05')
    data = build_data(load_config(write(tmp_path, text)))
    assert data.n_y == 40
    np.testing.assert_allclose(data.std, np.maximum(0.05 * np.abs(data.y), 0.01 * np.abs(data.y).max()))


@pytest.mark.parametrize("sampling", [None, "equally-spaced", "measured"])
def test_sampling_reaches_the_data_and_keeps_the_measured_peak(tmp_path, sampling):
    text = BEAM if sampling is None else variant("n_points = 40", f'n_points = 40\nsampling = "{sampling}"')
    cfg = load_config(write(tmp_path, text))
    assert cfg.experiments[0].sampling == (sampling or "equally-spaced")
    data = build_data(cfg)
    assert data.n_y == 40 and data.y.max() == 978.6185 and data.control[np.argmax(data.y)] == 0.01934611
    measured = sampling == "measured"
    assert any(("measured points" in note) == measured for note in data.notes if "control points" in note
               or "measured points" in note)


def test_a_bad_sampling_exits_2_naming_the_key(tmp_path, capsys):
    from fracid import cli
    from fracid.runtime import exits

    path = write(tmp_path, variant("n_points = 40", 'n_points = 40\nsampling = "all"'))
    assert cli.main(["identify", str(path), "--out", str(tmp_path / "out"), "--quiet"]) == exits.INPUT
    err = capsys.readouterr().err
    assert "experiments[0].sampling" in err and "'equally-spaced', 'measured'" in err


def test_data_errors_are_wrapped(tmp_path):
    text = variant("n_points = 40", "n_points = 40\ncontrol_range = [0.001, 9.0]")
    cfg = load_config(write(tmp_path, text))
    with pytest.raises(ConfigError) as info:
        build_data(cfg)
    message = str(info.value)
    assert "experiments[0]" in message and str(tmp_path / "load_cmod.csv") in message and "9" in message


def test_toml_syntax_error_names_file_and_line(tmp_path):
    path = write(tmp_path, variant('seed = 0', 'seed = '))
    with pytest.raises(ConfigError) as info:
        load_config(path)
    line = BEAM.splitlines().index("seed = 0") + 1
    assert str(path) in str(info.value) and f"line {line}" in str(info.value)


def test_missing_config_file(tmp_path):
    with pytest.raises(ConfigError, match="configuration file not found"):
        load_config(tmp_path / "nope.toml")


# ------------------------------------------------------------------------------------- bad configs

BAD = [
    pytest.param(BEAM + "\n[outputs]\ndirectory = 'x'\n", "identify",
                 ["outputs", "unknown key; allowed keys here: model, specimen, experiments"], id="unknown-top-level-key"),
    pytest.param(variant("seed = 0", "seed = 0\nneighbours = 7"), "identify",
                 ["identify.knn.neighbours", "7", "unknown key; allowed keys here: n, method, k, seed"],
                 id="unknown-key-in-section"),
    pytest.param(variant("kappa_i = 6.6e-5\nc = 9.0", "kappa_i = 6.6e-5\nc = -9.0"), "identify",
                 ["model.parameters.c", "-9.0", "0 < c", "mm^2"], id="negative-c"),
    pytest.param(variant("c = 9.0", "c = 9.0\nalpha = 1.2"), "identify",
                 ["model.parameters.alpha", "1.2", "0 <= alpha <= 1"], id="alpha-above-1"),
    pytest.param(variant("c = 9.0", "c = 9.0\nnu = 0.5"), "identify",
                 ["model.parameters.nu", "0.5", "-1 < nu < 0.5"], id="nu-0.5"),
    pytest.param(variant("c = [1.0, 30.0]", "c = [30.0, 1.0]"), "identify",
                 ["identify.bounds.c", "[30.0, 1.0]", "must be below upper"], id="bounds-reversed"),
    pytest.param(variant("c = [1.0, 30.0]", "c = [0.0, 30.0]"), "identify",
                 ["identify.bounds.c", "[0.0, 30.0]", "lower bound 0 is outside the valid range 0 < c"],
                 id="bounds-outside-valid-range"),
    pytest.param(variant('file = "load_cmod.csv"', 'file = "data/missing.csv"'), "identify",
                 ["experiments[0].file", "'data/missing.csv'", "file not found (resolved relative to the config file"],
                 id="missing-data-file"),
    pytest.param(variant('mean_column = "load_mean_N"', 'mean_column = "load_avg_N"'), "identify",
                 ["experiments[0].mean_column", "'load_avg_N'", "available columns: 'cmod_mm', 'load_mean_N'"],
                 id="wrong-column-name"),
    pytest.param(variant('control_unit = "mm"\n', ""), "identify",
                 ["experiments[0].control_unit", "missing", "'mm', 'um', 'm'"], id="unit-missing"),
    pytest.param(variant('force_unit = "N"', 'force_unit = "lbf"'), "identify",
                 ["experiments[0].force_unit", "'lbf'", "one of 'N', 'kN', 'MN'"], id="unknown-unit"),
    pytest.param(variant("n = 64\nmethod = \"sobol\"\nk = 5", "n = 8\nmethod = \"sobol\"\nk = 9"), "identify",
                 ["identify.knn.k", "9", "population size 8"], id="k-above-population"),
    pytest.param(variant('type = "notched-beam"', 'type = "beam"'), "identify",
                 ["specimen.type", "'beam'", "one of 'notched-beam', 'dogbone', 'bar'"], id="unknown-specimen-type"),
    pytest.param(variant('control = "cmod"', 'control = "elongation"'), "identify",
                 ["specimen.control", "'elongation'", "one of 'cmod', 'deflection'"], id="unknown-control"),
    pytest.param(variant('parameters = ["kappa_i", "beta", "c"]', 'parameters = ["kappa_i", "beta", "l"]'), "identify",
                 ["identify.parameters", "'l'", "not a model parameter"], id="not-a-model-parameter"),
    pytest.param(variant('parameters = ["kappa_i", "beta", "c"]', 'parameters = ["kappa_i", "beta", "c", "beta"]'),
                 "identify", ["identify.parameters", "['kappa_i', 'beta', 'c', 'beta']", "duplicate parameter 'beta'"],
                 id="duplicate-parameter"),
    pytest.param(variant("beta = [100.0, 2000.0]", "beta = [0.0, 2000.0]"), "identify",
                 ["identify.bounds.log", "['beta']", "lower bound > 0", "lower = 0"], id="log-with-lower-0"),
    pytest.param(variant("n_points = 40", "n_points = 2"), "identify",
                 ["experiments[0].n_points", "2", "integer >= 3"], id="n_points-below-3"),
    pytest.param(variant('upper_column = "load_max_N"\n', ""), "identify",
                 ["experiments[0].upper_column", "missing", "kind 'envelope'"], id="envelope-missing-column"),
    pytest.param(variant("E = 37000.0", 'E = "37000"'), "identify",
                 ["model.parameters.E", "'37000'", "must be a number"], id="string-for-number"),
    pytest.param(variant("h_fine = 2.0", "h_fine = 2.0\nnotch_depth = 60.0"), "identify",
                 ["specimen.notch_depth", "60.0", "must be smaller than depth"], id="specimen-own-validation"),
    pytest.param(variant("h_fine = 2.0", "h_fine = 2.0\nwidht = 60.0"), "identify",
                 ["specimen.widht", "60.0", "unknown key; allowed keys here: type, control, depth"],
                 id="unknown-specimen-field"),
    pytest.param(variant("h_fine = 2.0", 'h_fine = "fine"'), "identify",
                 ["specimen.h_fine", "'fine'", "must be a number"], id="specimen-field-type"),
    pytest.param(variant("groups = 4", "groups = 41"), "identify",
                 ["identify.kalman.groups", "41", "n_y = 40"], id="too-many-groups"),
    pytest.param(variant('restart = "linearize"', 'restart = "again"'), "identify",
                 ["identify.kalman.restart", "'again'", "'linearize', 'prior-mean'"], id="unknown-restart"),
    pytest.param(variant("n_points = 40", 'n_points = 40\nquantity = "damaged_zone_width"'), "identify",
                 ["experiments[0].quantity", "'damaged_zone_width'", "one of 'force', 'fpz_width'"],
                 id="quantity-not-an-observable"),
    pytest.param(variant("n_points = 40", "n_points = 40\ncontrol_range = [0.2, 0.1]"), "identify",
                 ["experiments[0].control_range", "[0.2, 0.1]", "0 < start < stop"], id="control-range-reversed"),
    pytest.param(variant("n_points = 40", "n_points = 40\nstd = 20.0"), "identify",
                 ["experiments[0].std", "20.0", "not used by kind 'envelope'"], id="key-of-another-kind"),
    pytest.param(variant("c = [1.0, 30.0]\n", ""), "identify",
                 ["identify.bounds.c", "missing"], id="bounds-missing"),
    pytest.param(variant("c = [1.0, 30.0]", "c = [1.0, 30.0]\nE = [1e4, 5e4]"), "identify",
                 ["identify.bounds.E", "[10000.0, 50000.0]", "unknown key; allowed keys here: kappa_i, beta, c, log"],
                 id="bounds-of-unidentified-parameter"),
    pytest.param(variant("vtk_steps = []", "vtk_steps = [1, -2]"), "identify",
                 ["output.vtk_steps", "[1, -2]", "integers >= 0"], id="negative-vtk-step"),
    pytest.param(BAR_SIMULATE.replace("stop_force_fraction = 0.2", "stop_force_fraction = 1.0"), "simulate",
                 ["simulate.stop_force_fraction", "1.0", "0 < f < 1"], id="stop-fraction-1"),
    pytest.param(BAR_SIMULATE.replace("n_elements = 120", "n_elements = 12.5"), "simulate",
                 ["specimen.n_elements", "12.5", "must be an integer"], id="float-for-integer"),
    pytest.param(BAR_SIMULATE.replace('type = "local-damage"', 'type = "nonlocal"'), "simulate",
                 ["model.type", "'nonlocal'", "one of 'gradient-damage', 'local-damage'"], id="unknown-model-type"),
    pytest.param(variant("n_points = 40", "n_points = 40\nweight = -1.0"), "identify",
                 ["experiments[0].weight", "-1.0", "must be a number > 0"], id="negative-weight"),
    pytest.param(variant("n_points = 40", "n_points = 40\ndamage_threshold = 0.5"), "identify",
                 ["experiments[0].damage_threshold", "0.5", "local quantity only"], id="threshold-on-force"),
    pytest.param(variant("n_points = 40", 'n_points = 40\nrole = "validation"'), "identify",
                 ["experiments[0].role", "'validation'", "'calibration', 'prediction'"], id="unknown-role"),
    pytest.param(variant("n_points = 40", 'n_points = 40\nrole = "prediction"'), "identify",
                 ["experiments", "role = 'calibration'"], id="nothing-to-calibrate"),
    pytest.param(variant("n_points = 40", "n_points = 40\nspecimen = { depth = 20.0 }"), "identify",
                 ["experiments[0].specimen.depth", "20.0", "notch"], id="override-breaks-specimen"),
    pytest.param(variant("n_points = 40", "n_points = 40\nspecimen = { size = 20.0 }"), "identify",
                 ["experiments[0].specimen.size", "unknown key"], id="override-unknown-field"),
    pytest.param(variant("vtk_steps = []", "vtk_steps = []\n[study]\nreplicates = 1"), "identify",
                 ["study.replicates", "1", ">= 2"], id="one-replicate"),
    pytest.param(variant("vtk_steps = []", "vtk_steps = []\n[study]\nprior = 'flat'"), "identify",
                 ["study.prior", "'flat'", "'search', 'bounds'"], id="unknown-prior"),
    pytest.param(variant("n_points = 40", 'n_points = 40\nsampling = "measured-points"'), "identify",
                 ["experiments[0].sampling", "'measured-points'", "'equally-spaced', 'measured'"],
                 id="unknown-sampling"),
    pytest.param(variant("n_points = 40", "n_points = 40\nsampling = 1"), "identify",
                 ["experiments[0].sampling", "1", "must be one of 'equally-spaced', 'measured'"], id="sampling-number"),
]


@pytest.mark.parametrize("text, purpose, words", BAD)
def test_bad_config_is_named(tmp_path, text, purpose, words):
    path = write(tmp_path, text)
    with pytest.raises(ConfigError) as info:
        load_config(path, purpose=purpose)
    message = str(info.value)
    assert isinstance(info.value, ValueError)
    assert "\n" not in message  # one paragraph
    assert message.startswith(str(path))
    for word in words:
        assert word in message, f"{word!r} not in: {message}"


# ------------------------------------------------------------------------- other forward models

COHESIVE = variant("""[model]
type = "gradient-damage"
[model.parameters]
E = 37000.0
kappa_i = 6.6e-5
c = 9.0
""", """[model]
type = "cohesive-crack"
[model.parameters]
E = 37000.0
ft = 3.0
Gf = 0.1
""", variant("""parameters = ["kappa_i", "beta", "c"]
[identify.bounds]
kappa_i = [4e-5, 1.2e-4]
beta = [100.0, 2000.0]
c = [1.0, 30.0]
log = ["beta"]""", """parameters = ["ft", "Gf"]
[identify.bounds]
ft = [1.5, 6.0]
Gf = [0.04, 0.3]
log = ["Gf"]"""))


def test_cohesive_model_config_builds_its_operator(tmp_path):
    from fracid.fem.material.cohesive import CohesiveParameters
    from fracid.models import CohesiveCrackModel

    cfg = load_config(write(tmp_path, COHESIVE))
    assert build_parameters(cfg) == CohesiveParameters(E=37000.0, ft=3.0, Gf=0.1)
    assert cfg.model.regularization is None and "regularization" not in simulate_settings(cfg)
    operator = build_operator(cfg, build_data(cfg))
    assert isinstance(operator.model, CohesiveCrackModel) and operator.names == ("ft", "Gf")
    assert operator.units == {"ft": "MPa", "Gf": "N/mm"}
    space = build_space(cfg)
    assert space.names == ("ft", "Gf") and space.log == (False, True)


def test_model_types_are_read_from_the_registry_when_loading(tmp_path, monkeypatch):
    """A model registered in fracid.models.MODEL_TYPES is a valid [model] type with no change to the config code."""
    import fracid.models
    from fracid.config import build_model

    text = COHESIVE.replace('type = "cohesive-crack"', 'type = "cohesive-crack-stiff"')
    with pytest.raises(ConfigError, match="model.type = 'cohesive-crack-stiff'"):
        load_config(write(tmp_path, text))
    monkeypatch.setitem(fracid.models.MODEL_TYPES, "cohesive-crack-stiff",
                        lambda: fracid.models.CohesiveCrackModel(penalty_factor=1e4))
    cfg = load_config(write(tmp_path, text))
    assert build_model(cfg).penalty_factor == 1e4
    assert build_operator(cfg, build_data(cfg)).model == fracid.models.CohesiveCrackModel(penalty_factor=1e4)


def test_simulate_cohesive_beam_from_its_config(tmp_path):
    """`fracid simulate` with type = "cohesive-crack" on a coarse beam: a peaked, softening curve and its energy."""
    from fracid.cli.dispatch import main

    assert main(["simulate", str(CONFIGS / "beam_cohesive_simulate.toml"), "--out", str(tmp_path), "--quiet"]) == 0
    with open(tmp_path / "curve.csv") as handle:
        names = handle.readline().strip().split(",")
    curve = dict(zip(names, np.loadtxt(tmp_path / "curve.csv", delimiter=",", skiprows=1).T))
    assert {"cmod", "force_N", "crack_length", "dissipated_energy"} <= set(curve)
    peak = int(np.argmax(curve["force_N"]))
    assert 0 < peak < curve["cmod"].size - 10  # softening after the peak
    assert 800.0 < curve["force_N"][peak] < 1100.0  # N; ft 3 MPa on the Gregoire beam (about 930 N)
    assert curve["cmod"][-1] == pytest.approx(0.3)  # target reached: the force stays above 10 % of the peak
    # the crack dissipates less than Gf times the ligament area before it has separated
    assert 0.0 < curve["dissipated_energy"][-1] < 0.1 * 25.0 * 50.0
    assert (tmp_path / "curve.png").stat().st_size > 0


from fracid.models import MODEL_TYPES  # noqa: E402  (every registered model is a valid type)

@pytest.mark.slow
def test_size_effect_runs_any_model(tmp_path):
    """The size-effect series takes the config's forward model: here the cohesive crack, three depths."""
    from fracid.cli.dispatch import main

    config = str(CONFIGS / "beam_cohesive_simulate.toml")
    assert main(["size-effect", config, "--sizes", "40", "50", "60", "--out", str(tmp_path), "--quiet"]) == 0
    table = np.loadtxt(tmp_path / "size_effect.csv", delimiter=",", skiprows=1)
    assert table.shape == (3, 3) and np.all(np.isfinite(table))
    assert np.all(np.diff(table[:, 1]) > 0)  # deeper beams carry more
    assert (tmp_path / "size_effect.png").stat().st_size > 0


BAD_MODELS = [
    pytest.param(variant('type = "gradient-damage"', 'type = "crack-bands"'), "identify",
                 ["model.type", "'crack-bands'", "must be one of " + ", ".join(map(repr, MODEL_TYPES))],
                 id="unknown-model-type-lists-registry"),
    pytest.param(COHESIVE.replace("Gf = 0.1\n", "Gf = 0.1\nkappa_i = 6.6e-5\n", 1), "identify",
                 ["model.parameters.kappa_i", "6.6e-05", "not a parameter of model.type = 'cohesive-crack'",
                  "CohesiveParameters", "E, nu, ft, Gf, c1, c2"], id="damage-parameter-for-cohesive-model"),
    pytest.param(COHESIVE.replace("ft = 3.0\n", "ft = -3.0\n", 1), "identify",
                 ["model.parameters.ft", "-3.0", "valid range 0 < ft [MPa]"], id="cohesive-ft-negative"),
    pytest.param(COHESIVE.replace("Gf = 0.1\n", "Gf = 0.1\nc1 = 10.0\nc2 = 2.0\n", 1), "identify",
                 ["model.parameters", "c1", "c2", "CohesiveParameters", "area"], id="cohesive-law-without-area"),
    pytest.param(COHESIVE.replace('parameters = ["ft", "Gf"]', 'parameters = ["ft", "beta"]'), "identify",
                 ["identify.parameters", "'beta'", "not a model parameter of model.type = 'cohesive-crack'"],
                 id="damage-parameter-identified-with-cohesive-model"),
    pytest.param(COHESIVE.replace("Gf = [0.04, 0.3]", "Gf = [0.0, 0.3]"), "identify",
                 ["identify.bounds.Gf", "[0.0, 0.3]", "lower bound 0 is outside the valid range 0 < Gf [N/mm]"],
                 id="cohesive-bound-outside-valid-range"),
]


@pytest.mark.parametrize("text, purpose, words", BAD_MODELS)
def test_bad_model_config_is_named(tmp_path, text, purpose, words):
    test_bad_config_is_named(tmp_path, text, purpose, words)


# --------------------------------------------------------------- data formats, limits, warnings

SINGLE = """\
[specimen]
type = "notched-beam"
h_fine = 1.0

[[experiments]]
file = "curve.csv"
control_column = "cmod_mm"
control_unit = "mm"
force_unit = "N"
kind = "single"
force_columns = ["F_N"]
std = 10.0
n_points = 5

[identify]
parameters = ["c"]
bounds = { c = [1.0, 30.0] }
"""


def curve_file(tmp_path, text, name="curve.csv"):
    (tmp_path / name).write_text(text)
    return tmp_path


def ramp(separator=",", decimal=".", n=12):
    """A CSV text cmod_mm, F_N: 0.01 k mm, 100 k + 10 N, written with the given separator and decimal mark."""
    rows = [f"{0.01 * k:.2f}{separator}{100.0 * k + 10.0:.1f}".replace(".", decimal) for k in range(n)]
    return separator.join(["cmod_mm", "F_N"]) + "\n" + "\n".join(rows) + "\n"


@pytest.mark.parametrize("separator, decimal, keys", [
    (";", ",", 'delimiter = ";"\ndecimal = ","'),
    ("\t", ",", 'delimiter = "tab"\ndecimal = ","'),
    ("\t", ".", 'delimiter = "\\t"'),
    (" ", ".", 'delimiter = " "'),
])
def test_delimiter_and_decimal_reach_the_reader(tmp_path, separator, decimal, keys):
    curve_file(tmp_path, ramp(separator, decimal))
    cfg = load_config(write(tmp_path, variant("n_points = 5", "n_points = 5\n" + keys, SINGLE)))
    (exp,) = cfg.experiments
    assert exp.delimiter == separator and exp.decimal == decimal
    data = build_data(cfg)
    np.testing.assert_allclose(data.control, np.linspace(0.0, 0.11, 5))
    np.testing.assert_allclose(data.y, 10000.0 * data.control + 10.0)


def test_a_semicolon_file_read_with_the_default_delimiter_is_named(tmp_path):
    curve_file(tmp_path, "cmod_mm;F_N\n0,001;12,5\n0,002;13,5\n")
    path = write(tmp_path, SINGLE)
    with pytest.raises(ConfigError) as info:
        load_config(path)
    message = str(info.value)
    assert message.startswith(f"{path}: experiments[0].file = 'curve.csv': the header is one cell 'cmod_mm;F_N'")
    assert "the file seems to be separated by ';'" in message and 'set delimiter = ";"' in message
    assert 'decimal = ","' in message and "no such column" not in message
    # the separator right, the decimal mark not: the first data row is named
    with pytest.raises(ConfigError) as info:
        load_config(write(tmp_path, variant("n_points = 5", 'n_points = 5\ndelimiter = ";"', SINGLE)))
    message = str(info.value)
    assert "experiments[0].file = 'curve.csv': the first data row ('0,001', '12,5')" in message
    assert 'set decimal = ","' in message


def test_backtrack_tolerance_is_a_key_in_control_unit(tmp_path):
    """An unloading loop of 30 um: refused by the default tolerance (1 % of the range) with a message
    pointing to the key; dropped as noise with backtrack_tolerance = 50 um (0.05 mm)."""
    control = [0.0, 20.0, 40.0, 60.0, 80.0, 100.0, 70.0, 110.0, 120.0, 140.0, 160.0, 180.0, 200.0]
    curve_file(tmp_path, "u_um,F_N\n" + "".join(f"{u},{10.0 * u + 1.0}\n" for u in control))
    text = SINGLE.replace('"cmod_mm"', '"u_um"').replace('control_unit = "mm"', 'control_unit = "um"')
    cfg = load_config(write(tmp_path, text))
    assert cfg.experiments[0].backtrack_tolerance is None
    with pytest.raises(ConfigError) as info:
        build_data(cfg)
    message = str(info.value)
    assert "experiments[0]" in message and "backwards at row 8" in message
    assert "backtrack_tolerance: the key of [[experiments]]" in message
    for tolerance, ok in ((20, False), (50, True)):
        key = f"n_points = 5\nbacktrack_tolerance = {tolerance}"
        cfg = load_config(write(tmp_path, variant("n_points = 5", key, text)))
        assert cfg.experiments[0].backtrack_tolerance_mm == pytest.approx(tolerance * 1e-3)
        if ok:
            assert build_data(cfg).n_y == 5
        else:
            with pytest.raises(ConfigError, match="backwards at row 8"):
                build_data(cfg)


@pytest.mark.parametrize("forces, words", [
    ([-100.0 * k - 5.0 for k in range(12)], ["the forces are all negative", "negate the column"]),
    ([0.0] * 12, ["all forces are zero"]),
])
def test_negated_or_zero_forces_are_refused(tmp_path, forces, words):
    curve_file(tmp_path, "cmod_mm,F_N\n" + "".join(f"{0.01 * k},{f}\n" for k, f in enumerate(forces)))
    cfg = load_config(write(tmp_path, SINGLE))
    with pytest.raises(ConfigError) as info:
        build_data(cfg)
    message = str(info.value)
    assert "experiments[0]" in message and str(tmp_path / "curve.csv") in message and "column 'F_N'" in message
    for word in words:
        assert word in message


def test_control_in_the_wrong_unit_is_refused(tmp_path):
    """The Gregoire CMOD (mm) declared in um would be fine; the same values scaled by 1000 as if um were mm
    reach 200 mm of CMOD, far past any failure of the beam: refused naming control_unit."""
    raw = np.genfromtxt(datasets.path("gregoire2013-beam4"), delimiter=",", names=True)
    rows = "".join(f"{1000 * c},{f},{lo},{hi}\n" for c, f, lo, hi in
                   zip(raw["cmod_mm"], raw["load_mean_N"], raw["load_min_N"], raw["load_max_N"]))
    path = write(tmp_path, BEAM)
    (tmp_path / "load_cmod.csv").write_text("cmod_mm,load_mean_N,load_min_N,load_max_N\n" + rows)
    with pytest.raises(ConfigError) as info:
        build_data(load_config(path))
    message = str(info.value)
    for word in ("experiments[0].control_unit = 'mm'", "reach 2", "check control_unit", "1000 times too large"):
        assert word in message
    path.write_text(BEAM.replace('control_unit = "mm"', 'control_unit = "um"'))  # the right unit: accepted
    assert build_data(load_config(path)).control.max() == pytest.approx(raw["cmod_mm"].max(), rel=0.05)


def test_warnings(tmp_path):
    assert load_config(CONFIGS / "beam_identify.toml").warnings == ()  # h_fine = 1 mm, c >= 1 mm^2: l >= 1.41 mm
    text = variant("std = 10.0", "relative_std = 5", SINGLE)
    curve_file(tmp_path, ramp())
    cfg = load_config(write(tmp_path, text))
    assert cfg.warnings == ("experiments[0].relative_std = 5 is more than 1, i.e. more than 100 % of the value; "
                            "if you meant 5 %, write 0.05",)
    # elements larger than the internal length l = sqrt(2 c) of the smallest c the study may try
    cfg = load_config(write(tmp_path, variant("h_fine = 2.0", "h_fine = 4.0")))  # c >= 1: l >= 1.41 mm
    (warning,) = cfg.warnings
    assert warning.startswith("specimen.h_fine = 4: the element size h_fine = 4 mm is larger than the internal "
                              "length l = sqrt(2 c) = 1.41 mm (with the lower bound c = 1 mm^2 of identify.bounds.c)")
    assert "use h_fine <= l/2" in warning
    cfg = load_config(write(tmp_path, BAR_SIMULATE.replace('"local-damage"', '"gradient-damage"')
                            .replace("n_elements = 120", "n_elements = 20")), purpose="simulate")
    (warning,) = cfg.warnings  # c = 2: l = 2 mm, elements of 100 / 20 = 5 mm
    assert warning.startswith("specimen.n_elements = 20: the element size length / n_elements = 5 mm is larger than "
                              "the internal length l = sqrt(2 c) = 2 mm (with c = 2 mm^2)")
    assert "use n_elements >= 100" in warning
    # the local model has no internal length: nothing to resolve
    cfg = load_config(write(tmp_path, BAR_SIMULATE.replace("n_elements = 120", "n_elements = 20")), purpose="simulate")
    assert cfg.warnings == ()
    # the PF-CZM's mesh resolves l / 5 (l = 2.5 mm by default: elements of 100 / 200 mm pass, of 100 / 100 not)
    pf_czm = (BAR_SIMULATE.replace('"local-damage"', '"pf-czm"').replace("kappa_i = 1e-4\nc = 2.0\n", "ft = 2.4\n")
              .replace("damage_threshold = 0.1\n", ""))
    assert load_config(write(tmp_path, pf_czm.replace("n_elements = 120", "n_elements = 200")), purpose="simulate").warnings == ()
    (warning,) = load_config(write(tmp_path, pf_czm.replace("n_elements = 120", "n_elements = 100")),
                             purpose="simulate").warnings
    assert warning.startswith("specimen.n_elements = 100: the element size length / n_elements = 1 mm is larger than "
                              "l / 5 (a fifth of the length scale) = 0.5 mm (with l = 2.5 mm (default)): the phase "
                              "field's band is not resolved"), warning
    assert warning.endswith("make the elements where the crack runs 0.5 mm or smaller")


def test_mesh_size_is_counted_without_building_the_mesh():
    from fracid.specimens.dogbone import DogBone

    for specimen in (NotchedBeam(h_fine=2.0), NotchedBeam(notch_width=8.0, plate_width=3.0), NotchedBeam(span=175.0),
                     DogBone(), DogBone(size=200.0, platens="hinged", hinge_offset=5.0)):
        mesh = specimen.mesh()
        assert specimen.mesh_size() == (len(mesh.cells), len(mesh.nodes), mesh.n_vertices)


LIMITS = [
    pytest.param(variant("n = 64", "n = 1000000000"), "identify",
                 ["identify.knn.n", "1000000000", "population of 1,000,000,000 points", "limit of 100,000",
                  "one forward run", "320 GiB"], id="population"),
    pytest.param(variant("n = 64\nmethod = \"sobol\"", "n = 100\nmethod = \"grid\""), "identify",
                 ["identify.knn.n", "100", "1,000,000 points (n**p = 100**3", "limit of 100,000"],
                 id="grid-population"),
    pytest.param(BAR_SIMULATE.replace("n_elements = 120", "n_elements = 100000000"), "simulate",
                 ["specimen.n_elements", "100000000", "373 GiB", "at most 200,000 elements"], id="bar-elements"),
    pytest.param(variant("h_fine = 2.0", "h_fine = 0.01"), "identify",
                 ["specimen.h_fine = 0.01", "2,643,904 elements", "18,525,256 unknowns", "at most 2,000,000 unknowns",
                  "GiB"], id="beam-h_fine"),
    pytest.param(variant("n_points = 40", "n_points = 40\nspecimen = { h_fine = 0.02 }"), "identify",
                 ["experiments[0].specimen.h_fine = 0.02", "unknowns", "at most 2,000,000"], id="override-h_fine"),
    pytest.param('[specimen]\ntype = "dogbone"\n[[experiments]]\nfile = "load_cmod.csv"\n'
                 'control_column = "cmod_mm"\ncontrol_unit = "mm"\nforce_unit = "N"\nkind = "single"\n'
                 'force_columns = ["load_mean_N"]\nstd = 10.0\nn_points = 10\nspecimen = { size = 10000.0 }\n',
                 "simulate",
                 ["specimen.h_fine = 2 (default) with experiments[0].specimen = {size = 10000.0}", "3,001,428 unknowns",
                  "at most 2,000,000"], id="override-size"),
    pytest.param(variant("n_points = 40", 'n_points = 40\ndecimal = ","'), "identify",
                 ["experiments[0].decimal", "','", 'delimiter = ","', 'set delimiter = ";"'],
                 id="decimal-comma-with-comma"),
    pytest.param(variant("n_points = 40", 'n_points = 40\ndelimiter = "|"'), "identify",
                 ["experiments[0].delimiter", "'|'", '",", ";", "\\t" (or "tab"), " "'], id="unknown-delimiter"),
    pytest.param(variant("n_points = 40", "n_points = 40\nbacktrack_tolerance = -0.1"), "identify",
                 ["experiments[0].backtrack_tolerance", "-0.1", ">= 0 [mm]"], id="negative-backtrack-tolerance"),
]


@pytest.mark.parametrize("text, purpose, words", LIMITS)
def test_limits_and_formats_are_named(tmp_path, text, purpose, words):
    test_bad_config_is_named(tmp_path, text, purpose, words)


def test_data_values_are_not_capped_over_the_calibration_blocks(tmp_path):
    """No cap on n_y (the data covariance is not an n x n matrix): each block and the sum are accepted;
    a prediction block is not stacked with the calibration blocks."""
    block = BEAM[BEAM.index("[[experiments]]"):BEAM.index("[identify]")]
    two = variant("n_points = 40", "n_points = 3000", BEAM.replace("[identify]", block + "[identify]", 1))
    assert load_config(write(tmp_path, two)).n_y == 3040
    assert load_config(write(tmp_path, two.replace("n_points = 40", "n_points = 50000"))).n_y == 53000
    predicted = two.replace("n_points = 40", 'n_points = 2001\nrole = "prediction"')
    assert load_config(write(tmp_path, predicted)).n_y == 3000


@pytest.mark.slow
def test_beam_supported_at_its_ends():
    """S = L is a valid beam: supports at the end nodes; longer span, softer beam (elastic run)."""
    import fracid

    params = fracid.DamageParameters(E=37000.0, kappa_i=1e-3)
    ends, usual = (NotchedBeam(span=span, length=175.0, h_fine=5.0) for span in (175.0, 125.0))
    mesh = ends.mesh()
    assert mesh.nodes[:, 0].max() == pytest.approx(87.5)  # nothing meshed beyond the end
    fixed = np.asarray(conditions(ends.describe(mesh)).fixed_dofs)
    support = mesh.nodes[fixed[fixed % 2 == 1] // 2]
    assert np.all(support[:, 1] == 0.0) and support[:, 0].min() == pytest.approx(85.0)
    assert support[:, 0].max() == pytest.approx(87.5)  # the end node holds the beam
    runs = [fracid.simulate(b, params, target=0.002, stop_force_fraction=None) for b in (ends, usual)]
    for run in runs:  # elastic: force proportional to the CMOD
        assert run.force[-1] / run.control[-1] == pytest.approx(run.force[1] / run.control[1], rel=1e-6)
    k_ends, k_usual = (run.force[-1] / run.control[-1] for run in runs)
    # CMOD grows with the bending moment F S / 4: F / CMOD about in the ratio of the spans 125 / 175 = 0.71
    assert 0.6 < k_ends / k_usual < 0.75
    # the deflection grows faster than the span (bending ~ S^3, shear ~ S)
    c_ends, c_usual = (run.observables["deflection"][-1] / run.force[-1] for run in runs)
    assert 175.0 / 125.0 < c_ends / c_usual < (175.0 / 125.0) ** 3
    with pytest.raises(ValueError, match="span = 176.0 must not exceed length = 175.0"):
        NotchedBeam(span=176.0)
