"""Direct differentiation (DDM) of the continuum damage models equals central differences of runs.

The paths are traced with a step sequence that does not depend on the parameters (every step lands
on a checkpoint), so that the central differences (relative step 1e-6) see the same discrete path
as the derivative: the adaptive step rule would otherwise move the steps with the parameters and
add that change (of the order of the step) to the differences. Points before the peak, at the peak,
in softening, points that unload and a snap-back under indirect control are all in these paths.
"""

import numpy as np
import pytest

import fracid
from fracid.specimens import SPECIMENS
from fracid.fem.material.damage import exponential_damage, exponential_damage_parameter_derivatives
from fracid.fem.material.elasticity import plane_stress_matrix, plane_stress_matrix_derivative
from fracid.fem.material.equivalent_strain import (modified_von_mises_plane_stress,
                                          modified_von_mises_plane_stress_parameter_derivatives,
                                          modified_von_mises_uniaxial, modified_von_mises_uniaxial_parameter_derivatives)
from fracid.fem.formulations.nonlocal_average import averaging_length_derivative, averaging_matrix
from fracid.models import DamageModel, StepOptions

RELATIVE_STEP = 1e-6


def central(f, value, h):
    return (f(value + h) - f(value - h)) / (2 * h)


def test_law_parameter_derivatives_equal_central_differences():
    rng = np.random.default_rng(1)
    strain = rng.normal(size=(40, 3)) * 1e-4
    for nu, eta in [(0.2, 10.0), (0.3, 1.0)]:
        d = modified_von_mises_plane_stress_parameter_derivatives(strain, nu, eta)
        fd_nu = central(lambda v: modified_von_mises_plane_stress(strain, v, eta)[0], nu, 1e-7)
        fd_eta = central(lambda v: modified_von_mises_plane_stress(strain, nu, v)[0], eta, 1e-6)
        np.testing.assert_allclose(d["nu"], fd_nu, atol=1e-6 * np.abs(fd_nu).max())
        np.testing.assert_allclose(d["eta"], fd_eta, atol=1e-6 * np.abs(fd_eta).max())
    axial = rng.normal(size=(30, 1)) * 1e-4
    d = modified_von_mises_uniaxial_parameter_derivatives(axial, 0.2, 8.0)
    fd = central(lambda v: modified_von_mises_uniaxial(axial, 0.2, v)[0], 8.0, 1e-6)
    np.testing.assert_allclose(d["eta"], fd, atol=1e-8 * np.abs(fd).max())
    assert np.all(d["nu"] == 0.0)
    kappa = np.linspace(1.02e-4, 3e-3, 50)
    params = {"kappa_i": 1e-4, "alpha": 0.95, "beta": 300.0}
    d = exponential_damage_parameter_derivatives(kappa, **params)
    for name in params:
        h = RELATIVE_STEP * params[name]
        fd = central(lambda v: exponential_damage(kappa, **{**params, name: v})[0], params[name], h)
        np.testing.assert_allclose(d[name], fd, atol=1e-6 * np.abs(fd).max())
    assert np.all(exponential_damage_parameter_derivatives(np.array([5e-5]), **params)["alpha"] == 0.0)
    fd = central(plane_stress_matrix, 0.23, 1e-7)
    np.testing.assert_allclose(plane_stress_matrix_derivative(0.23), fd, atol=1e-7)
    points, weights = rng.random((150, 2)) * 10, rng.random(150) + 0.5
    fd = central(lambda l: averaging_matrix(points, weights, l, mirror=[(0, 0.0)]).toarray(), 1.3, 1e-6)
    exact = averaging_length_derivative(points, weights, 1.3, mirror=[(0, 0.0)]).toarray()
    np.testing.assert_allclose(exact, fd, atol=1e-7 * np.abs(fd).max())


