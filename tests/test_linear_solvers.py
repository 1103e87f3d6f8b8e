"""SuperLU with a METIS nested-dissection ordering (the default when pymetis is installed) solves as the
plain SuperLU does and gives the same curves on the beam and the dog-bone."""

import numpy as np
import pytest
import scipy.sparse as sp

import fracid
from fracid.fem.path.linear_solvers import SuperLUSolver, SymmetricOrdering, linear_solver
from fracid.models import DamageModel
from fracid.specimens import SPECIMENS

pytest.importorskip("pymetis")


def test_metis_ordered_lu_solves_and_keeps_its_ordering_per_pattern():
    rng = np.random.default_rng(3)
    n = 400
    pattern = sp.random(n, n, density=0.01, random_state=4, format="csc")
    pattern = (pattern + pattern.T + sp.eye(n) * 10.0).tocsc()  # structurally symmetric, nonsymmetric values
    solver = SuperLUSolver(ordering="metis")
    assert linear_solver("superlu").ordering == "metis"  # SuperLU picks METIS when pymetis is there
    first = None
    for k in range(3):
        values = sp.csc_matrix((pattern.data * rng.uniform(0.5, 1.5, pattern.nnz), pattern.indices, pattern.indptr),
                               shape=pattern.shape)
        b = rng.standard_normal((n, 2))
        x = solver.solve(values, b)
        assert np.linalg.norm(values @ x - b) <= 1e-12 * np.linalg.norm(b)
        order = solver._order
        assert isinstance(order, SymmetricOrdering) and sorted(order.perm) == list(range(n))
        if k:
            assert order is first  # computed once for the pattern
        first = order
    with pytest.raises(ValueError, match="ordering"):
        SuperLUSolver(ordering="amd")


@pytest.mark.parametrize("specimen, target", [(SPECIMENS["notched-beam"](h_fine=4.0, h_coarse=12.0), 0.12),
                                              (SPECIMENS["dogbone"](size=50.0, h_fine=4.0), 0.02)])
def test_curves_equal_those_of_superlus_own_ordering(specimen, target):
    params = fracid.DamageParameters(E=37000.0, nu=0.2, kappa_i=1.1e-4, alpha=0.99, beta=500.0, c=4.0, eta=10.0)
    runs = [DamageModel("gradient").simulate(specimen, params, target=target, stop_force_fraction=None,
                                             linear_solver=SuperLUSolver(ordering=ordering))
            for ordering in ("superlu", "metis")]
    np.testing.assert_allclose(runs[1].control, runs[0].control, rtol=1e-9)
    np.testing.assert_allclose(runs[1].force, runs[0].force, rtol=0, atol=1e-6 * np.abs(runs[0].force).max())



def test_runs_on_one_mesh_share_the_pattern_and_the_ordering():
    from fracid.fem.mesh.assembly import SparsePattern

    beam = SPECIMENS["notched-beam"](h_fine=4.0, h_coarse=12.0)
    solver = linear_solver("superlu")
    assert linear_solver("superlu") is solver  # one per thread
    model = DamageModel("gradient")
    model.simulate(beam, fracid.DamageParameters(), target=0.02, linear_solver="superlu")
    order = solver._order
    model.simulate(beam, fracid.DamageParameters(c=2.0), target=0.02, linear_solver="superlu")
    assert order is not None and solver._order is order  # METIS ran once for both runs
    dofs = np.arange(12).reshape(3, 4)
    assert SparsePattern.shared(12, dofs, [0], [1]) is SparsePattern.shared(12, dofs.copy(), [0], [1])
    assert SparsePattern.shared(12, dofs, [0], [2]) is not SparsePattern.shared(12, dofs, [0], [1])
