"""Direct differentiation (fracid.fem.path.ddm) of the crack models' paths: the cohesive crack and the crack band.

The DDM derivatives of the recorded force and energies are compared with central differences of runs
(relative step 1e-6 per parameter) at the same control values, checkpoints covering the rise, the peak
and the softening. Every run uses the same step sequence: one step per checkpoint (``initial =
target / N``, no smaller first step after the onset, no growth beyond the initial step, no jump to the
onset), so the differences do not see the steps move with the parameters. Where Newton fails (the
cohesive crack on the coarse beam), the shrunk increments between two checkpoints are the same in
every run too (checked).

What unloads: the bulk of the cohesive crack is elastic, and interface points behind the tip do not
unload under monotonic opening; but on these coarse meshes the quadratic opening over the edge that
holds the tip is not monotonic, so a few cracked Gauss points near the tip close again (secant
unloading, some back below the penalty opening w0), which carries the history derivative through the
path. In the crack band on the notched beam no cracked element unloads (the band along the ligament
keeps opening; only the elastic bulk and the uncrackable elements unload). The unloading branch of both
formulations is checked separately by the pseudo-load at states whose history is ahead of the
displacements.
"""

from types import SimpleNamespace

import numpy as np
import pytest

from fracid.fem.material.cohesive import CohesiveParameters
from fracid.models import CohesiveCrackModel, CrackBandModel, StepOptions
from fracid.specimens import SPECIMENS

pytestmark = pytest.mark.slow  # the fast loop (-m "not slow") leaves this module out

PARAMS = CohesiveParameters()
NAMES = PARAMS.names()  # E, nu, ft, Gf, c1, c2
REL_STEP = 1e-6
TOL = 1e-4


def _beam():
    return SPECIMENS["notched-beam"](h_fine=4.0, h_coarse=12.0, fine_width=12)


def _dogbone():
    return SPECIMENS["dogbone"](size=50.0, h_fine=4.0)


# case -> (model, specimen, number of checkpoints, target as a fraction of the model's default)
CASES = {
    "cohesive-beam": (CohesiveCrackModel(), _beam, 20, 0.5),
    "cohesive-dogbone": (CohesiveCrackModel(), _dogbone, 40, 0.4),
    "crack-band-beam": (CrackBandModel(), _beam, 20, 0.5),
}


def _options(target, n):
    checkpoints = np.linspace(0.0, target, n + 1)[1:]
    steps = StepOptions(initial=target / n, onset_fraction=1.0, max_factor=1.0, jump_to_onset=False)
    return checkpoints, dict(target=target, steps=steps, checkpoints=checkpoints, stop_force_fraction=None)


@pytest.fixture(scope="module", params=sorted(CASES))
def case(request):
    model, make, n, fraction = CASES[request.param]
    specimen = make()
    target = fraction * model.default_target(specimen, PARAMS)  # held in every run (it depends on ft / E and wc)
    checkpoints, options = _options(target, n)
    run = model.simulate(specimen, PARAMS, sensitivities=NAMES, field_steps="all", **options)
    rows = np.array([int(np.argmin(np.abs(run.control - c))) for c in checkpoints])
    assert np.allclose(run.control[rows], checkpoints, rtol=1e-12)
    quantities = ("force", "external_work", "elastic_energy")
    differences = {}
    for name in NAMES:
        value = getattr(PARAMS, name)
        step = REL_STEP * value
        plus, minus = (model.simulate(specimen, PARAMS.replace(**{name: value + sign * step}), field_steps=None,
                                      **options) for sign in (1.0, -1.0))
        for other in (plus, minus):  # the same steps, or the differences would see them move
            assert other.control.shape == run.control.shape and np.array_equal(other.control, run.control), name
        differences[name] = {q: (_curve(plus, q)[rows] - _curve(minus, q)[rows]) / (2.0 * step) for q in quantities}
    return SimpleNamespace(name=request.param, model=model, specimen=specimen, run=run, rows=rows,
                           differences=differences)


def _curve(run, quantity):
    return run.force if quantity == "force" else run.observables[quantity]


def _relative_errors(case, quantity):
    errors = {}
    for k, name in enumerate(NAMES):
        ddm = case.run.derivatives[quantity][case.rows, k]
        fd = case.differences[name][quantity]
        scale = np.max(np.abs(fd))
        assert scale > 0.0, (name, quantity)  # every parameter moves every case's curves
        errors[name] = float(np.max(np.abs(ddm - fd)) / scale)
    return errors


def test_the_checkpoints_cover_the_rise_the_peak_and_the_softening(case):
    force = case.run.force[case.rows]
    peak = int(np.argmax(force))
    assert 2 <= peak < len(force) - 5  # points before the peak, at it and well after it
    assert force[-1] < 0.75 * force[peak]


def test_force_derivatives_match_central_differences(case):
    assert case.run.derivatives["names"] == NAMES
    assert case.run.derivatives["force"].shape == (case.run.n_steps + 1, len(NAMES))
    errors = _relative_errors(case, "force")
    print(f"\n{case.name} force: " + ", ".join(f"{n} {e:.1e}" for n, e in errors.items()))
    assert max(errors.values()) <= TOL, errors


