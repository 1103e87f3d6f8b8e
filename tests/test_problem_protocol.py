"""The problem protocol the solver relies on: every model's problem implements it, keeps no state
between calls, and each named field gets its own tolerance."""

import numpy as np
import pytest

import fracid
from fracid.fem.material.cohesive import CohesiveParameters
from fracid.fem.formulations.protocol import Problem, allocate_history, initial_history
from fracid.models import MODEL_TYPES, model_from_type, runs_on
from fracid.specimens import DogBone, NotchedBeam

BEAM = NotchedBeam(h_fine=5.0, h_coarse=10.0)


@pytest.mark.parametrize("kind", sorted(MODEL_TYPES))
def test_every_problem_implements_the_protocol(kind):
    model = model_from_type(kind)
    params = model.parameters()
    problem = model.build(BEAM, params)
    assert isinstance(problem, Problem)
    assert set(problem.functionals) == {"cmod", "deflection"} and problem.load_vector.shape == (problem.n_free,)
    assert set(problem.blocks) <= {"u", "ebar", "d"} and problem.element_dofs.max() < problem.n_free
    # its declared history is the layout of the history the path starts from
    assert np.shape(allocate_history(problem.history_spec, problem.disc)) == np.shape(initial_history(problem))


def test_the_cohesive_problem_keeps_no_state_between_calls():
    """Its energy depends on the history it is given, not on the last evaluation (call order)."""
    params = CohesiveParameters(E=30000.0, ft=3.0, Gf=0.08)
    model = model_from_type("cohesive-crack")
    run = model.simulate(BEAM, params, target=0.05, stop_force_fraction=None, field_steps="all")
    problem = model.build(BEAM, params)
    step = run.n_steps
    q = problem.restrict(run.fields[step]["u"])
    w_max = run.fields[step]["crack_opening_max"]
    omega = np.zeros(problem.disc.weights.shape)
    before = problem.elastic_energy(q, w_max, omega)
    problem.evaluate(np.zeros_like(q), problem.initial_history())  # an unrelated evaluation in between
    assert problem.elastic_energy(q, w_max, omega) == before
    assert before == pytest.approx(run.observables["elastic_energy"][-1], rel=1e-12)


def test_tolerances_per_named_field():
    options = fracid.NewtonOptions(rtol_u=1e-9, field_rtol={"crack": 1e-6, "ebar": 1e-7})
    assert options.tolerance("u") == 1e-9 and options.tolerance("ebar") == 1e-7 and options.tolerance("crack") == 1e-6
    assert options.tolerance("other") == 1e-9  # a field named nowhere gets rtol_u
    with pytest.raises(ValueError, match=r"field_rtol\['crack'\]"):
        fracid.NewtonOptions(field_rtol={"crack": 0.0})


def test_the_removed_ebar_tolerance_names_its_replacement():
    with pytest.raises(TypeError, match=r"rtol_ebar.*removed.*field_rtol=\{'ebar': 1e-06\}"):
        fracid.NewtonOptions(rtol_ebar=1e-6)


def test_a_model_that_does_not_run_on_a_specimen_says_why():
    dogbone = DogBone(size=50.0, h_fine=5.0)
    assert runs_on(model_from_type("cohesive-crack"), dogbone)
    with pytest.raises(TypeError, match="plane-stress model"):
        model_from_type("crack-band").simulate(fracid.BarWithWeakZone(n_elements=20), CohesiveParameters())
