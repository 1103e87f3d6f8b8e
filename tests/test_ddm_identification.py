"""Identification with exact sensitivities: the forward operator returns S with its run, the run store keeps it,
the Kalman filter uses it by default (one run per linearisation) and Gauss-Newton reaches the same MAP point."""

import numpy as np
import pytest

import fracid
from fracid.inverse.core.forward_operator import ForwardOperator, Observation
from fracid.inverse.core.space import ParameterSpace
from fracid.inverse.core.runs import StoredOperator
from fracid.inverse.core.sensitivity import (CentralDifferences, DirectDifferentiation, exact_sensitivity,
                                        sensitivity_label)
from fracid.models import CohesiveCrackModel
from fracid.specimens import SPECIMENS
from fracid.store.runs import RunStore

BAR = fracid.BarWithWeakZone(n_elements=100)
POINTS = np.linspace(0.004, 0.03, 16)  # end displacement [mm]: pre-peak, peak and softening
TRUTH = np.array([2.0, 250.0])  # c [mm^2], beta [-]
SPACE = ParameterSpace(("c", "beta"), [0.5, 100.0], [4.0, 500.0])


@pytest.fixture(scope="module")
def operator():
    return ForwardOperator([Observation(BAR, POINTS)], fracid.DamageParameters(), ("c", "beta"))


def test_the_differentiated_operator_returns_S_and_the_store_keeps_it(operator, tmp_path):
    exact = operator.differentiated()
    assert exact.sensitivities and not operator.sensitivities and exact.differentiable
    record = exact(TRUTH)
    assert record.ok and record.S.shape == (POINTS.size, 2)
    # the same steps; the Newton iterates differ within the tolerance (the derivatives hand a factorization
    # of the converged tangent on to the next step, where the plain run keeps an older one)
    np.testing.assert_allclose(record.y, operator(TRUTH).y, rtol=1e-8)
    # S against central differences of the adaptive runs: d/d beta does not move the steps, and agrees
    # to 1e-6 at a relative step of 1e-3 (at 1e-2 the differences' truncation error is 8e-4, at 1e-4
    # the runs' convergence to the Newton tolerance, 1e-9, divided by the step: 9e-6); c moves the
    # onset and with it the steps, which the differences also see (0.2 % at the package's step 1e-2,
    # more at smaller steps: DDM differentiates the model, not the step rule)
    def deviation(step):
        _, S_cd, _ = CentralDifferences(relative_step=step)(operator, TRUTH)
        return np.abs(S_cd - record.S).max(axis=0) / np.abs(S_cd).max(axis=0)

    assert deviation(1e-3)[1] < 2e-6 and deviation(1e-2)[0] < 5e-3
    with RunStore(tmp_path / "runs.sqlite") as store:
        first = StoredOperator(operator, store).differentiated()
        assert first.operator.sensitivities
        stored = first(TRUTH)
        again = StoredOperator(operator, store).differentiated()
        reloaded = again(TRUTH)
        assert again.computed == 0 and again.reused == 1
        np.testing.assert_array_equal(reloaded.S, stored.S)
        plain = StoredOperator(operator, store)  # runs without S have keys of their own
        assert plain(TRUTH).S is None and plain.computed == 1


def test_exact_sensitivity_picks_ddm_where_the_model_has_it(operator):
    evaluate, sensitivity = exact_sensitivity(operator)
    assert isinstance(sensitivity, DirectDifferentiation) and evaluate.sensitivities
    assert sensitivity_label(sensitivity).startswith("direct differentiation")
    y, S, records = sensitivity(evaluate, TRUTH)
    assert len(records) == 1 and S.shape == (POINTS.size, 2)
    # an analytic model without S: central differences
    evaluate, sensitivity = exact_sensitivity(lambda x, needed=None: np.array([x[0] ** 2, x[1]]))
    assert isinstance(sensitivity, CentralDifferences)
    # the damage models differentiate their zone widths; the crack models' crack length is a staircase
    width = ForwardOperator([Observation(fracid.BarWithWeakZone(n_elements=40), POINTS, "damaged_zone_width")],
                            fracid.DamageParameters(), ("c",))
    assert width.differentiable and width.differentiated().sensitivities
    model = CohesiveCrackModel()
    beam = SPECIMENS["notched-beam"](h_fine=4.0, h_coarse=12.0)
    crack = ForwardOperator([Observation(beam, np.linspace(0.01, 0.1, 5), "crack_length")], model.parameters(),
                            ("ft",), model=model)
    force = ForwardOperator([Observation(beam, np.linspace(0.01, 0.1, 5))], model.parameters(), ("ft",), model=model)
    assert not crack.differentiable and crack.differentiated() is crack and force.differentiable


class _WithoutDerivatives:
    """A forward model that does not say what it differentiates (a user's model): no DDM."""

    def __init__(self, model):
        self.model = model
        self.key, self.parameters = model.key, model.parameters

    def simulate(self, specimen, params, **options):
        return self.model.simulate(specimen, params, **options)


def test_models_without_ddm_keep_central_differences(operator):
    model = _WithoutDerivatives(operator.model)
    op = ForwardOperator([Observation(BAR, POINTS)], fracid.DamageParameters(), ("c",), model=model)
    assert not op.differentiable and op.differentiated() is op
    evaluate, sensitivity = exact_sensitivity(op)
    assert evaluate is op and isinstance(sensitivity, CentralDifferences)