@pytest.mark.parametrize("quantity", ["external_work", "elastic_energy"])
def test_energy_derivatives_match_central_differences(case, quantity):
    errors = _relative_errors(case, quantity)
    print(f"\n{case.name} {quantity}: " + ", ".join(f"{n} {e:.1e}" for n, e in errors.items()))
    assert max(errors.values()) <= TOL, errors


def test_cracked_points_near_the_tip_of_the_coarse_cohesive_crack_unload(case):
    """The path exercises the history derivative of the secant branch (see the module docstring)."""
    if case.name != "cohesive-beam":
        pytest.skip("the cohesive crack on the notched beam")
    problem = case.model.build(case.specimen, PARAMS)
    w0 = PARAMS.ft / problem.penalty
    unloading = 0
    for step in range(2, case.run.n_steps + 1):
        w = problem.openings(problem.restrict(case.run.fields[step]["u"]))
        w_max_old = case.run.fields[step - 1]["crack_opening_max"]
        unloading += int(np.sum((w_max_old > w0) & (w < w_max_old)))
    assert unloading > 0


# the unloading branch, step by step: at a state whose history is ahead of the displacements


def _history(problem, fields):
    return fields["crack_opening_max"] if "crack_opening_max" in fields else fields["kappa"]


@pytest.mark.parametrize("unloading", [True, False])
def test_pseudo_load_and_completion_match_finite_differences_at_fixed_displacements(case, unloading):
    """d r / d x at fixed q with a history that moves with the parameters (the carried derivative), and
    the completed history and energy derivatives for a given q', against differences of the problem's
    own evaluation. ``unloading``: the displacements of an early step with the (slightly raised)
    history of a later one, so that every cracked point unloads; else the displacements of the later
    step with the history of the early one (the opening points load)."""
    model, specimen, run = case.model, case.specimen, case.run
    early, late = run.fields[len(run.control) // 4], run.fields[run.n_steps]
    problem = model.build(specimen, PARAMS)
    q_early, q_late = problem.restrict(early["u"]), problem.restrict(late["u"])
    if unloading:  # raised by 1e-3: no point on the kink w = w_max within the differences' steps
        q, history = q_early, 1.001 * _history(problem, late)
    else:
        q, history = q_late, _history(problem, early)
    rng = np.random.default_rng(3)
    per_unit = np.array([getattr(PARAMS, name) for name in NAMES])
    shape = history.shape[:1] + (1,) if case.name == "crack-band-beam" else history.shape  # one kappa per element
    history_rate = history[..., None] * rng.uniform(0.5, 1.5, shape + (len(NAMES),)) / per_unit
    # smooth displacement rates (mixtures of the two states), not to cross the kinks either
    a, b = rng.uniform(0.5, 1.5, (2, len(NAMES)))
    dq = (q_early[:, None] * a + q_late[:, None] * b) / per_unit
    derivative = problem.differentiate(q, history, history_rate, NAMES)
    rate, energy = derivative.complete(dq)
    if unloading:  # the carried history derivative enters the pseudo-load
        without = problem.differentiate(q, history, np.zeros_like(history_rate), NAMES).pseudo_load
        assert np.max(np.abs(derivative.pseudo_load - without)) > 0.01 * np.max(np.abs(derivative.pseudo_load))
    for k, name in enumerate(NAMES):
        value, step = getattr(PARAMS, name), REL_STEP * getattr(PARAMS, name)
        results = []
        for sign in (1.0, -1.0):
            shifted = model.build(specimen, PARAMS.replace(**{name: value + sign * step}))
            q_k = q + sign * step * dq[:, k]
            h_k = history + sign * step * history_rate[..., k]
            residual, _, _ = shifted.evaluate(q, h_k)
            _, arrays, _ = shifted.evaluate(q_k, h_k)
            results.append((residual, arrays.history, shifted.elastic_energy(q_k, arrays.history, arrays)))
        (r_plus, k_plus, e_plus), (r_minus, k_minus, e_minus) = results
        fd_load = (r_plus - r_minus) / (2.0 * step)
        fd_rate = (k_plus - k_minus) / (2.0 * step)
        fd_energy = (e_plus - e_minus) / (2.0 * step)
        assert np.max(np.abs(derivative.pseudo_load[:, k] - fd_load)) <= 1e-5 * np.max(np.abs(fd_load)), name
        assert np.max(np.abs(rate[..., k] - fd_rate)) <= 1e-5 * np.max(np.abs(fd_rate)), name
        assert abs(energy[k] - fd_energy) <= 1e-5 * abs(fd_energy), name


@pytest.mark.parametrize("model", [CohesiveCrackModel(), CrackBandModel()], ids=["cohesive", "crack-band"])
def test_the_problems_declare_their_parameters_and_refuse_others(model):
    problem = model.build(_beam(), PARAMS)
    assert problem.differentiable == NAMES
    history = problem.initial_history()
    with pytest.raises(ValueError, match="kappa_i"):
        problem.differentiate(np.zeros(problem.n_free), history, np.zeros(history.shape + (2,)), ["E", "kappa_i"])