def fixed_steps_run(model, specimen, params, n, control=None, target=None, names=None):
    """A path whose steps are the checkpoints (n of them evenly spaced up to ``target``, or the array
    ``n``): the steps then do not depend on the parameters (the rule cuts a step that fails, as
    it would in the runs of central differences)."""
    target = target if target is not None else model.default_target(specimen, params)
    checkpoints = np.linspace(0.0, target, n + 1)[1:] if np.ndim(n) == 0 else np.asarray(n)
    target = float(checkpoints[-1])
    spacing = float(np.diff(checkpoints, prepend=0.0).max())
    result = model.simulate(specimen, params, control=control, target=target, stop_force_fraction=None,
                            checkpoints=checkpoints, field_steps="last",
                            steps=StepOptions(initial=spacing, onset_fraction=1.0, max_factor=1.0, jump_to_onset=False),
                            sensitivities=names)
    rows = np.array([np.argmin(np.abs(result.control - c)) for c in checkpoints])
    np.testing.assert_allclose(result.control[rows], checkpoints, rtol=1e-12)  # every checkpoint is a step
    return result, rows


def compare(model, specimen, params, names, n, quantities=("force",), control=None, target=None, rtol=1e-4):
    """DDM derivatives against central differences at every checkpoint; returns the DDM run."""
    target = target if target is not None else model.default_target(specimen, params)  # not moved by x
    run, rows = fixed_steps_run(model, specimen, params, n, control, target, names)
    assert run.derivatives["names"] == tuple(names)
    for k, name in enumerate(names):
        value = getattr(params, name)
        h = RELATIVE_STEP * value
        plus, rows_p = fixed_steps_run(model, specimen, params.replace(**{name: value + h}), n, control, target)
        minus, rows_m = fixed_steps_run(model, specimen, params.replace(**{name: value - h}), n, control, target)
        # the same steps (a step cut elsewhere would change the discrete path, not the model)
        np.testing.assert_array_equal(plus.control, run.control)
        np.testing.assert_array_equal(minus.control, run.control)
        for quantity in quantities:
            def curve(r, rr):
                return (r.force if quantity == "force" else r.observables[quantity])[rr]
            fd = (curve(plus, rows_p) - curve(minus, rows_m)) / (2 * h)
            ddm = run.derivatives[quantity][rows, k]
            # a quantity independent of the parameter (at a held control, a displacement does not
            # depend on E): both must vanish, at the differences' rounding level
            rounding = 1e-3 * np.abs(curve(run, rows)).max() / value
            scale = max(np.abs(fd).max(), rounding)
            error = np.abs(ddm - fd).max() / scale
            assert error <= rtol, f"d {quantity} / d {name}: DDM differs from central differences by {error:.2e}"
    return run


@pytest.mark.parametrize("regularization, names", [
    ("gradient", ("E", "kappa_i", "alpha", "beta", "c", "eta")),
    ("local", ("E", "kappa_i", "alpha", "beta")),
    ("integral", ("kappa_i", "beta", "c")),
])
def test_bar_paths_through_the_peak_and_softening(regularization, names):
    bar = fracid.BarWithWeakZone(n_elements=60)
    params = fracid.DamageParameters(eta=4.0)  # eta acts in compression: zero in a tension bar
    model = DamageModel(regularization)
    quantities = ("force", "external_work", "elastic_energy", "dissipated_energy")
    run = compare(model, bar, params, [n for n in names if n != "eta"], 60, quantities, target=0.12)
    assert run.peak_force > 10 * abs(run.force[-1])  # the path goes well into softening
    if "eta" in names:  # no compression in the bar: the derivative is exactly zero
        run, _ = fixed_steps_run(model, bar, params, 60, target=0.12, names=["eta"])
        assert np.abs(run.derivatives["force"]).max() <= 1e-9 * run.peak_force / params.eta


def test_bar_with_unloading_points_gradient_model():
    """The weak zone's neighbours damage before the peak, then unload while the zone softens: their
    history derivative is carried, not recomputed."""
    bar = fracid.BarWithWeakZone(n_elements=60, weak_zone_factor=0.97, profile="hat")
    params = fracid.DamageParameters()
    model = DamageModel("gradient")
    run = compare(model, bar, params, ("kappa_i", "beta", "c"), 60, target=0.12)
    problem = model.build(bar, params)
    fields = run.fields[run.n_steps]
    q = problem.restrict(np.concatenate([fields["u"], fields["ebar"]]))
    driving = problem.gather(q)[:, problem.dofs.n_u:] @ problem.disc.space("linear").shape.T
    unloading = (driving < fields["kappa"] * (1 - 1e-9)) & (fields["kappa"] > params.kappa_i)
    assert unloading.sum() >= 2


