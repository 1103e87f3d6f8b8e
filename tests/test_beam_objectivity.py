"""Notched beam (Gregoire geometry): mesh objectivity of peak and softening, and its process zone."""

import numpy as np
import pytest
from test_specimens_2d import post_peak_forces

import fracid
from fracid.specimens.beam import NotchedBeam

# internal length sqrt(2 c) = 4.2 mm, resolved by the default 1 mm process-zone elements
pytestmark = pytest.mark.slow  # the fast loop (-m "not slow") leaves this module out

PARAMS = fracid.DamageParameters(E=37000.0, nu=0.2, kappa_i=8.4e-5, alpha=0.99, beta=600.0, c=9.0)


@pytest.fixture(scope="module")
def beam_runs():
    beam = NotchedBeam()
    return [fracid.simulate(b, PARAMS, target=0.6, stop_force_fraction=0.25) for b in (beam, beam.refined(2.0))]


def test_notched_beam_is_mesh_objective(beam_runs):
    default, refined = beam_runs
    assert refined.peak_force == pytest.approx(default.peak_force, rel=0.02)
    f_default, f_refined = post_peak_forces(default, refined)
    np.testing.assert_allclose(f_refined, f_default, rtol=0.02)


def test_beam_fpz_width(beam_runs):
    for result in beam_runs:
        width = result.observables["fpz_width"]
        assert width[1] == 0.0 and width[-1] > width[int(np.argmax(result.force))] > 0.0
    assert beam_runs[1].observables["fpz_width"][-1] == pytest.approx(beam_runs[0].observables["fpz_width"][-1], rel=0.15)
    # a band around the crack (about 30 mm with threshold 0 at 25 % of the peak), not the whole beam
    assert beam_runs[0].observables["fpz_width"][-1] < 0.25 * NotchedBeam().length
