"""Full-field observations at DIC scale: a sparse probe matrix applied by the path follower at the checkpoint
steps only (``follow_path(probes=...)``, ``PathResult.probed``), and its exact sensitivities."""

import tracemalloc

import numpy as np
import pytest
import scipy.sparse as sp

from fracid.fem.mesh.probes import dof_matrix, probe_matrix
from fracid.fem.path.recorder import ProbeSampler
from fracid.inverse.core.forward_operator import FieldObservation, ForwardOperator, Observation
from fracid.models import DamageModel, StepOptions
from fracid.specimens import SPECIMENS

N_STEPS = 8
NAMES = ("kappa_i", "beta", "c")
POINTS = np.array([[5.0, 30.0], [20.0, 10.0], [2.0, 45.0], [0.5, 25.5], [40.0, 45.0]])


@pytest.fixture(scope="module")
def case():
    beam = SPECIMENS["notched-beam"](h_fine=4.0, h_coarse=12.0, fine_width=12)
    model = DamageModel("gradient")
    params = model.parameters()
    target = 0.5 * model.default_target(beam, params)
    d = beam.describe()
    P = probe_matrix(d.nodes, d.cells, POINTS)
    matrix = sp.vstack([dof_matrix(P, 0), dof_matrix(P, 1)], format="csr")
    return beam, model, params, target, matrix


def _fixed_steps(target):
    """One step per checkpoint, the same sequence in every run (no jump to the onset, no growth)."""
    steps = StepOptions(initial=target / N_STEPS, onset_fraction=1.0, max_factor=1.0, jump_to_onset=False)
    return steps, np.linspace(0.0, target, N_STEPS + 1)[1:]


def test_probed_values_are_the_probe_matrix_times_the_nodal_field_at_the_checkpoints_only(case):
    beam, model, params, target, matrix = case
    frames = np.array([0.3, 0.7, 1.0]) * target
    run = model.simulate(beam, params, target=target, checkpoints=frames, field_steps="all", probes=matrix,
                         stop_force_fraction=None)
    steps = [int(np.argmin(np.abs(run.control - f))) for f in frames]
    assert run.n_steps > len(frames) and sorted(run.probed) == steps  # adaptive steps between the frames
    for step in steps:
        u = run.fields[step]["u"]
        np.testing.assert_allclose(run.probed[step], matrix @ u, rtol=0, atol=1e-12 * np.abs(u).max())
    values, derivatives = run.probed_at(frames)
    assert derivatives is None and values.shape == (3, matrix.shape[0]) and np.abs(values).max() > 1e-3
    with pytest.raises(ValueError, match="no probe values at control"):
        run.probed_at([0.5 * target])
    assert np.all(np.isnan(run.probed_at([2.0 * target])[0]))  # beyond the run: not reached


def test_probe_sensitivities_match_central_differences_at_fixed_steps(case):
    beam, model, params, target, matrix = case
    steps, control = _fixed_steps(target)
    frames = control[[2, 5, 7]]

    def run(p, sensitivities=None):
        out = model.simulate(beam, p, target=target, steps=steps, checkpoints=control, probes=matrix,
                             stop_force_fraction=None, **({"sensitivities": sensitivities} if sensitivities else {}))
        assert out.n_steps == N_STEPS
        return out.probed_at(frames)

    _, S = run(params, NAMES)
    assert S.shape == (3, matrix.shape[0], len(NAMES))
    for j, name in enumerate(NAMES):
        h = 1e-6 * getattr(params, name)
        plus, _ = run(params.replace(**{name: getattr(params, name) + h}))
        minus, _ = run(params.replace(**{name: getattr(params, name) - h}))
        difference = (plus - minus) / (2 * h)
        scale = np.abs(difference).max()
        assert scale > 0
        np.testing.assert_allclose(S[..., j], difference, rtol=0, atol=1e-4 * scale)


