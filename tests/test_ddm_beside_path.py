"""The derivatives beside the path (fracid.fem.path.ddm.ConcurrentDerivatives, the default): the same derivatives as
in the path's thread, the path of the plain run to the last digit, and a singular tangent of the derivatives
ending the run with the steps before it."""

import numpy as np
import pytest

import fracid
from fracid.fem.path import ddm
from fracid.fem.path.linear_backend import SingularMatrixError
from fracid.fem.path.linear_solvers import SuperLUSolver
from fracid.fem.path.path_following import ConvergenceError
from fracid.models import DamageModel

NAMES = ("kappa_i", "beta", "c")
# (the bar's load-point displacement is its control, held: derivatives of rounding only)
QUANTITIES = ("force", "external_work", "elastic_energy", "dissipated_energy")


@pytest.fixture
def in_the_paths_thread(monkeypatch):
    monkeypatch.setattr(ddm, "BESIDE_PATH", False)


def bar_run(**options):
    bar = fracid.BarWithWeakZone(n_elements=40)
    return DamageModel("gradient").simulate(bar, fracid.DamageParameters(c=2.0, beta=250.0), stop_force_fraction=None,
                                            **options)


@pytest.mark.parametrize("backend", ["superlu", "pardiso"])
def test_beside_the_path_equals_the_paths_thread(backend, monkeypatch):
    if backend == "pardiso":
        pytest.importorskip("pypardiso")
    beside = bar_run(sensitivities=NAMES, linear_solver=backend)
    plain = bar_run(linear_solver=backend)
    monkeypatch.setattr(ddm, "BESIDE_PATH", False)
    inline = bar_run(sensitivities=NAMES, linear_solver=backend)
    # the path is the plain run's exactly; in the path's thread Newton starts from the derivatives' factorization
    np.testing.assert_array_equal(beside.control, plain.control)
    np.testing.assert_array_equal(beside.force, plain.force)
    assert beside.control.shape == inline.control.shape
    np.testing.assert_allclose(beside.force, inline.force, rtol=0, atol=1e-7 * plain.peak_force)
    assert plain.peak_force > 5 * abs(plain.force[-1])  # well into softening
    for quantity in QUANTITIES:
        d_beside, d_inline = beside.derivatives[quantity], inline.derivatives[quantity]
        assert d_beside.shape == (beside.n_steps + 1, len(NAMES))
        scale = np.abs(d_inline).max(axis=0)
        assert np.all(np.abs(d_beside - d_inline) <= 1e-5 * scale), quantity
    assert beside.stats.factorizations > plain.stats.factorizations  # the derivatives' counted too


def test_a_solver_instance_keeps_the_derivatives_in_the_paths_thread():
    solver = SuperLUSolver()
    run = bar_run(sensitivities=NAMES, linear_solver=solver, target=0.02)
    assert run.derivatives["force"].shape == (run.n_steps + 1, len(NAMES))


@pytest.mark.parametrize("beside", [True, False])
def test_singular_derivatives_end_the_run_with_the_steps_before(beside, monkeypatch):
    """The derivatives of step 12 fail: the run stops there with 11 steps, curves and derivatives of the same
    length, whether the failure is found one step later (beside the path) or at once."""
    monkeypatch.setattr(ddm, "BESIDE_PATH", beside)
    step = ddm.PathDerivatives.step

    def failing(self, *args, **kwargs):
        if len(self.records["force"]) == 12:  # rows: step 0 and 11 steps differentiated
            raise SingularMatrixError("injected")
        return step(self, *args, **kwargs)

    monkeypatch.setattr(ddm.PathDerivatives, "step", failing)
    with pytest.raises(ConvergenceError, match="derivatives are not defined there") as info:
        bar_run(sensitivities=NAMES)
    partial = info.value.partial
    assert partial.n_steps == 11
    for name in ("force", *QUANTITIES):
        assert partial.derivatives[name].shape == (12, len(NAMES)), name
    assert partial.force.shape == (12,) and partial.observables["external_work"].shape == (12,)
    assert f"{partial.control[-1]:.6g}" not in str(info.value)  # the message names the failed step, not the last kept
    plain = bar_run()
    np.testing.assert_allclose(partial.force, plain.force[:12], rtol=0, atol=0.0 if beside else 1e-8 * plain.peak_force)
