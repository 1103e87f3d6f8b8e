"""Mesh defaults that scale with the specimen: resolved values, today's mesh of the default specimens, run
keys, and the size of a long beam's default mesh against a hand-tuned one (counted, not built)."""

from dataclasses import replace

import pytest

from fracid.specimens import DogBone, NotchedBeam, WedgeSplitting
from fracid.store.runs import key_for

LONG = dict(depth=100.0, span=800.0, length=900.0, notch_depth=50.0, plate_width=10.0)  # benchmarks/mesh_defaults.py


def _similar_beam(factor: float, **fields) -> NotchedBeam:
    """The default beam with every dimension times ``factor`` (the element sizes left to their defaults)."""
    base = NotchedBeam()
    names = ("depth", "thickness", "length", "span", "notch_depth", "notch_width", "plate_width")
    return NotchedBeam(**{name: factor * getattr(base, name) for name in names}, **fields)


def test_the_default_specimens_keep_their_mesh_and_run_key():
    beam, wedge = NotchedBeam(), WedgeSplitting()
    assert (beam.h_coarse, beam.fine_width) == (4.0, 10.0)
    assert wedge.h_coarse == 25.0
    assert (DogBone()._h_coarse, DogBone()._fine_height) == (10.0, 15.0)
    # the fields hold the numbers the defaults used to be: same specimen, same key
    assert beam == NotchedBeam(h_coarse=4.0, fine_width=10.0) and wedge == WedgeSplitting(h_coarse=25.0)
    assert key_for(specimen=beam) == key_for(specimen=NotchedBeam(h_coarse=4.0, fine_width=10.0))
    assert key_for(specimen=wedge) == key_for(specimen=WedgeSplitting(h_coarse=25.0))
    assert beam.mesh_size() == NotchedBeam(h_coarse=4.0, fine_width=10.0).mesh_size()


def test_the_beam_defaults_scale_with_the_depth():
    twice = _similar_beam(2.0)
    assert (twice.h_coarse, twice.fine_width) == pytest.approx((8.0, 20.0))
    deep = NotchedBeam(**LONG)
    assert (deep.h_coarse, deep.fine_width) == pytest.approx((8.0, 20.0))


def test_the_beam_defaults_are_clipped():
    small = _similar_beam(0.4, h_fine=2.0)  # D = 20: D / 12.5 = 1.6 < h_fine
    assert small.h_coarse == 2.0
    assert small.fine_width == pytest.approx(max(0.2 * 20.0, small.notch_width / 2 + 4.0))  # the band holds 2 h_fine
    short = NotchedBeam(span=45.0, length=60.0)  # the band may not reach the support: (S - plate) / 4
    assert short.fine_width == pytest.approx((45.0 - 5.0) / 4)


def test_given_values_are_kept_and_checked():
    beam = NotchedBeam(h_coarse=7.0, fine_width=12.0, **LONG)
    assert (beam.h_coarse, beam.fine_width) == (7.0, 12.0)
    with pytest.raises(ValueError, match="h_coarse"):
        NotchedBeam(h_coarse=-1.0)
    with pytest.raises(ValueError, match="h_coarse"):
        WedgeSplitting(h_coarse=0.0)


def test_replace_keeps_the_resolved_values_a_new_specimen_derives_them():
    assert replace(NotchedBeam(), depth=60.0).h_coarse == 4.0
    assert NotchedBeam(depth=60.0).h_coarse == pytest.approx(4.8)


def test_the_wedge_and_the_dogbone_scale_with_their_size():
    base = WedgeSplitting()
    twice = WedgeSplitting(**{name: 2.0 * getattr(base, name) for name in (
        "width", "height", "groove_width", "groove_depth", "notch_depth", "notch_width", "load_height", "load_piece")})
    assert twice.h_coarse == 50.0
    assert WedgeSplitting(width=400.0).h_coarse == 25.0  # the smaller of width and height
    assert WedgeSplitting(h_fine=30.0).h_coarse == 30.0  # at least h_fine
    assert DogBone(size=200.0)._h_coarse == 20.0 and DogBone(size=50.0, h_fine=8.0)._h_coarse == 8.0


def test_the_long_beam_default_mesh_is_near_a_hand_tuned_one():
    """The beam of benchmarks/mesh_defaults.py: its default mesh has at most 1.6 times the nodes of the
    hand-tuned h_coarse = 20 mm (1.43 when written), the former fixed defaults (4 and 10 mm) over 2 times."""
    default = NotchedBeam(**LONG)
    tuned = NotchedBeam(h_coarse=20.0, fine_width=default.fine_width, **LONG)
    former = NotchedBeam(h_coarse=4.0, fine_width=10.0, **LONG)
    nodes = {name: beam.mesh_size()[1] for name, beam in (("default", default), ("tuned", tuned), ("former", former))}
    assert nodes["default"] < 1.6 * nodes["tuned"]
    assert nodes["former"] > 2.0 * nodes["tuned"]
