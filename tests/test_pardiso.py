"""PARDISO backend: agreement with SuperLU, reuse of the symbolic analysis, singular matrices."""

import gc
import subprocess
import sys

import numpy as np
import pytest
import scipy.sparse as sp
import scipy.sparse.linalg as spla

import fracid
from fracid.fem.path import pardiso as pardiso_module
from fracid.fem.path.linear_backend import SingularMatrixError
from fracid.fem.path.linear_solvers import SuperLUSolver
from fracid.fem.path.pardiso import PardisoSolver
from fracid.models.damage import DamageModel

pytest.importorskip("pypardiso")  # fracid.fem.path.pardiso itself imports it only when a solver is made

# Step rule made insensitive to round-off, so that both backends take the same steps: with the defaults,
# the step after the jump to 0.999 x onset lands exactly on the onset (0.999 + 0.02/20), and whether it
# counts as the onset step is decided by round-off; and the step growth depends on iteration counts, which
# round-off can change where a point sits exactly at its damage threshold.
STEPS = fracid.StepOptions(onset_fraction=0.03, easy_iterations=fracid.NewtonOptions().max_iterations)


def random_unsymmetric(n, density, seed, explicit_zeros=0):
    """A well-conditioned unsymmetric CSC matrix (random entries plus a dominant diagonal)."""
    rng = np.random.default_rng(seed)
    off = sp.random(n, n, density=density, random_state=rng, data_rvs=rng.standard_normal, format="csc")
    matrix = (off + sp.diags(rng.uniform(2.0, 3.0, n) * (1.0 + abs(off).sum(axis=1).A1))).tocsc()
    matrix.sort_indices()
    if explicit_zeros:
        off_diagonal = np.flatnonzero(matrix.indices != np.repeat(np.arange(n), np.diff(matrix.indptr)))
        matrix.data[rng.choice(off_diagonal, explicit_zeros, replace=False)] = 0.0  # stored, not removed
    return matrix


def relative_error(x, reference):
    return np.linalg.norm(x - reference) / np.linalg.norm(reference)


@pytest.mark.parametrize("n, density, explicit_zeros", [(50, 0.1, 0), (400, 0.01, 0), (400, 0.01, 60)])
def test_matches_spsolve(n, density, explicit_zeros):
    matrix = random_unsymmetric(n, density, seed=n + explicit_zeros, explicit_zeros=explicit_zeros)
    assert np.count_nonzero(matrix.data == 0.0) == explicit_zeros
    assert abs(matrix - matrix.T).max() > 0.1  # truly unsymmetric: a transposed solve would be wrong
    b = np.random.default_rng(1).standard_normal(n)
    x = PardisoSolver().solve(matrix, b)
    assert x.shape == (n,)
    assert relative_error(x, spla.spsolve(matrix, b)) < 1e-10
    assert relative_error(x, spla.spsolve(matrix.T.tocsc(), b)) > 1e-3


def test_several_right_hand_sides_and_other_formats():
    matrix = random_unsymmetric(200, 0.03, seed=3)
    rhs = np.random.default_rng(2).standard_normal((200, 3))
    reference = spla.spsolve(matrix, rhs)
    solver = PardisoSolver()
    x = solver.solve(matrix, rhs)
    assert x.shape == (200, 3)
    assert relative_error(x, reference) < 1e-10
    # CSR input and a non-canonical CSC (unsorted indices, a duplicate entry) give the same answer
    assert relative_error(solver.solve(matrix.tocsr(), rhs), reference) < 1e-10
    indices, data = [], []
    for j in range(matrix.shape[1]):  # reverse each column, and split the first entry into two duplicates
        col = slice(matrix.indptr[j], matrix.indptr[j + 1])
        indices += [matrix.indices[col][::-1], matrix.indices[col][:1]]
        data += [matrix.data[col][::-1] * np.r_[np.ones(col.stop - col.start - 1), 0.75], 0.25 * matrix.data[col][:1]]
    indptr = np.r_[0, np.cumsum(np.diff(matrix.indptr) + 1)]
    messy = sp.csc_matrix((np.concatenate(data), np.concatenate(indices), indptr), shape=matrix.shape)
    assert not messy.has_canonical_format
    assert relative_error(solver.solve(messy, rhs), reference) < 1e-10


@pytest.fixture
def phases(monkeypatch):
    """The PARDISO phases called, in order."""
    called = []
    call = pardiso_module._call

    def recording_call(pardiso, pt_type, pt, iparm, phase, *args):
        called.append(phase)
        return call(pardiso, pt_type, pt, iparm, phase, *args)

    monkeypatch.setattr(pardiso_module, "_call", recording_call)
    return called


