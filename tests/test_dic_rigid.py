"""The rigid-body motion of DIC frames: marginalised in the covariance, estimated afterwards (issue 27, item 2)."""

import numpy as np
import pytest

from fracid.data.covariance_matrix import Diagonal
from fracid.data.covariance_matrix import block_diagonal
from fracid.data.dic import DicData, field_block
from fracid.data.dic.rigid import RIGID_STD, fit_rigid_motion, rigid_modes, with_rigid_motion
from fracid.data.dic_noise import dic_covariance

RNG = np.random.default_rng(5)
POINTS = np.column_stack([RNG.uniform(5.0, 80.0, 60), RNG.uniform(10.0, 45.0, 60)])  # mm
MOTION = np.array([0.004, -0.012, 5e-5])  # tx, ty [mm], theta [rad]: a support settling


def _deformation(points) -> np.ndarray:
    """A smooth non-rigid field [mm] (u then v at every point): a beam-like bending and a stretch."""
    x, y = points.T
    return np.concatenate([2e-4 * x * (y - 25.0) / 25.0, -3e-6 * (x - 40.0) ** 2])


def _noise_covariance(points, std=1e-3):
    block = dic_covariance(points, std, 6.0)
    return block_diagonal([block, block])


def test_rigid_modes_are_translations_and_the_small_rotation_about_the_origin():
    R = rigid_modes(POINTS, (0, 1))
    n = len(POINTS)
    np.testing.assert_array_equal(R[:n, 0], 1.0)
    np.testing.assert_array_equal(R[n:, 0], 0.0)
    np.testing.assert_array_equal(R[n:, 1], 1.0)
    np.testing.assert_allclose(R[:, 2], np.concatenate([-POINTS[:, 1], POINTS[:, 0]]))
    theta = 1e-4  # the linear mode is the rotation's displacement to first order
    exact = POINTS @ (np.array([[np.cos(theta), -np.sin(theta)], [np.sin(theta), np.cos(theta)]]) - np.eye(2)).T
    np.testing.assert_allclose(R[:, 2] * theta, exact.T.reshape(-1), atol=1e-6)  # theta^2 |x| / 2
    assert rigid_modes(POINTS, (1,)).shape == (n, 3)


def test_the_marginalised_likelihood_is_the_one_with_the_best_rigid_motion_taken_out():
    C = _noise_covariance(POINTS)
    total = with_rigid_motion(C, POINTS, (0, 1))
    assert total.U.shape[1] == 3 and total.base is C  # the prior's columns on the sparse noise's own factor
    R = rigid_modes(POINTS, (0, 1))
    r = R @ MOTION + C.color(np.random.default_rng(0).normal(size=C.n))
    motion, fitted = fit_rigid_motion(POINTS, (0, 1), r, C)  # generalised least squares
    profiled = C.quadratic(r - fitted)
    assert total.quadratic(r) == pytest.approx(profiled, rel=1e-3)
    assert 0.6 < profiled / (C.n - 3) < 1.4  # the noise alone
    assert C.quadratic(r) > 20 * profiled  # without the marginalisation the motion dominates the misfit
    # a further rigid motion of the data changes nothing (to (a / s)^2: 1e-4 per mode here)
    assert total.quadratic(r + R @ [0.01, -0.01, 1e-4]) == pytest.approx(total.quadratic(r), abs=1e-3)


def test_the_motion_of_a_noise_free_field_is_recovered():
    R = rigid_modes(POINTS, (0, 1))
    motion, fitted = fit_rigid_motion(POINTS, (0, 1), R @ MOTION)
    np.testing.assert_allclose(motion, MOTION, rtol=1e-10)
    r = R @ MOTION
    r[[3, 70]] = np.nan  # missing values are ignored, and stay missing
    motion, fitted = fit_rigid_motion(POINTS, (0, 1), r)
    np.testing.assert_allclose(motion, MOTION, rtol=1e-10)
    assert np.isnan(fitted[[3, 70]]).all() and np.isfinite(np.delete(fitted, [3, 70])).all()


def test_one_component_sees_two_modes():
    u_only = rigid_modes(POINTS, (0,)) @ MOTION
    motion, _ = fit_rigid_motion(POINTS, (0,), u_only)
    np.testing.assert_allclose(motion, [MOTION[0], 0.0, MOTION[2]], rtol=1e-10, atol=1e-15)
    total = with_rigid_motion(Diagonal(np.full(len(POINTS), 1e-6)), POINTS, (0,))
    assert total.U.shape[1] == 2  # t_y moves no u_x: no column
    assert total.quadratic(u_only) < 1e-3


