"""The written contracts: every registered specimen meets :class:`fracid.specimens.protocol.Specimen`
and every registered model :class:`fracid.models.ForwardModel`; the configuration asks the specimen
(no branch on its type name), so a specimen of a test file registered in SPECIMENS runs through
``fracid simulate``; errors are classified by type; the data size is not capped."""

import dataclasses
import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np
import pytest

from fracid import cli
from fracid.config import ConfigError, load_config
from fracid.config.sections import specimen_error_key
from fracid.fem.material.laws import HordijkLaw
from fracid.fem.path.path_following import StepOptions
from fracid.settings.field_error import FieldError
from fracid.models import (MODEL_TYPES, CohesiveCrackModel, CrackBandModel, DamageModel, ForwardModel, declared,
                           runs_on)
from fracid.specimens import SPECIMENS, BarWithWeakZone, MeshSpecimen, NotchedBeam, TensionStrip
from fracid.specimens.description import Description
from fracid.specimens.mesh import write_gmsh
from fracid.specimens.protocol import Resolution, SizeEstimate, Specimen, SpecimenDefaults
from test_extension import EdgeNotchedPlate

SCALES = {"strain": 1e-4, "opening": 0.1}
BEAM = NotchedBeam(h_fine=5.0, h_coarse=10.0)


def _beam_mesh(tmp_path) -> MeshSpecimen:
    """The half beam written as a Gmsh file and read back as the user's own mesh."""
    path = tmp_path / "beam.msh"
    write_gmsh(BEAM.describe(), path)
    return MeshSpecimen(str(path), thickness=50.0, supports=(("support", "y"),),
                        loads=(("loading_plate", "y", True, -0.5),), controls=(("cmod", (("mouth", "x", 2.0),)),),
                        symmetry=(("ligament", "x"),), symmetry_factor=2.0, crack=("ligament", "x"))


@pytest.fixture(params=sorted(SPECIMENS))
def specimen(request, tmp_path):
    made = SPECIMENS[request.param].default_instance()
    return made if made is not None else _beam_mesh(tmp_path)


def test_the_registry_holds_every_specimen():
    assert {"notched-beam", "dogbone", "bar", "wedge-splitting", "strip", "mesh"} <= set(SPECIMENS)
    assert SPECIMENS["strip"] is TensionStrip and SPECIMENS["mesh"] is MeshSpecimen


def test_every_registered_specimen_meets_the_protocol(specimen):
    assert isinstance(specimen, Specimen)
    names = specimen.control_names
    assert isinstance(names, tuple) and names and all(isinstance(n, str) for n in names)
    assert specimen.default_control == names[0]
    description = specimen.describe()
    assert isinstance(description, Description) and set(names) <= set(description.functionals)
    assert isinstance(specimen.observables, tuple) and all(isinstance(n, str) for n in specimen.observables)
    # the observables are what a damage model records on it
    assert set(DamageModel().observers(description, DamageModel().parameters())) == set(specimen.observables)
    try:
        target = specimen.default_target(SCALES)
        assert isinstance(target, float) and target > 0
    except ValueError as err:  # the mesh: no default target, and the message says to give one
        assert "target" in str(err)
    assert isinstance(specimen.default_steps(0.3), StepOptions)
    assert isinstance(specimen.options_text({}), str)
    assert specimen.size_field is None or specimen.size_field in {f.name for f in dataclasses.fields(specimen)}
    resolution, size = specimen.resolution(1.0), specimen.size_estimate()
    assert isinstance(resolution, Resolution) and resolution.h > 0 and isinstance(resolution.advice, str)
    assert isinstance(size, SizeEstimate) and isinstance(size.count, int) and 0 < size.count <= size.limit
    assert size.unit in ("element", "unknown") and size.memory == size.count * size.bytes_per


def test_size_field_scales_the_specimen(specimen):
    if specimen.size_field is None:
        return
    value = getattr(specimen, specimen.size_field)
    bigger = dataclasses.replace(specimen, **{specimen.size_field: 2.0 * value})
    assert bigger.characteristic_size == pytest.approx(2.0 * specimen.characteristic_size)


def test_the_size_estimate_counts_the_mesh_exactly(tmp_path):
    """The unknowns estimated without building the mesh are those of the built one (2 per node + 1 per vertex)."""
    for specimen in (BEAM, TensionStrip(n_elements=11), _beam_mesh(tmp_path)):
        d = specimen.describe()
        assert specimen.size_estimate().count == 2 * len(d.nodes) + d.n_vertices, type(specimen).__name__
    bar = BarWithWeakZone(n_elements=40)
    assert bar.size_estimate().count == len(bar.describe().cells) == 40


