"""Which frames inform: each frame's Fisher information and the greedy ranking with its advice."""

import numpy as np
import pytest

from fracid.data.covariance_matrix import Diagonal, block_diagonal
from fracid.inverse.studies.frame_information import frame_information, rank_frames


def _along(direction, weight):
    d = np.asarray(direction, float)
    return weight * np.outer(d, d)


def test_the_frames_that_separate_two_parameters_come_first_and_are_advised():
    names = ("beta", "c")
    frames = [_along([1.0, 1.0], 100.0),   # sees beta + c only: alone, beta and c fully correlated
              _along([1.0, 1.0], 90.0),    # the same combination again: redundant
              _along([1.0, -1.0], 20.0),   # the other combination: separates them
              _along([1.0, 1.0], 1.0)]     # little
    prior = np.eye(2) * 1e-2
    ranking = rank_frames(frames, names, prior, labels=[f"frame {k}" for k in range(1, 5)])
    assert ranking.order[:2] in ((0, 2), (2, 0))  # the two combinations before the repeats
    assert set(ranking.advised) == {0, 2} and ranking.largest_r[1] <= 0.8
    all_info = prior + sum(frames)
    C = np.linalg.inv(all_info)
    np.testing.assert_allclose(ranking.std[-1], np.sqrt(np.diag(C)), rtol=1e-10)
    r_all = abs(C[0, 1]) / np.sqrt(C[0, 0] * C[1, 1])
    assert ranking.largest_r[-1] == pytest.approx(r_all, rel=1e-10)
    text = "\n".join(ranking.lines())
    assert "frames advised: frame 1, frame 3" in text or "frames advised: frame 3, frame 1" in text
    assert "<= 0.8" in text and "largest |r|" in text


def test_without_a_set_below_the_target_the_advice_is_within_reach_of_all_frames():
    names = ("a", "b")
    frames = [_along([1.0, 0.9], 50.0), _along([1.0, 0.95], 50.0), _along([1.0, 0.92], 1.0)]
    ranking = rank_frames(frames, names, np.eye(2) * 1e-4, target=0.8, within=0.05)
    assert np.all(ranking.largest_r > 0.8)
    n = len(ranking.advised)
    assert ranking.largest_r[n - 1] <= ranking.largest_r[-1] + 0.05
    assert "no set brings |r| to 0.8" in ranking.lines()[-1]


def test_frame_information_is_each_frames_block_of_the_whole():
    rng = np.random.default_rng(0)
    S = rng.standard_normal((12, 3))
    blocks = [np.diag(rng.uniform(0.5, 2.0, 4)) for _ in range(3)]
    C = block_diagonal([Diagonal(np.diag(b)) for b in blocks])
    slices = [slice(0, 4), slice(4, 8), slice(8, 12)]
    info = frame_information(S, C, slices)
    np.testing.assert_allclose(sum(info), S.T @ np.linalg.solve(C.dense(), S), rtol=1e-12)
    np.testing.assert_allclose(info[1], S[4:8].T @ np.linalg.solve(blocks[1], S[4:8]), rtol=1e-12)


def test_no_frame_is_refused():
    with pytest.raises(ValueError, match="at least one frame"):
        rank_frames([], ("a",))


def test_parameters_in_units_many_orders_apart_rank_as_in_common_units():
    frames = [_along([1.0, 1.0], 100.0), _along([1.0, -1.0], 20.0), _along([1.0, 0.5], 5.0)]
    prior = np.eye(2) * 1e-2
    units = np.diag([1e7, 1e-2])  # kappa_i-like against beta-like: the information scales by 1e14 and 1e-4
    scaled = rank_frames([units @ F @ units for F in frames], ("k", "b"), units @ prior @ units)
    plain = rank_frames(frames, ("k", "b"), prior)
    assert scaled.order == plain.order
    np.testing.assert_allclose(scaled.largest_r, plain.largest_r, rtol=1e-8)
    np.testing.assert_allclose(scaled.std * np.diag(units), plain.std, rtol=1e-8)