def test_analysis_reused_while_pattern_is_unchanged(phases):
    base = random_unsymmetric(300, 0.02, seed=7, explicit_zeros=20)
    rng = np.random.default_rng(8)
    solver = PardisoSolver()
    for k in range(5):
        # a new matrix object with new values (explicit zeros becoming nonzero and back) on the same pattern
        data = base.data * rng.uniform(0.5, 1.5, base.nnz) + (k % 2) * (base.data == 0.0) * rng.standard_normal(base.nnz)
        matrix = sp.csc_matrix((data, base.indices.copy(), base.indptr.copy()), shape=base.shape)
        b = rng.standard_normal(300)
        assert relative_error(solver.solve(matrix, b), spla.spsolve(matrix, b)) < 1e-10
    assert solver.n_analyses == 1
    assert solver.n_factorizations == 5
    assert phases == [11] + [23] * 5
    # a new pattern triggers a new analysis (after releasing the old one)
    other = random_unsymmetric(300, 0.02, seed=9)
    b = rng.standard_normal(300)
    assert relative_error(solver.solve(other, b), spla.spsolve(other, b)) < 1e-10
    assert solver.n_analyses == 2
    assert phases[-3:] == [-1, 11, 23]
    solver.free()
    assert not solver.pt.any()
    solver.solve(other, b)
    assert solver.n_analyses == 3


def bordered(n, seed, coupled=(), reach=()):
    """A random matrix bordered by a row and a column with a zero diagonal (as the path's tangents), plus a
    dense block between the rows ``coupled`` and the columns ``reach`` (as the integral model's coupling)."""
    rng = np.random.default_rng(seed)
    border = np.zeros(n)
    border[rng.choice(n, 5, replace=False)] = 1.0
    inner = random_unsymmetric(n, 0.02, seed=seed).tolil()
    for i in coupled:
        inner[i, list(reach)] = 0.05 * rng.standard_normal(len(reach))
    return sp.bmat([[inner.tocsc(), sp.csc_matrix(-border[:, None])], [sp.csc_matrix(border[None, :]), None]]).tocsc()


def test_a_grown_pattern_keeps_the_ordering_with_the_grown_rows_moved_last(phases):
    rng = np.random.default_rng(3)
    solver = PardisoSolver()
    base = bordered(300, seed=5)
    solver.solve(base, rng.standard_normal(301))
    ordering = solver._perm.copy()
    assert phases == [11, -1, 11, 23] and ordering[-1] == 300  # nested dissection, then with the border last
    coupled, reach = [4, 17, 250], range(100, 220)
    grown = bordered(300, seed=5, coupled=coupled, reach=reach)
    grown = grown + base * 0.0  # holds every entry of the base pattern (the coupling is added to it)
    grown.sort_indices()
    b = rng.standard_normal(301)
    assert relative_error(solver.solve(grown, b), spla.spsolve(grown, b)) < 1e-10
    assert phases[4:] == [-1, 11, 23]  # one analysis, without the nested dissection
    # the base ordering, the 3 rows that gained entries (fewer than the 120 columns) after it, the border last
    assert solver._perm[-1] == 300 and sorted(solver._perm[-4:-1]) == coupled
    np.testing.assert_array_equal(solver._perm[:-4], ordering[~np.isin(ordering, coupled)][:-1])
    # a pattern that is not a superset is ordered anew (and becomes the base)
    other = bordered(300, seed=6)
    assert relative_error(solver.solve(other, b), spla.spsolve(other, b)) < 1e-10
    assert phases[7:] == [-1, 11, -1, 11, 23]


def test_memory_released_when_the_solver_is_collected(phases):
    solver = PardisoSolver()
    solver.solve(random_unsymmetric(100, 0.05, seed=4), np.ones(100))
    del solver
    gc.collect()
    assert phases == [11, 23, -1]


def test_singular_matrices_raise():
    solver = PardisoSolver()
    with pytest.raises(SingularMatrixError):  # numerically singular: perturbed pivots, large residual
        solver.solve(sp.csc_matrix(np.array([[1.0, 2.0, 0.0], [2.0, 4.0, 0.0], [0.0, 1.0, 1.0]])), np.array([1.0, 0.0, 0.0]))
    with pytest.raises(SingularMatrixError):  # all-zero values on a full pattern
        solver.solve(sp.csc_matrix((np.zeros(4), [0, 1, 0, 1], [0, 2, 4]), shape=(2, 2)), np.ones(2))
    with pytest.raises(SingularMatrixError):  # an empty column (PARDISO itself would crash on it)
        solver.solve(sp.csc_matrix(np.array([[1.0, 0.0], [1.0, 0.0]])), np.ones(2))
    with pytest.raises(SingularMatrixError):  # an empty row
        solver.solve(sp.csc_matrix(np.array([[1.0, 1.0], [0.0, 0.0]])), np.ones(2))
    # the solver is still usable afterwards
    matrix = random_unsymmetric(30, 0.2, seed=1)
    assert relative_error(solver.solve(matrix, np.ones(30)), spla.spsolve(matrix, np.ones(30))) < 1e-10


def test_bar_force_curve_matches_superlu():
    bar = fracid.BarWithWeakZone(n_elements=100)
    params = fracid.DamageParameters()
    reference = fracid.simulate(bar, params, steps=STEPS, linear_solver=SuperLUSolver())
    solver = PardisoSolver()
    result = fracid.simulate(bar, params, steps=STEPS, linear_solver=solver)
    assert result.status == reference.status
    assert result.n_steps == reference.n_steps > 10
    np.testing.assert_allclose(result.control, reference.control, rtol=1e-8, atol=0.0)
    np.testing.assert_allclose(result.force, reference.force, rtol=1e-8, atol=1e-8 * reference.peak_force)
    assert solver.n_analyses == 1
    assert solver.n_factorizations == result.stats.factorizations < result.stats.linear_solves  # a step starts with the last factorization


