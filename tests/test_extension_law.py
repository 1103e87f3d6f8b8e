"""A traction-separation law written in this file only, run by the cohesive crack through ``simulate``
and the ``ForwardOperator``, with its exact sensitivities, and no package file edited: the law is an
object with values and derivatives (:class:`fracid.fem.material.tsl.TractionSeparationLaw`), its parameter
class composed of the elastic part and the law's own (:func:`fracid.fem.material.ranges.compose`)."""

from dataclasses import dataclass
from typing import ClassVar

import numpy as np
import pytest
from scipy.integrate import quad

import fracid
from fracid.fem.material.cohesive import CohesiveParameters
from fracid.fem.material.ranges import ELASTIC, compose
from fracid.fem.material.tsl import STRENGTH_AND_ENERGY
from fracid.inverse.core.forward_operator import ForwardOperator, Observation
from fracid.models import CohesiveCrackModel, StepOptions
from fracid.specimens.beam import NotchedBeam

from test_traction_laws import _ddm_case

# ------------------------------------------------------------------------------------------------
# the new law: exponential softening sigma = ft exp(-ft w / Gf), of area Gf, never exactly zero

ExponentialParameters = compose("ExponentialParameters", ELASTIC, STRENGTH_AND_ENERGY,
                                summary="E, nu of the bulk, ft and Gf of the exponential cohesive law.")


@dataclass(frozen=True)
class ExponentialSoftening:
    name: ClassVar[str] = "exponential"
    parameters: ClassVar[type] = ExponentialParameters

    def traction(self, w, p):
        w = np.asarray(w, dtype=float)
        opened = w >= 0.0
        sigma = np.where(opened, p.ft * np.exp(-p.ft * np.maximum(w, 0.0) / p.Gf), 0.0)
        return sigma, np.where(opened, -p.ft / p.Gf * sigma, 0.0)

    def parameter_derivatives(self, w, p) -> dict:
        w = np.maximum(np.asarray(w, dtype=float), 0.0)
        sigma = self.traction(w, p)[0]
        return {"ft": sigma * (1.0 / p.ft - w / p.Gf), "Gf": sigma * p.ft * w / p.Gf**2}

    def strength(self, p):
        return p.ft

    def critical_opening(self, p):
        return np.inf

    def scales(self, p):
        return {"strain": p.ft / p.E, "opening": 5.0 * p.Gf / p.ft}  # sigma = ft exp(-5) there

    def steepest_slope(self, p):
        return p.ft**2 / p.Gf


LAW = ExponentialSoftening()
PARAMS = ExponentialParameters(E=36000.0, ft=3.0, Gf=0.08)
MODEL = CohesiveCrackModel(law=LAW)
BEAM = NotchedBeam(h_fine=4.0, h_coarse=12.0, fine_width=12)


def test_the_law_has_area_gf_and_derivatives_that_match_differences():
    area, _ = quad(lambda w: float(LAW.traction(w, PARAMS)[0]), 0.0, np.inf, epsrel=1e-12)
    assert area == pytest.approx(PARAMS.Gf, rel=1e-10)
    w = np.linspace(0.001, 0.2, 9)
    sigma, slope = LAW.traction(w, PARAMS)
    h = 1e-8
    np.testing.assert_allclose(slope, (LAW.traction(w + h, PARAMS)[0] - LAW.traction(w - h, PARAMS)[0]) / (2 * h),
                               rtol=1e-6)
    for name, exact in LAW.parameter_derivatives(w, PARAMS).items():
        step = 1e-6 * getattr(PARAMS, name)
        plus, minus = (LAW.traction(w, PARAMS.replace(**{name: getattr(PARAMS, name) + s * step}))[0] for s in (1, -1))
        np.testing.assert_allclose(exact, (plus - minus) / (2 * step), rtol=1e-6, err_msg=name)


@pytest.fixture(scope="module")
def beam_run():
    return fracid.simulate(BEAM, PARAMS, model=MODEL, target=0.2, stop_force_fraction=None)


def test_the_new_law_runs_through_simulate(beam_run):
    result = beam_run
    assert MODEL.key == "cohesive-crack-exponential" and MODEL.parameters is ExponentialParameters
    assert result.status == "target reached" and result.control[-1] == pytest.approx(0.2)
    peak = int(np.argmax(result.force))
    assert 0 < peak < result.n_steps - 5 and result.force[-1] < 0.5 * result.force[peak]
    assert np.all(np.diff(result.observables["crack_length"]) >= -1e-9)  # the crack only grows
    # the same beam with Hordijk's law of the same ft, Gf: the same elastic slope, a peak within 15 %
    reference = CohesiveCrackModel().simulate(BEAM, CohesiveParameters(E=36000.0, ft=3.0, Gf=0.08), target=0.2,
                                              stop_force_fraction=None)
    assert result.force[1] / result.control[1] == pytest.approx(reference.force[1] / reference.control[1], rel=1e-6)
    assert result.force.max() == pytest.approx(reference.force.max(), rel=0.15)


@pytest.mark.slow
def test_the_new_law_has_exact_sensitivities_along_the_path():
    force, errors = _ddm_case(LAW, PARAMS)
    peak = int(np.argmax(force))
    assert 2 <= peak < len(force) - 5
    assert max(errors.values()) <= 1e-4, errors


def test_the_forward_operator_runs_the_new_law_with_its_sensitivities(beam_run):
    """The operator's S against central differences of its runs, with steps that do not move with
    the parameters (the default steps jump to the onset, whose control value moves with ft: the
    differences would see the path move, which the derivatives at fixed steps do not)."""
    points = np.linspace(0.02, 0.2, 8)
    steps = StepOptions(initial=0.005, onset_fraction=1.0, max_factor=1.0, jump_to_onset=False)
    op = ForwardOperator([Observation(BEAM, points, control="cmod")], PARAMS, ("ft", "Gf"), model=MODEL, steps=steps)
    assert op.units == {"ft": "MPa", "Gf": "N/mm"}
    exact = op.differentiated()
    assert exact.sensitivities
    x = np.array([PARAMS.ft, PARAMS.Gf])
    record = exact(x)
    assert record.ok and np.all(np.isfinite(record.y)) and record.S.shape == (8, 2)
    cmod = beam_run.observables["cmod"]
    np.testing.assert_allclose(record.y, np.interp(points, cmod, beam_run.force), rtol=0.02)
    for k in range(2):
        step = np.zeros(2)
        step[k] = 1e-6 * x[k]
        fd = (op(x + step).y - op(x - step).y) / (2 * step[k])
        np.testing.assert_allclose(record.S[:, k], fd, atol=1e-5 * np.max(np.abs(fd)))