def test_resolutions_are_the_element_sizes(tmp_path):
    bar = BarWithWeakZone(length=100.0, n_elements=50)
    r = bar.resolution(internal_length=1.0)
    assert (r.field, r.value, r.h) == ("n_elements", 50, 2.0) and "n_elements >= 200" in r.advice  # 2 L / l
    assert "beyond the limit" in bar.resolution(internal_length=1e-4).advice
    assert BEAM.resolution().field == "h_fine" and BEAM.resolution().h == 5.0
    mesh = _beam_mesh(tmp_path)
    r = mesh.resolution()
    assert r.field == "file" and r.value == mesh.path
    # the smallest corner-to-corner side of the quadrilaterals
    corners = mesh.describe().nodes[mesh.describe().corners]
    assert r.h == pytest.approx(np.linalg.norm(corners - np.roll(corners, -1, axis=1), axis=-1).min())


# ---- a specimen of this file, registered for the configuration


@dataclass(frozen=True)
class RegisteredPlate(SpecimenDefaults, EdgeNotchedPlate):
    """The edge-notched plate of tests/test_extension.py with what the protocol adds."""

    controls: ClassVar[tuple] = ("cmod", "grip_displacement")
    observables: ClassVar[tuple] = ("fpz_width",)
    size_field: ClassVar[str] = "width"


def test_a_specimen_of_a_test_file_is_named_in_a_configuration_and_simulated(tmp_path, monkeypatch, capsys):
    monkeypatch.setitem(SPECIMENS, "edge-plate", RegisteredPlate)
    assert isinstance(RegisteredPlate(), Specimen)
    path = tmp_path / "plate.toml"
    path.write_text('[model]\ntype = "gradient-damage"\n[specimen]\ntype = "edge-plate"\nh = 8.0\n'
                    'control = "grip_displacement"\n[simulate]\ntarget = 0.004\n')
    cfg = load_config(path, purpose="simulate")
    assert cfg.specimen.type == "edge-plate" and dict(cfg.specimen.options) == {"h": 8.0}
    assert cli.main(["simulate", str(path), "--quiet", "--out", str(tmp_path / "out")]) == 0
    rows = (tmp_path / "out" / "curve.csv").read_text().splitlines()
    assert len(rows) > 3
    # a control it does not have is refused with its own names
    path.write_text(path.read_text().replace('"grip_displacement"', '"cmod2"'))
    with pytest.raises(ConfigError, match=r"specimen.control.*'cmod2'.*'cmod', 'grip_displacement'"):
        load_config(path, purpose="simulate")


def test_the_tension_strip_is_configured_like_the_others(tmp_path):
    path = tmp_path / "strip.toml"
    path.write_text('[model]\ntype = "crack-band"\n[specimen]\ntype = "strip"\nn_elements = 11\n')
    cfg = load_config(path, purpose="simulate")
    assert cfg.specimen.control == "band_opening"
    path.write_text(path.read_text().replace("n_elements = 11", "n_elements = 10"))
    with pytest.raises(ConfigError, match=r"specimen.n_elements = 10: .*odd integer"):
        load_config(path, purpose="simulate")
    path.write_text('[model]\ntype = "cohesive-crack"\n[specimen]\ntype = "strip"\n')
    with pytest.raises(ConfigError, match=r"specimen.type.*does not run on it \(the specimen has no crack path"):
        load_config(path, purpose="simulate")


# ---- errors classified by type


def test_a_field_error_is_classified_by_its_names_not_its_message():
    err = FieldError(("notch_depth", "depth"), 60.0, "a message that names no field at all")
    fields = {"depth": None, "notch_depth": None}
    assert specimen_error_key(err, fields, {"depth": 40.0}) == "depth"  # the one given first
    assert specimen_error_key(err, fields, {}) == "notch_depth"
    # another package's ValueError: the field names in its message, as a fallback
    assert specimen_error_key(ValueError("depth = 3 is too small"), fields, {}) == "depth"
    with pytest.raises(FieldError) as info:
        NotchedBeam(notch_depth=60.0)
    assert info.value.names == ("notch_depth", "depth") and info.value.value == 60.0


# ---- forward models


@pytest.mark.parametrize("kind", sorted(MODEL_TYPES))
def test_every_registered_model_declares_its_capabilities(kind):
    model = MODEL_TYPES[kind]()
    assert isinstance(model, ForwardModel) and declared(model) is model
    assert set(model.differentiable) <= set(model.parameters.names())
    assert isinstance(model.differentiates_observers, bool) and isinstance(model.observer_names, tuple)
    assert model.regularization in (None, "gradient", "local", "integral")
    assert isinstance(model.scales(model.parameters()), dict)
    assert model.runs_on(BEAM) and model.why_not(BEAM) is None


@dataclass(frozen=True)
class OtherLaw(HordijkLaw):
    name: ClassVar[str] = "other-law"


