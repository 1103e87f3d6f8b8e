"""DIC twin identification (fracid issue 27, first "Done when" bullet) through the Python API.

The notched beam of the demo geometry on a COARSE mesh (h_fine 4 mm, so the file stays fast), gradient
damage, (kappa_i, beta, c) at the demo's estimate; data: the force-CMOD curve at 12 points [N] and a DIC
field (:func:`~fracid.inverse.studies.dic_twin.synthetic_dic`, complete: no holes, no rigid motion; u and v
[mm] at ~116 points and 4 frames) observed with :class:`~fracid.inverse.core.observations.FieldObservation`.

- a. a noise-free twin is identified back within 1 % (knn-gauss-newton, 8 population runs);
- b. the linearised posterior (S^T C^-1 S + C0^-1)^-1 at the truth, with the exact sensitivities, from the
  curve alone and from curve + field (1 micrometre std correlated over a 6 mm subset; the curve's std 1 % of
  its peak; C0 the uniform prior over the bounds): the field shrinks the stds and the correlations;
- c. the field's direct-differentiation sensitivities equal central differences of runs at fixed steps.
"""

import dataclasses

import numpy as np
import pytest

from fracid.data import Diagonal
from fracid.data.covariance_matrix import block_diagonal
from fracid.data.dic_noise import dic_frames_covariance
from fracid.fem.material.parameters import DamageParameters
from fracid.fem.path.path_following import StepOptions
from fracid.inverse.core.forward_operator import ForwardOperator, Observation
from fracid.inverse.core.field_observations import FieldObservation
from fracid.inverse.core.sensitivity import CentralDifferences
from fracid.inverse.core.space import ParameterSpace
from fracid.inverse.methods.strategy import identify
from fracid.inverse.studies.dic_twin import synthetic_dic
from fracid.inverse.studies.uniqueness import bounds_covariance
from fracid.specimens.beam import NotchedBeam

BEAM = NotchedBeam(h_fine=4.0, h_coarse=10.0)
BASE = DamageParameters(E=36250.0, nu=0.2, kappa_i=6.6e-5, alpha=0.99, beta=600.0, c=9.0, eta=10.0)
NAMES = ("kappa_i", "beta", "c")
TRUTH = np.array([4.798e-5, 1086.5, 21.46])  # the demo's estimate (docs/demo/result.json, rounded)
SPACE = ParameterSpace(NAMES, [4e-5, 200.0, 4.0], [1e-4, 3000.0, 30.0], log=(False, True, False))  # demo.toml
CURVE = np.linspace(0.01, 0.2, 12)  # CMOD [mm]
FRAMES = np.array([0.03, 0.08, 0.14, 0.2])  # CMOD [mm]: pre-peak, near the peak, softening
DIC_STD, SUBSET = 1e-3, 6.0  # mm: 1 micrometre, 6 mm subsets
CURVE_STD = 0.01  # of the peak force


def truth_params(x=TRUTH):
    return dataclasses.replace(BASE, **dict(zip(NAMES, map(float, x))))


@pytest.fixture(scope="module")
def dic():
    return synthetic_dic(BEAM, truth_params(), frames=FRAMES, spacing=6.0, std=0.0, subset_size=SUBSET,
                         holes=None, seed=3)


@pytest.fixture(scope="module")
def operators(dic):
    curve = Observation(BEAM, CURVE, control="cmod", name="curve")
    field = FieldObservation(BEAM, dic.points, FRAMES, control="cmod", name="dic")
    return (ForwardOperator([curve], BASE, NAMES).differentiated(),
            ForwardOperator([curve, field], BASE, NAMES).differentiated())


@pytest.fixture(scope="module")
def at_truth(operators):
    record = operators[1](TRUTH)
    assert record.ok and record.S is not None
    return record


def covariance(record, dic, with_field: bool):
    """Curve: diagonal, std 1 % of the peak [N]; field: DIC noise, low rank + diagonal [mm]."""
    n = CURVE.size
    curve = Diagonal(np.full(n, (CURVE_STD * record.y[:n].max()) ** 2))
    if not with_field:
        return curve
    return block_diagonal([curve, dic_frames_covariance(dic.points, DIC_STD, SUBSET, n_frames=FRAMES.size)])