def test_kinds_sharing_a_run_get_their_own_rows_of_the_stacked_matrix(case):
    beam, model, params, target, _ = case
    steps, control = _fixed_steps(target)
    x = np.array([getattr(params, n) for n in NAMES[:2]])
    first = FieldObservation(beam, POINTS[:3], control[[3, 7]], name="a")
    second = FieldObservation(beam, POINTS[2:], control[[1, 5, 7]], components=1, name="b")
    curve = Observation(beam, control)

    def evaluate(kinds):
        return ForwardOperator(kinds, params, NAMES[:2], model=model, steps=steps, sensitivities=True)(x)

    together = evaluate([first, curve, second])
    alone = [evaluate([kind]) for kind in (first, curve, second)]
    np.testing.assert_allclose(together.y, np.concatenate([r.y for r in alone]), rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(together.S, np.concatenate([r.S for r in alone]), rtol=1e-7, atol=1e-10)


def test_a_run_for_part_of_the_outputs_samples_the_frames_it_passes(case):
    """The step-by-step Kalman filter asks for the first entries only: the curve's run goes to its end, past
    frames whose entries are not needed; they are steps too (regression: 'no probe values at control')."""
    beam, model, params, target, _ = case
    steps, control = _fixed_steps(target)
    frames = 0.5 * (control[[1, 4, 6]] + control[[2, 5, 7]])  # not points of the curve
    curve, field = Observation(beam, control), FieldObservation(beam, POINTS, frames)
    operator = ForwardOperator([curve, field], params, NAMES[:2], model=model, steps=steps, sensitivities=True)
    x = np.array([getattr(params, n) for n in NAMES[:2]])
    needed = curve.size + 2 * len(POINTS)  # the curve and the first frame's entries
    part, whole = operator(x, needed=needed), operator(x)
    assert part.ok, part.error
    np.testing.assert_allclose(part.y[:needed], whole.y[:needed], rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(part.S[:needed], whole.S[:needed], rtol=1e-7, atol=1e-10)


def test_points_of_the_other_half_are_the_mirror_images(case):
    """A half beam (crack on the symmetry line x = 0): a camera point at (-x, y) is computed as (x, y), u_x's
    sign flipped, u_y's kept, with its sensitivities."""
    beam, model, params, target, _ = case
    steps, control = _fixed_steps(target)
    mirror = POINTS * [-1.0, 1.0]
    kinds = [FieldObservation(beam, np.vstack([POINTS, mirror]), control[[3, 7]])]
    record = ForwardOperator(kinds, params, NAMES[:2], model=model, steps=steps, sensitivities=True)(
        np.array([getattr(params, n) for n in NAMES[:2]]))
    n = len(POINTS)
    y, S = record.y.reshape(2, 2, 2 * n), record.S.reshape(2, 2, 2 * n, -1)  # frame, component, point
    assert np.abs(y[:, 0, :n]).max() > 1e-4  # u_x is not zero where we compare
    np.testing.assert_allclose(y[:, 0, n:], -y[:, 0, :n], rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(y[:, 1, n:], y[:, 1, :n], rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(S[:, 0, n:], -S[:, 0, :n], rtol=1e-12, atol=1e-15)


def test_five_thousand_points_on_the_default_beam_stay_sparse():
    beam = SPECIMENS["notched-beam"]()
    model = DamageModel("gradient")
    d = beam.describe()
    rng = np.random.default_rng(3)
    lo, hi = d.nodes.min(axis=0), d.nodes.max(axis=0)
    points = rng.uniform(lo + [0.0, 30.0], hi - [0.5, 0.5], (5000, 2))  # above the notch, inside the half beam
    problem = model.build(d, model.parameters())
    dense_bytes = 2 * len(points) * problem.n_free * 8
    tracemalloc.start()
    field = FieldObservation(beam, points, [0.01, 0.02])
    sampler = ProbeSampler(problem, field.probe_matrix(), [0.01, 0.02])
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    assert problem.n_free > 10_000 and dense_bytes > 500e6
    assert peak < 0.02 * dense_bytes, f"{peak / 1e6:.1f} MB for {dense_bytes / 1e6:.0f} MB dense"
    assert sp.issparse(field.probe_matrix()) and sp.issparse(sampler.matrix) and field.probes == {}
    assert field.probe_matrix().nnz <= 2 * len(points) * 8 and sampler.matrix.nnz <= field.probe_matrix().nnz
    assert not any(isinstance(v, np.ndarray) and v.size > 2 * len(points) for v in vars(field).values())


def test_bad_probes_are_named(case):
    beam, model, params, target, matrix = case
    problem = model.build(beam.describe(), params)
    with pytest.raises(TypeError, match="scipy.sparse"):
        ProbeSampler(problem, matrix.toarray())
    with pytest.raises(ValueError, match="columns"):
        ProbeSampler(problem, matrix[:, :-2])
    sampler = ProbeSampler(problem, matrix, [0.1, 0.2])
    assert sampler.wanted(0.1 + 1e-14) and not sampler.wanted(0.15)
    assert ProbeSampler(problem, matrix).wanted(0.15)  # no checkpoints: every step