def test_snap_back_traced_under_indirect_control():
    """A long bar: after the peak the end displacement goes back (snap-back) while the weak zone's
    elongation, the control, grows; the derivatives follow through it."""
    bar = fracid.BarWithWeakZone(n_elements=100, profile="hat", length=1000.0)
    params = fracid.DamageParameters(beta=300.0)
    checkpoints = np.concatenate([np.linspace(0.0002, 0.0012, 6), np.linspace(0.0012, 0.003, 41)[1:]])
    run = compare(DamageModel("gradient"), bar, params, ("kappa_i", "beta", "c"), checkpoints,
                  quantities=("force", "end_displacement"), control="weak_zone_elongation")
    assert np.any(np.diff(run.observables["end_displacement"]) < -1e-6)


def test_linear_elastic_range_is_differentiated_exactly():
    """Before damage F = E A u / L (the weak zone a softer segment): d F / d E = F / E to rounding."""
    bar = fracid.BarWithWeakZone(n_elements=40)
    params = fracid.DamageParameters()
    run, _ = fixed_steps_run(DamageModel("gradient"), bar, params, 4, target=0.004,
                             names=("E", "kappa_i", "beta", "c"))
    assert run.observables["dissipated_energy"][-1] == pytest.approx(0.0, abs=1e-12)
    np.testing.assert_allclose(run.derivatives["force"][:, 0], run.force / params.E, rtol=1e-12, atol=1e-15)
    assert np.all(run.derivatives["force"][:, 1:] == 0.0)
    np.testing.assert_allclose(run.derivatives["elastic_energy"][:, 0], run.observables["elastic_energy"] / params.E,
                               rtol=1e-9, atol=1e-18)


@pytest.mark.slow
def test_notched_beam_gradient_model_all_parameters():
    beam = SPECIMENS["notched-beam"](h_fine=4.0, h_coarse=12.0, fine_width=12.0)
    compare(DamageModel("gradient"), beam, fracid.DamageParameters(), ("E", "nu", "kappa_i", "beta", "c", "eta"), 16,
            quantities=("force", "deflection"))


@pytest.mark.slow
def test_dogbone_gradient_model():
    dogbone = SPECIMENS["dogbone"](size=50.0, h_fine=4.0)
    compare(DamageModel("gradient"), dogbone, fracid.DamageParameters(), ("E", "nu", "kappa_i", "alpha", "c"), 30)


def test_zone_widths_are_differentiated():
    """The damaged-zone width of the bar and the FPZ width of the beam move with the level-set crossings:
    DDM equals central differences where no sample crosses the threshold between the runs."""
    bar = fracid.BarWithWeakZone(n_elements=60)
    model = DamageModel("gradient")
    params = fracid.DamageParameters()
    run = compare(model, bar, params, ("kappa_i", "beta", "c"), 60, quantities=("damaged_zone_width",), target=0.12)
    assert run.observables["damaged_zone_width"][-1] > 0
    beam = SPECIMENS["notched-beam"](h_fine=4.0, h_coarse=12.0, fine_width=12.0)
    run = compare(model, beam, params, ("beta", "c"), 16, quantities=("fpz_width",))
    assert run.observables["fpz_width"][-1] > 0


@pytest.mark.slow
def test_pardiso_keeps_the_factorization_for_the_derivatives():
    pytest.importorskip("pypardiso")
    beam = SPECIMENS["notched-beam"](h_fine=4.0, h_coarse=12.0, fine_width=12.0)
    model, params = DamageModel("gradient"), fracid.DamageParameters()
    runs = [model.simulate(beam, params, sensitivities=("c", "beta"), linear_solver=solver, target=0.05)
            for solver in ("superlu", "pardiso")]
    np.testing.assert_allclose(runs[1].derivatives["force"], runs[0].derivatives["force"], rtol=0,
                               atol=1e-9 * np.abs(runs[0].derivatives["force"]).max())
    plain = model.simulate(beam, params, linear_solver="pardiso", target=0.05)
    # the derivatives factorize the converged tangent at every step, and the next step starts with it
    assert runs[1].stats.factorizations <= plain.stats.factorizations + runs[1].n_steps