def test_field_block_marginalises_every_frame_on_request():
    n_frames = 3
    deformation = np.stack([_deformation(POINTS).reshape(2, -1).T * k for k in (1, 2, 3)])
    motions = np.outer([0.5, 1.0, 2.0], MOTION)
    u = deformation + np.stack([(rigid_modes(POINTS, (0, 1)) @ m).reshape(2, -1).T for m in motions])
    load = {"cmod_mm": np.array([0.02, 0.04, 0.08])}
    dic = DicData(POINTS, (1, 2, 3), u, None, load)
    plain = field_block(dic, std=1e-3, subset_size=6.0)
    marginal = field_block(dic, std=1e-3, subset_size=6.0, rigid_std=RIGID_STD)
    np.testing.assert_array_equal(plain.data.y, marginal.data.y)  # the data are not changed
    np.testing.assert_allclose(marginal.data.covariance.diag()[: 2 * len(POINTS)] - plain.data.std[: 2 * len(POINTS)] ** 2,
                               np.sum((rigid_modes(POINTS, (0, 1)) * [1, 1, 1 / np.hypot(*POINTS.T).max()]) ** 2, 1),
                               rtol=1e-9)  # + the prior's variance
    model = deformation.transpose(0, 2, 1).reshape(-1)  # what a model with fixed supports computes
    residual = marginal.data.y - model
    assert marginal.data.covariance.quadratic(residual) < 1e-2  # the motions are not misfit
    assert plain.data.covariance.quadratic(residual) > 1e3
    assert any("rigid motion" in note for note in marginal.data.notes)
    with pytest.raises(Exception, match="rigid_std"):
        field_block(dic, std=1e-3, rigid_std=-1.0)
    assert n_frames == len(marginal.frames)


def _hinge(points, phi):
    """Both halves of a beam turning by -+phi about the crack tip (0, 25) mm: the opening of a crack at x = 0,
    mirror-symmetric (u_x odd, u_y even in x) [mm]; (n, 2)."""
    x, y = points.T
    turn = np.where(x >= 0, phi, -phi)  # the right half turns clockwise as the crack opens at the bottom
    return np.column_stack([turn * (y - 25.0), -turn * x])


def test_a_camera_on_both_halves_keeps_the_opening_a_rigid_motion_of_one_half_would_hide():
    """The opening of a crack turns each half of a beam about the crack tip: on one half that is a rigid rotation,
    absorbed by the marginalised rigid motion; on both halves (the mirror images turning the other way) it is not.
    The model computes the other half by symmetry (FieldObservation, tests/test_field_probes.py)."""
    both = np.vstack([POINTS, POINTS * [-1.0, 1.0]])  # the right half and its mirror image
    load = {"cmod_mm": np.array([0.05])}

    def block(points):
        u = (_hinge(points, 2e-4) + (rigid_modes(points, (0, 1)) @ MOTION).reshape(2, -1).T)[None]
        return field_block(DicData(points, (1,), u, None, load), std=1e-3, subset_size=6.0, rigid_std=RIGID_STD)

    half, whole = block(POINTS), block(both)
    # a model that computes no opening: on one half the hinge is a rigid rotation and is absorbed, on both it is not
    assert half.data.covariance.quadratic(half.data.y) < 1.0
    assert whole.data.covariance.quadratic(whole.data.y) > 1e3
    model = _hinge(both, 2e-4).T.reshape(-1)  # a model that computes the opening: the rigid motion alone is left
    assert whole.data.covariance.quadratic(whole.data.y - model) < 1e-2


def test_the_noise_std_leaves_the_rigid_prior_out():
    """diag() is the matrix's (the rigid prior's 1 mm in it); noise_diag() the measurement noise's, through take
    and block stacking; the stability check's relative noise reads the latter."""
    from fracid.data.covariance_matrix import block_diagonal
    from fracid.inverse.studies.stability import relative_noise

    C = _noise_covariance(POINTS)
    total = with_rigid_motion(C, POINTS, (0, 1))
    assert np.all(np.sqrt(total.diag()) > 0.5)  # the prior of the rigid motion, 1 mm
    np.testing.assert_allclose(total.noise_diag(), C.diag(), rtol=1e-12)
    part = block_diagonal([Diagonal(np.full(4, 25.0)), total.take(np.arange(10, 50))])
    np.testing.assert_allclose(part.noise_diag(), np.concatenate([np.full(4, 25.0), C.diag()[10:50]]), rtol=1e-12)
    y = np.concatenate([np.full(4, 1000.0), np.full(40, 0.02)])  # a curve [N] and displacements [mm]
    assert relative_noise(y, part) == pytest.approx(np.sqrt(np.mean(np.r_[np.full(4, 25e-6), C.diag()[10:50] / 4e-4])))
