"""The assembled consistent tangent against a central finite-difference Jacobian of the residual."""

import numpy as np
import pytest

import fracid
from fracid.fem.mesh.assembly import SparsePattern
from fracid.models import DamageModel


def finite_difference_jacobian(problem, q, kappa_old, steps):
    jac = np.zeros((q.size, q.size))
    for j in range(q.size):
        dq = np.zeros_like(q)
        dq[j] = steps[j]
        plus = problem.evaluate(q + dq, kappa_old)[0]
        minus = problem.evaluate(q - dq, kappa_old)[0]
        jac[:, j] = (plus - minus) / (2 * steps[j])
    return jac


def post_peak_state(regularization, params, bar, control=None, target=None):
    """History after a post-peak step k, and a trial state q_k + r * (q_k+1 - q_k), r random in [-1, 2].

    The random increment makes some damaged points unload while others keep loading; the ends of
    the bar stay undamaged.
    """
    if control is None:
        control = "end_displacement" if regularization == "gradient" else "weak_zone_elongation"
        target = 0.025 if regularization == "gradient" else 0.005
    result = fracid.simulate(bar, params, model=DamageModel(regularization), control=control, target=target,
                             stop_force_fraction=None, field_steps="all")
    problem = DamageModel(regularization).build(bar, params)
    k = result.n_steps - 2  # the last increment may be a sliver up to the target
    assert result.force[k] < 0.9 * result.peak_force  # well past the peak
    kappa_old = result.fields[k]["kappa"]
    q_k, q_next = (
        problem.restrict(np.concatenate([result.fields[i][f] for f in ("u", "ebar") if f in result.fields[i]]))
        for i in (k, k + 1)
    )
    ratio = np.random.default_rng(3).uniform(-1.0, 2.0, size=q_k.size)
    return problem, q_k + ratio * (q_next - q_k), kappa_old


@pytest.mark.parametrize("regularization", ["gradient", "local"])
def test_tangent_matches_finite_differences(regularization):
    params = fracid.DamageParameters(alpha=0.99, beta=300.0, c=1.0)
    bar = fracid.BarWithWeakZone(n_elements=60, profile="hat")
    problem, q, kappa_old = post_peak_state(regularization, params, bar)

    residual, arrays, _ = problem.evaluate(q, kappa_old)
    loading = arrays.history > kappa_old
    damaged = arrays.history > params.kappa_i
    assert np.any(loading & damaged), "no damaged point loading"
    assert np.any(~loading & (kappa_old > params.kappa_i)), "no damaged point unloading"
    assert np.any(~damaged), "no undamaged point"

    tangent = SparsePattern(problem.n_free, problem.element_dofs).matrix(arrays.tangent).toarray()
    steps = np.full(q.size, 1e-9)  # mm for displacements
    if "ebar" in problem.blocks:
        steps[problem.blocks["ebar"]] = 1e-10  # ebar is ~1e-4
    numeric = finite_difference_jacobian(problem, q, kappa_old, steps)
    for rows in problem.blocks.values():
        for cols in problem.blocks.values():
            exact, fd = tangent[np.ix_(rows, cols)], numeric[np.ix_(rows, cols)]
            assert np.linalg.norm(exact - fd) <= 1e-6 * np.linalg.norm(exact)


@pytest.mark.parametrize("regularization", ["gradient", "local"])
def test_plane_stress_tangent_matches_finite_differences(regularization):
    from fracid.specimens.dogbone import DogBone

    params = fracid.DamageParameters(E=30000.0, nu=0.2, alpha=0.99, beta=300.0, c=4.0, eta=10.0)
    specimen = DogBone(size=50.0, h_fine=5.0)
    target = 0.02 if regularization == "gradient" else 0.008
    problem, q, kappa_old = post_peak_state(regularization, params, specimen, control="elongation", target=target)

    residual, arrays, _ = problem.evaluate(q, kappa_old)
    loading = arrays.history > kappa_old
    damaged = arrays.history > params.kappa_i
    assert np.any(loading & damaged) and np.any(~loading & (kappa_old > params.kappa_i)) and np.any(~damaged)

    tangent = SparsePattern(problem.n_free, problem.element_dofs).matrix(arrays.tangent).toarray()
    steps = np.full(q.size, 1e-9)
    if "ebar" in problem.blocks:
        steps[problem.blocks["ebar"]] = 1e-10
    numeric = finite_difference_jacobian(problem, q, kappa_old, steps)
    for rows in problem.blocks.values():
        for cols in problem.blocks.values():
            exact, fd = tangent[np.ix_(rows, cols)], numeric[np.ix_(rows, cols)]
            assert np.linalg.norm(exact - fd) <= 1e-6 * np.linalg.norm(exact)
