"""The inverse code depends only on the model interface of fracid.models: a new model, written here
without touching fracid.inverse, is identified by the same KNN + Kalman filter and study."""

from dataclasses import dataclass, fields, replace
from types import SimpleNamespace
from typing import ClassVar

import numpy as np
import pytest

import fracid
from fracid.inverse.core.forward_operator import ForwardOperator, Observation
from fracid.inverse.core.space import ParameterSpace
from fracid.inverse.methods.strategy import identify
from fracid.inverse.studies.study import StudySettings, run_study
from fracid.inverse.studies.twin import synthetic_data
from fracid.models import DamageModel, parameter_units


@dataclass(frozen=True)
class SofteningBarParameters:
    """E [MPa], tensile strength ft [MPa], fracture energy Gf [N/mm] of a bar with one cohesive crack."""

    E: float = 30000.0
    ft: float = 3.0
    Gf: float = 0.1

    def __post_init__(self):
        for f in fields(self):
            if not getattr(self, f.name) > 0:
                raise ValueError(f"{f.name} = {getattr(self, f.name)!r} must be > 0")

    @classmethod
    def names(cls):
        return tuple(f.name for f in fields(cls))

    @classmethod
    def units(cls):
        return {"E": "MPa", "ft": "MPa", "Gf": "N/mm"}

    @classmethod
    def valid_bounds(cls, names):
        return np.full(len(names), 1e-12), np.full(len(names), np.inf)

    def replace(self, **changes):
        return replace(self, **changes)


@dataclass(frozen=True)
class Bar:
    length: float = 100.0
    area: float = 100.0


@dataclass(frozen=True)
class LinearCohesiveBar:
    """Closed-form bar: elastic up to ft, then a crack with linear softening, w_c = 2 Gf / ft."""

    key: ClassVar[str] = "test-linear-cohesive-bar"
    parameters: ClassVar[type] = SofteningBarParameters

    def simulate(self, specimen, p, *, target=None, checkpoints=None, **ignored):
        u = np.union1d(np.linspace(0.0, target, 50), [] if checkpoints is None else checkpoints)
        wc = 2.0 * p.Gf / p.ft
        elastic = p.E * u / specimen.length
        softening = (u - wc) / (specimen.length / p.E - wc / p.ft)  # sigma on the softening branch
        sigma = np.where(elastic <= p.ft, elastic, np.clip(softening, 0.0, None))
        width = np.where(elastic > p.ft, (p.ft - sigma) * wc / p.ft, 0.0)  # crack opening [mm]
        return SimpleNamespace(control=u, force=sigma * specimen.area, observables={"opening": width})


TRUTH = np.array([3.0, 0.1])
POINTS = np.linspace(0.002, 0.06, 20)


def test_a_new_model_is_identified_by_the_unchanged_inverse_code():
    op = ForwardOperator([Observation(Bar(), POINTS)], SofteningBarParameters(), ("ft", "Gf"),
                         model=LinearCohesiveBar())
    assert op.units == {"ft": "MPa", "Gf": "N/mm"} and op.model.key == "test-linear-cohesive-bar"
    data = synthetic_data(op, TRUTH, {"global:relative": 0.01}, seed=None)
    space = ParameterSpace(("ft", "Gf"), [1.0, 0.02], [6.0, 0.4])
    result = identify(op, data.y, data.covariance, space, n=32, k=4, groups=[np.arange(20)])
    np.testing.assert_allclose(result.x, TRUTH, rtol=0.01)
    assert "N/mm" in result.summary()
    study = run_study(op, data, space, StudySettings().replace(n=32, k=4, groups="all", starts=0, replicates=0))
    assert study.verdict["ft"].status == "identified" and study.verdict["Gf"].status == "identified"


def test_operator_rejects_parameters_of_another_model():
    with pytest.raises(TypeError, match="takes SofteningBarParameters"):
        ForwardOperator([Observation(Bar(), POINTS)], fracid.DamageParameters(), ("ft",), model=LinearCohesiveBar())
    with pytest.raises(ValueError, match="not among"):
        ForwardOperator([Observation(Bar(), POINTS)], SofteningBarParameters(), ("c",), model=LinearCohesiveBar())


def test_damage_model_is_the_default_and_keys_differ_between_models():
    from fracid.inverse.core.runs import run_key

    bar = fracid.BarWithWeakZone(n_elements=40)
    gradient = ForwardOperator([Observation(bar, POINTS)], fracid.DamageParameters(), ("c",))
    local = ForwardOperator([Observation(bar, POINTS)], fracid.DamageParameters(), ("c",), model=DamageModel("local"))
    assert gradient.model == DamageModel("gradient") and parameter_units(gradient.model)["c"] == "mm^2"
    assert run_key(gradient, np.array([2.0])) != run_key(local, np.array([2.0]))
    with pytest.raises(ValueError, match="'nonlocal'"):
        DamageModel("nonlocal")


@dataclass(frozen=True)
class FailingBar(LinearCohesiveBar):
    """Converges only while Gf >= 0.09 N/mm: the Kalman filter's estimate runs may fail."""

    key: ClassVar[str] = "test-failing-bar"

    def simulate(self, specimen, p, **options):
        from fracid.fem.path.path_following import ConvergenceError

        result = super().simulate(specimen, p, **options)
        if p.Gf < 0.09:
            raise ConvergenceError("no convergence (test model)", SimpleNamespace(control=result.control[:3],
                                   force=result.force[:3], observables={}, n_steps=3))
        return result


def test_model_comparison_records_a_failed_fit_and_keeps_the_others():
    from fracid.inverse.studies.cross_model import compare_models
    from fracid.inverse.studies.model_fit import Candidate

    op = ForwardOperator([Observation(Bar(), POINTS)], SofteningBarParameters(), ("ft", "Gf"), model=LinearCohesiveBar())
    data = synthetic_data(op, [3.0, 0.05], {"global:relative": 0.01}, seed=None)
    space = ParameterSpace(("ft", "Gf"), [1.0, 0.02], [6.0, 0.4])
    candidates = [Candidate("failing", FailingBar(), SofteningBarParameters(), ("ft", "Gf"), space),
                  Candidate("closed form", LinearCohesiveBar(), SofteningBarParameters(), ("ft", "Gf"), space)]
    comparison = compare_models(data, Bar(), candidates, control="end", n=32, k=4, groups=[np.arange(20)])
    assert [fit.label for fit in comparison.fits] == ["failing", "closed form"] and not comparison.failures
    failing = comparison.fit("failing")
    # the filter's steps towards the truth (Gf 0.05) fail; it backtracks, records them and ends where runs succeed
    assert failing.identification.runs["kalman_failed"] > 0 and failing.x[1] >= 0.09
    assert failing.row()["status"] == failing.identification.status
    np.testing.assert_allclose(comparison.fit("closed form").x, [3.0, 0.05], rtol=0.01)