def test_crack_model_keys_name_their_law():
    assert CohesiveCrackModel().key == "cohesive-crack-hordijk" and CrackBandModel().key == "crack-band-hordijk"
    assert CohesiveCrackModel(law=OtherLaw()).key == "cohesive-crack-other-law"
    assert CrackBandModel(law=OtherLaw(), band_width=2.0).key == "crack-band-other-law-band-2"


def test_a_model_of_a_few_lines_gets_the_default_capabilities():
    @dataclass(frozen=True)
    class Minimal:
        key: ClassVar[str] = "minimal"
        parameters: ClassVar[type] = dict

        def simulate(self, specimen, params, **options):
            return "ran"

    model = declared(Minimal())
    assert not isinstance(Minimal(), ForwardModel) and isinstance(model, ForwardModel)
    assert (model.key, model.differentiable, model.differentiates_observers, model.observer_names,
            model.regularization) == ("minimal", (), False, (), None)
    assert model.simulate(None, None) == "ran" and runs_on(Minimal(), BEAM)
    with pytest.raises(TypeError, match="lacks key, parameters, simulate"):
        declared(object())


def test_simulate_reads_whether_a_model_needs_a_described_specimen():
    """``needs_description`` is declared (ModelDefaults: False; the built-in models: True), not guessed from the
    model's class: a model of a few lines takes any specimen object, one that declares it refuses a foreign one."""
    from fracid.models.forward import simulate

    @dataclass(frozen=True)
    class Minimal:
        key: ClassVar[str] = "minimal"
        parameters: ClassVar[type] = dict

        def simulate(self, specimen, params, **options):
            return ("ran", specimen)

    @dataclass(frozen=True)
    class Describing(Minimal):
        needs_description: ClassVar[bool] = True

    foreign = object()  # neither describe() nor a Description
    assert declared(Minimal()).needs_description is False and all(MODEL_TYPES[k]().needs_description
                                                                   for k in MODEL_TYPES)
    assert simulate(foreign, {}, model=Minimal()) == ("ran", foreign)
    with pytest.raises(TypeError, match="specimen is a object; give a specimen object"):
        simulate(foreign, {}, model=Describing())
    assert simulate(BEAM, {}, model=Describing()) == ("ran", BEAM)
    description = BarWithWeakZone(n_elements=10).describe()
    assert simulate(description, {}, model=Describing()) == ("ran", description)


def test_refined_is_the_specimens_declared_member():
    """``refined(specimen, factor)`` asks the specimen (no probe): SpecimenDefaults' field rule, or its own."""
    from fracid.specimens.protocol import refined

    @dataclass(frozen=True)
    class OwnRefinement(SpecimenDefaults):
        h: float = 4.0

        def refined(self, factor):
            return dataclasses.replace(self, h=self.h / factor**2)  # not the field rule: its own

    assert all(callable(kind.refined) for kind in SPECIMENS.values())
    assert refined(OwnRefinement(), 2.0) == OwnRefinement(h=1.0)
    assert refined(TensionStrip(n_elements=21), 3.0).n_elements == 63
    with pytest.raises(ValueError, match="no field sets its element size"):
        _NoField().refined(2.0)


class _NoField(SpecimenDefaults):
    """A specimen whose mesh no field sizes."""

    def resolution(self, internal_length=None):
        return Resolution(None, None, 1.0, "its smallest element side, 1 mm,", "")


def test_usual_ranges_and_units_are_read_from_the_declared_parameter_class():
    from fracid.fem.material.parameters import DamageParameters
    from fracid.models import parameter_units, usual_ranges

    assert usual_ranges(DamageParameters) == dict(DamageParameters.usual_ranges) and "kappa_i" in usual_ranges()
    assert parameter_units(DamageModel("local"))["c"] == "mm^2"
    with pytest.raises(TypeError, match="lacks key, parameters, simulate"):
        parameter_units(object())


# ---- no cap on the data size


def test_the_number_of_data_values_is_not_capped(tmp_path):
    u = np.linspace(0.0, 0.3, 200)
    (tmp_path / "d.csv").write_text("u,F\n" + "\n".join(f"{a},{1000 * math.sin(10 * a) + 1}" for a in u))
    block = ('[[experiments]]\nfile = "d.csv"\ncontrol_column = "u"\ncontrol_unit = "mm"\nforce_unit = "N"\n'
             'kind = "single"\nforce_columns = ["F"]\nrelative_std = 0.02\nn_points = 60000\n')
    path = tmp_path / "big.toml"
    path.write_text('[specimen]\ntype = "bar"\nn_elements = 40\n' + block + block.replace("60000", "50000"))
    assert load_config(path, purpose="simulate").n_y == 110_000
