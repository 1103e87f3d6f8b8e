"""FPZ width across the crack path: accuracy on an analytic field and continuity in the field."""

import numpy as np
import pytest

from fracid.fem.formulations.fpz import across_sampler, fpz_width


def _points(h=2.0):
    # jittered structured points on the half x >= 0 of a band along y (path: the line x = 0)
    rng = np.random.default_rng(0)
    x, y = np.meshgrid(np.arange(h / 4, 40.0, h / 2), np.arange(0.0, 50.0, h / 2))
    pts = np.column_stack([x.ravel(), y.ravel()])
    return pts + rng.uniform(-0.1, 0.1, pts.shape) * h


def _kappa(points, w):
    # damage zone of half-width w * sqrt(ln 2) at kappa = 1, widest at mid-height y = 25
    taper = 1.0 - ((points[:, 1] - 25.0) / 40.0) ** 2
    return 2.0 * taper * np.exp(-((points[:, 0] / w) ** 2))


@pytest.mark.slow
def test_width_matches_the_analytic_level_set_and_varies_smoothly():
    pts = _points()
    sampler = across_sampler(pts, axis=0, along_range=(0.0, 50.0), lines=101)
    widths = []
    for w in np.linspace(6.0, 6.3, 7):
        width = fpz_width(sampler, _kappa(pts, w), 1.0, mirror=True)
        assert width == pytest.approx(2 * w * np.sqrt(np.log(2.0)), rel=0.01)
        widths.append(width)
    # no staircase of the point spacing (h = 2 mm): equal increments of w give nearly equal increments
    steps = np.diff(widths)
    assert np.all(steps > 0) and steps.max() < 1.5 * steps.min()


def test_no_damage_gives_zero_width_and_a_half_model_is_doubled():
    pts = _points()
    sampler = across_sampler(pts, axis=0)
    assert fpz_width(sampler, _kappa(pts, 6.0), 5.0, mirror=True) == 0.0
    half = fpz_width(sampler, _kappa(pts, 6.0), 1.0, mirror=False)
    assert fpz_width(sampler, _kappa(pts, 6.0), 1.0, mirror=True) == pytest.approx(2 * half)


def test_superlevel_length_of_many_lines_at_once_equals_line_by_line():
    from fracid.fem.mesh.level_sets import superlevel_length

    x = np.linspace(0.0, 10.0, 41)
    lines = np.sin(x[None, :] + np.arange(5)[:, None]) + 0.2
    together = superlevel_length(x, lines, 0.5, -1.0, 12.0)
    assert together.shape == (5,)
    np.testing.assert_allclose(together, [superlevel_length(x, line, 0.5, -1.0, 12.0) for line in lines])


def test_observers_are_attached_only_when_asked_for():
    import fracid

    bar, params = fracid.BarWithWeakZone(n_elements=20), fracid.DamageParameters()
    everything = fracid.simulate(bar, params, target=0.005, stop_force_fraction=None)
    nothing = fracid.simulate(bar, params, target=0.005, stop_force_fraction=None, observables=())
    assert "damaged_zone_width" in everything.observables and "damaged_zone_width" not in nothing.observables
    np.testing.assert_array_equal(everything.force, nothing.force)