def test_snap_back_run_matches_superlu():
    """Local model of a long bar under weak-zone elongation control: the bordered system through snap-back."""
    bar = fracid.BarWithWeakZone(n_elements=200, profile="hat", length=400.0)
    params = fracid.DamageParameters(beta=100.0)
    kwargs = {"model": DamageModel("local"), "control": "weak_zone_elongation", "target": 0.1, "stop_force_fraction": 0.05, "steps": STEPS}
    reference = fracid.simulate(bar, params, linear_solver=SuperLUSolver(), **kwargs)
    solver = PardisoSolver()
    result = fracid.simulate(bar, params, linear_solver=solver, **kwargs)
    assert np.any(np.diff(result.observables["end_displacement"]) < 0)  # snap-back traced
    assert result.n_steps == reference.n_steps
    np.testing.assert_allclose(result.force, reference.force, rtol=1e-8, atol=1e-8 * reference.peak_force)
    assert solver.n_analyses == 1


def test_plane_stress_dog_bone_matches_superlu():
    """2D mixed quadrilaterals with tied dofs, past the peak."""
    from fracid.specimens.dogbone import DogBone

    specimen = DogBone(h_fine=4.0)
    params = fracid.DamageParameters()
    reference = fracid.simulate(specimen, params, steps=STEPS, linear_solver=SuperLUSolver(), max_steps=30)
    solver = PardisoSolver()
    result = fracid.simulate(specimen, params, steps=STEPS, linear_solver=solver, max_steps=30)
    assert result.n_steps == reference.n_steps == 30
    assert reference.force[-1] < 0.6 * reference.peak_force  # well into softening
    np.testing.assert_allclose(result.force, reference.force, rtol=1e-8, atol=1e-8 * reference.peak_force)
    assert solver.n_analyses == 1


def test_registered_by_name_when_available():
    from fracid.fem.path import linear_solvers

    if "pardiso" not in linear_solvers._BACKENDS:
        pytest.skip("'pardiso' is not registered in linear_solvers._BACKENDS yet")
    assert isinstance(linear_solvers.linear_solver("pardiso"), PardisoSolver)


def test_missing_pypardiso_gives_a_clear_error(monkeypatch):
    monkeypatch.setitem(sys.modules, "pypardiso", None)
    monkeypatch.setitem(sys.modules, "pypardiso.pardiso_wrapper", None)
    pardiso_module._mkl_pardiso.cache_clear()
    try:
        with pytest.raises(ImportError, match=r"pip install 'fracid\[pardiso\]'"):
            PardisoSolver()
    finally:
        pardiso_module._mkl_pardiso.cache_clear()


def test_importing_fracid_does_not_import_pypardiso():
    code = "import sys, fracid, fracid.fem.path.pardiso; assert 'pypardiso' not in sys.modules"
    subprocess.run([sys.executable, "-c", code], check=True)


def test_the_peer_beam_at_its_fine_mesh_runs_and_equals_superlu():
    """27k unknowns, point-like plates: with scaling and matching every factorization perturbed pivots
    and was rejected (the run stopped at its first increment); now the curve equals SuperLU's."""
    import fracid
    from fracid.models import DamageModel
    from fracid.specimens import SPECIMENS

    peer = SPECIMENS["notched-beam"](h_fine=0.5, plate_width=1.0)
    params = fracid.DamageParameters(E=37000.0, nu=0.2, kappa_i=1.1e-4, alpha=0.99, beta=500.0, c=4.0, eta=10.0)
    runs = [DamageModel("gradient").simulate(peer, params, control="cmod", target=0.16, max_steps=4,
                                             stop_force_fraction=None, linear_solver=solver)
            for solver in ("superlu", "pardiso")]
    assert runs[1].n_steps == 4 and runs[1].stats.failed_increments == 0
    np.testing.assert_allclose(runs[1].force, runs[0].force, rtol=0, atol=1e-8 * np.abs(runs[0].force).max())


def test_runs_on_one_mesh_share_the_symbolic_analysis():
    from fracid.fem.path.linear_solvers import linear_solver
    from fracid.models import DamageModel

    bar = fracid.BarWithWeakZone(n_elements=40)
    solver = linear_solver("pardiso")
    assert linear_solver("pardiso") is solver  # one per thread
    analyses = solver.n_analyses
    first = DamageModel().simulate(bar, fracid.DamageParameters(), target=0.03, linear_solver="pardiso")
    after_first = solver.n_analyses
    second = DamageModel().simulate(bar, fracid.DamageParameters(c=2.0), target=0.03, linear_solver="pardiso")
    assert after_first <= analyses + 1 and solver.n_analyses == after_first  # the second run reused it
    assert second.n_steps > 0 and first.n_steps > 0