def linearised_posterior(S, C) -> tuple[np.ndarray, np.ndarray]:
    """(correlation matrix, stds) of (S^T C^-1 S + C0^-1)^-1, C0 the uniform prior over SPACE's bounds."""
    P = np.linalg.inv(S.T @ C.solve(S) + np.linalg.inv(bounds_covariance(SPACE)))
    s = np.sqrt(np.diag(P))
    return P / np.outer(s, s), s


def test_the_field_block_equals_the_twins_displacements(dic, at_truth):
    """Frame x component x point order; the twin's data (no noise, no rigid motion) are the operator's."""
    u = at_truth.y[CURVE.size:].reshape(FRAMES.size, 2, -1).transpose(0, 2, 1)
    assert 80 <= len(dic.points) <= 150
    np.testing.assert_allclose(u, dic.U, atol=1e-9 * np.abs(dic.U).max())


def test_the_field_breaks_the_correlations_of_the_curve(dic, at_truth):
    """Measured on this coarse case (h_fine 4): curve alone r(beta, c) = 0.980, r(kappa_i, c) = -0.958;
    curve + field 0.951 and -0.689; the stds of kappa_i, beta, c shrink by 3.1, 2.1 and 2.7.

    The issue's target for beta-c (<= 0.8 with the field) is NOT met here: the field (~116 points on a 6 mm
    grid, 4 frames, 1 micrometre std correlated over 6 mm) mainly pins kappa_i (the elastic-to-onset part)
    and through it decorrelates kappa_i from c; beta and c both set the width and the softening of the
    process zone, which this coarse mesh and grid resolve poorly. The benchmark measures the demo mesh.
    """
    n = CURVE.size
    r_curve, s_curve = linearised_posterior(at_truth.S[:n], covariance(at_truth, dic, False))
    r_both, s_both = linearised_posterior(at_truth.S, covariance(at_truth, dic, True))
    assert abs(r_curve[1, 2]) >= 0.95 and abs(r_curve[0, 2]) >= 0.95  # the curve alone: the demo's verdict
    assert abs(r_both[1, 2]) < abs(r_curve[1, 2]) - 0.02
    assert abs(r_both[0, 2]) <= 0.8
    assert np.all(s_both < s_curve / 2)


@pytest.mark.slow
def test_a_noise_free_twin_is_identified_back_within_one_percent(operators, at_truth, dic):
    """A test of the inverse machinery with a field block: the population (8 Sobol points over the demo's
    bounds) seeds Gauss-Newton, whose prior is the population's spread; the data are exact (no noise) with
    the realistic covariance. About 15 runs, ~20 s."""
    result = identify(operators[1], at_truth.y, covariance(at_truth, dic, True), SPACE, method="knn-gauss-newton",
                      n=8, k=3, progress=False)
    np.testing.assert_allclose(result.x, TRUTH, rtol=1e-2)


def test_field_sensitivities_equal_central_differences_at_fixed_steps(dic):
    """Fixed increments (no jump to onset, a checkpoint at every step): the step sequence does not depend on the
    parameters, so differences of runs differentiate the same discrete path as DDM."""
    h = 0.01
    steps = StepOptions(initial=h, max_factor=1.0, onset_fraction=1.0, jump_to_onset=False)
    frames = np.array([0.03, 0.08, 0.14])
    curve = Observation(BEAM, np.arange(1, 15) * h, control="cmod", name="curve")
    field = FieldObservation(BEAM, dic.points[::3], frames, control="cmod", name="dic")
    operator = ForwardOperator([curve, field], BASE, NAMES, steps=steps)
    record = operator.differentiated()(TRUTH)
    assert record.ok
    part = slice(curve.size, None)

    def deviation(step):
        _, S_cd, _ = CentralDifferences(relative_step=step)(operator, TRUTH)
        return np.abs(record.S[part] - S_cd[part]).max(axis=0) / np.abs(S_cd[part]).max(axis=0)

    # measured: 1.7e-3, 8.8e-5, 3.0e-4 at a relative step 1e-2 and 1.9e-4, 2.9e-5, 1.4e-4 at 3e-3: the
    # differences' truncation error (step^2); at 3e-4 it is below the runs' Newton tolerance / step
    coarse, fine = deviation(3e-3), deviation(3e-4)
    assert np.all(fine <= 1e-4), fine
    assert np.all(fine < coarse)
