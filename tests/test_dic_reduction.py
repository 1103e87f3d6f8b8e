"""Thinning a dense DIC field to a spacing, its covariance the marginal of the full one (issue 27, item 3)."""

import numpy as np
import pytest

from fracid.data import DataError
from fracid.data.dic import DicData, field_block
from fracid.data.dic.reduction import thinned

RNG = np.random.default_rng(3)
POINTS = RNG.uniform([0.0, 0.0], [24.0, 12.0], (300, 2))  # mm, about 1 point per mm^2


def test_one_point_per_occupied_cell_nearest_its_centre():
    mask = thinned(POINTS, 4.0)
    cells = np.floor((POINTS - POINTS.min(axis=0)) / 4.0).astype(int)
    occupied = {tuple(c) for c in cells}
    kept = [tuple(c) for c in cells[mask]]
    assert len(kept) == len(set(kept)) == len(occupied)  # one per occupied cell, every cell served
    centre = (cells + 0.5) * 4.0 + POINTS.min(axis=0)
    distance = np.hypot(*(POINTS - centre).T)
    for cell in list(occupied)[:20]:
        members = np.flatnonzero((cells == cell).all(axis=1))
        assert mask[members[np.argmin(distance[members])]]
    assert thinned(POINTS, 0.01).all()  # finer than the points: nothing dropped
    with pytest.raises(DataError, match="point_spacing = -1"):
        thinned(POINTS, -1.0)


def test_the_thinned_block_is_the_marginal_of_the_full_one():
    u = RNG.normal(0.0, 1e-3, (2, len(POINTS), 2))
    dic = DicData(POINTS, (1, 2), u, None, {"cmod_mm": np.array([0.02, 0.05])})
    full = field_block(dic, std=1e-3, subset_size=6.0)
    thin = field_block(dic, std=1e-3, subset_size=6.0, point_spacing=3.0)
    mask = thinned(POINTS, 3.0)
    np.testing.assert_array_equal(thin.points, POINTS[mask])
    n = len(POINTS)
    index = np.concatenate([f * 2 * n + c * n + np.flatnonzero(mask) for f in range(2) for c in range(2)])
    np.testing.assert_array_equal(thin.data.y, full.data.y[index])
    marginal, own = full.data.covariance.take(index).dense(), thin.data.covariance.dense()
    np.testing.assert_allclose(np.diag(own), np.diag(marginal), rtol=1e-9)
    assert np.linalg.norm(own - marginal) <= 0.05 * np.linalg.norm(marginal)  # the kernel's low-rank tolerance
