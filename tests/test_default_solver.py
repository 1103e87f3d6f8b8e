"""The default linear solver (the fastest installed backend) and the default Newton iteration (modified:
a factorization kept while the residual falls fast) trace the curves the defaults traced before."""

import numpy as np
import pytest

import fracid
from fracid.models import DamageModel
from fracid.specimens import SPECIMENS


def test_the_default_backend_is_the_fastest_installed():
    from fracid.fem.path.linear_solvers import _has_pardiso, linear_solver

    expected = "pardiso" if _has_pardiso() else "superlu"
    assert linear_solver().name == linear_solver("auto").name == expected


@pytest.mark.parametrize("specimen, target", [(SPECIMENS["notched-beam"](h_fine=4.0, h_coarse=12.0), 0.12),
                                              (SPECIMENS["dogbone"](size=50.0, h_fine=4.0), 0.02)])
@pytest.mark.slow
def test_default_curves_equal_superlu_with_full_newton(specimen, target):
    """The default (fastest backend, modified Newton) traces the curves of SuperLU with a factorization
    per iteration, the default before, at the same steps: forces within 1e-6 of the peak."""
    params = fracid.DamageParameters(E=37000.0, nu=0.2, kappa_i=1.1e-4, alpha=0.99, beta=500.0, c=4.0, eta=10.0)
    model = DamageModel("gradient")
    before = model.simulate(specimen, params, target=target, stop_force_fraction=None, linear_solver="superlu",
                            newton=fracid.NewtonOptions(reuse_ratio=0.0))
    default = model.simulate(specimen, params, target=target, stop_force_fraction=None)
    assert default.stats.factorizations < 0.6 * before.stats.factorizations
    np.testing.assert_allclose(default.control, before.control, rtol=1e-9)
    np.testing.assert_allclose(default.force, before.force, rtol=0, atol=1e-6 * np.abs(before.force).max())


def test_a_factorization_is_kept_only_while_the_residual_falls_fast():
    from fracid.fem.path.solver import _keeps_factorization

    options = fracid.NewtonOptions(reuse_ratio=0.3, reuse_iterations=6)
    assert _keeps_factorization(options, 1e3, 1e4)  # rate 0.1: 3 more iterations
    assert _keeps_factorization(options, 1e6, 1e7)  # 6 more
    assert not _keeps_factorization(options, 1e7, 1e8)  # 7 more
    assert not _keeps_factorization(options, 1e5, 2e5)  # rate 0.5 > 0.3
    assert not _keeps_factorization(options, 2.0, 1.0)  # diverging
    assert _keeps_factorization(options, 0.5, 10.0)  # converged at the next check anyway
    assert not _keeps_factorization(fracid.NewtonOptions(reuse_ratio=0.0), 1e3, 1e4)  # full Newton


def test_full_newton_factorizes_every_iteration_but_the_first_of_a_step():
    bar = fracid.BarWithWeakZone(n_elements=40)
    full = DamageModel().simulate(bar, fracid.DamageParameters(), target=0.05, linear_solver="superlu",
                                  newton=fracid.NewtonOptions(reuse_ratio=0.0))
    modified = DamageModel().simulate(bar, fracid.DamageParameters(), target=0.05, linear_solver="superlu")
    s = full.stats
    assert s.failed_increments == 0 and s.factorizations == s.iterations - (s.steps - 1)
    assert modified.n_steps == full.n_steps and modified.stats.factorizations < s.factorizations
    np.testing.assert_allclose(modified.force, full.force, rtol=0, atol=1e-7 * full.peak_force)
