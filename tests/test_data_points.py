"""Which control values the data hold: equally spaced with the measured peak kept (default), or the
measured points themselves, decimated by arc length to n_points (the ends and the peak kept)."""

import numpy as np
import pytest

from fracid import datasets
from fracid.data import Curve, DataError, decimate, from_envelope, from_repeats, read_curve_csv, with_std


def softening_curve(n=400, peak_at=0.0237, source="test"):
    """A measured-like curve: a linear rise to a peak between grid points, then exponential softening, with
    a little noise; its peak is a measured point."""
    control = np.linspace(0.0, 0.2, n) + 1e-5
    control[np.argmin(np.abs(control - peak_at))] = peak_at
    force = np.where(control < peak_at, 1000.0 * control / peak_at,
                     1000.0 * np.exp(-(control - peak_at) / 0.04))
    force = force + np.random.default_rng(0).normal(scale=2.0, size=n) * (control > 0.05)
    return Curve(control=control, force=force, source=source)


@pytest.mark.parametrize("sampling", ["equally-spaced", "measured"])
def test_the_data_keep_the_measured_peak_exactly(sampling):
    curve = softening_curve()
    control, peak = curve.peak()
    data = with_std(curve, 5.0, 30, sampling=sampling)
    assert data.n_y == 30 and data.y.max() == peak and data.control[np.argmax(data.y)] == control
    assert np.all(np.diff(data.control) > 0)
    assert data.control[0] == curve.control[0] and data.control[-1] == curve.control[-1]


def test_equally_spaced_points_move_only_the_one_nearest_the_peak():
    curve = softening_curve()
    data = with_std(curve, 5.0, 21)
    grid = np.linspace(curve.control[0], curve.control[-1], 21)
    moved = np.flatnonzero(data.control != grid)
    assert moved.size == 1 and abs(grid[moved[0]] - curve.peak()[0]) <= 0.5 * (grid[1] - grid[0])
    assert any("measured peak" in note and "replaces the nearest" in note for note in data.notes)


def test_measured_points_are_measured_and_decimated_by_arc_length():
    curve = softening_curve()
    data = with_std(curve, 5.0, 25, sampling="measured")
    assert np.all(np.isin(data.control, curve.control))  # no interpolated value
    np.testing.assert_array_equal(data.y, curve.force[np.isin(curve.control, data.control)])
    # arc length: the steep rise (a tenth of the range) gets a fair share of the points, not a tenth
    assert np.sum(data.control < curve.peak()[0]) >= 5
    assert any("25 of the 400 measured points" in note for note in data.notes)
    everything = with_std(curve, 5.0, 1000, sampling="measured")
    assert everything.n_y == 400 and any("all the 400 measured points" in note for note in everything.notes)


def test_decimate_keeps_the_ends_the_point_asked_and_n_points():
    x = np.linspace(0.0, 1.0, 101)
    y = np.sin(3 * x)
    for n, keep in ((5, 50), (10, 1), (100, 99), (3, 0)):
        kept = decimate(x, y, n, keep)
        assert kept.size == n and np.unique(kept).size == n and {0, 100, keep} <= set(kept.tolist())
    np.testing.assert_array_equal(decimate(x[:4], y[:4], 10, 2), np.arange(4))


def test_repeats_and_envelope_keep_the_peak_of_their_mean():
    a = softening_curve(source="a")
    b = Curve(control=a.control[::3] * 1.01, force=0.9 * a.force[::3], source="b")  # other control values
    for sampling in ("equally-spaced", "measured"):
        data = from_repeats([a, b], 20, sampling=sampling, std_floor=0.0)
        knots = np.unique(np.concatenate([a.control, b.control]))
        knots = knots[(knots >= data.control[0]) & (knots <= data.control[-1])]
        mean = 0.5 * (np.interp(knots, a.control, a.force) + np.interp(knots, b.control, b.force))
        assert data.y.max() == pytest.approx(mean.max(), rel=1e-14) and data.n_y == 20
        envelope = from_envelope(a, Curve(control=a.control, force=0.9 * a.force), Curve(control=a.control,
                                 force=1.1 * a.force), 20, sampling=sampling)
        assert envelope.y.max() == a.peak()[1]


def test_the_bundled_test_keeps_its_peak():
    for sampling in ("equally-spaced", "measured"):
        curves = read_curve_csv(datasets.path("gregoire2013-beam4"), control_column="cmod_mm",
                                force_columns=["load_mean_N", "load_min_N", "load_max_N"])
        data = from_envelope(*curves, 40, sampling=sampling)
        assert data.n_y == 40 and data.y.max() == 978.6185 and data.control[np.argmax(data.y)] == 0.01934611


def test_bad_sampling_is_refused():
    curve = softening_curve()
    with pytest.raises(DataError, match="sampling = 'measure'; choose 'equally-spaced' or 'measured'"):
        with_std(curve, 5.0, 20, sampling="measure")
    with pytest.raises(DataError, match="fewer than 2 measured points"):
        with_std(curve, 5.0, 20, (0.10001, 0.10002), sampling="measured")


def test_the_sampling_names_are_imported_from_where_they_are_defined():
    """fracid.data offers the sampling and stacking names of fracid.data.sampling and fracid.data.dataset;
    fracid.data.experimental, where they were before the split, no longer re-exports them (issue 37)."""
    import fracid.data as data
    from fracid.data import dataset, experimental, sampling

    assert sampling.SAMPLINGS is data.SAMPLINGS == ("equally-spaced", "measured")
    assert sampling.decimate is data.decimate and sampling.sample_points is data.sample_points
    assert dataset.stack is data.stack and dataset.ExperimentalData is data.ExperimentalData
    for name in ("SAMPLINGS", "decimate", "sample_points", "stack"):
        assert not hasattr(experimental, name), name
