"""A new observation kind, written in this file only: the crack-opening profile along the ligament of
the notched beam (cohesive crack, symmetric half) at given control values, with its exact
sensitivities, run by the unchanged ForwardOperator and identified by the unchanged inverse code.

The kind is a plain class with the members of ``fracid.inverse.core.observations.ObservationKind``: the
run it needs, the displacement functionals (probes) the run must record (the opening of a node of the
crack line is twice its displacement normal to the line: the half model's symmetry), its size and
control values, the coordinates of its values and ``sample(run) -> (y, S)``, S from the run's
derivatives of the probes (direct differentiation inside the analysis).
"""

from dataclasses import dataclass

import numpy as np
import pytest

from fracid.inverse.core.forward_operator import ForwardOperator, Observation
from fracid.inverse.core.space import ParameterSpace
from fracid.inverse.core.observations import ObservationKind
from fracid.inverse.methods.strategy import identify
from fracid.models import CohesiveCrackModel, StepOptions
from fracid.specimens import SPECIMENS


@dataclass(frozen=True, eq=False)
class CrackOpeningProfile:
    """Crack opening w [mm] at the nodes of the specimen's crack line, at the control values ``frames``
    [mm]: n_frames x n_nodes values, frame by frame, nodes along the line from the notch tip."""

    specimen: object
    frames: tuple
    control: str | None = None
    name: str = "opening"

    def __post_init__(self):
        d = self.specimen.describe()
        crack = d.crack
        nodes = d.nodes_of(crack.nodes)
        along = 1 - crack.normal  # the coordinate along the crack line
        order = np.argsort(d.nodes[nodes, along])
        object.__setattr__(self, "nodes", nodes[order])
        object.__setattr__(self, "position", d.nodes[nodes[order], along])
        object.__setattr__(self, "normal", crack.normal)
        object.__setattr__(self, "frames", np.asarray(self.frames, float))

    # -- what run it needs and what the run records
    @property
    def run_key(self):
        return (hash(self.specimen), self.specimen), self.control, None

    @property
    def observables(self):
        return ()

    def _probe(self, i):
        return f"{self.name}:w[{i}]"

    @property
    def probes(self):
        factor = 2.0 if self.specimen.describe().crack.mirrored else 1.0
        return {self._probe(i): ((int(n), self.normal, factor),) for i, n in enumerate(self.nodes)}

    # -- its values and their coordinates
    @property
    def size(self):
        return self.frames.size * self.nodes.size

    @property
    def controls(self):
        return np.repeat(self.frames, self.nodes.size)

    def coordinates(self):
        return {"control": self.controls, "position": np.tile(self.position, self.frames.size)}

    # read by the inverse code's result fields (fracid.inverse.core.method.observed_fields) until it reads
    # ``controls`` and ``name``: not part of the protocol
    control_points = controls
    quantity = "opening"

    def differentiable_with(self, model):
        return True

    def key(self):
        return {"kind": "crack-opening-profile", "specimen": self.specimen, "frames": self.frames.tolist(),
                "control": self.control}

    def sample(self, run):
        derivatives = run.derivatives or {}
        y, S = [], []
        for i in range(self.nodes.size):
            name = self._probe(i)
            y.append(np.interp(self.frames, run.control, run.observables[name]))
            if name in derivatives:
                S.append(np.column_stack([np.interp(self.frames, run.control, d) for d in derivatives[name].T]))
        y = np.stack(y, axis=1).ravel()  # frame by frame
        return y, (np.stack(S, axis=1).reshape(y.size, -1) if len(S) == self.nodes.size else None)


N_STEPS = 20
NAMES = ("ft", "Gf")
MODEL = CohesiveCrackModel()


@pytest.fixture(scope="module")
def case():
    beam = SPECIMENS["notched-beam"](h_fine=4.0, h_coarse=12.0, fine_width=12)
    params = MODEL.parameters()
    target = 0.5 * MODEL.default_target(beam, params)
    steps = StepOptions(initial=target / N_STEPS, onset_fraction=1.0, max_factor=1.0, jump_to_onset=False)
    control = np.linspace(0.0, target, N_STEPS + 1)[1:]
    profile = CrackOpeningProfile(beam, control[[7, 13, 19]])
    operator = ForwardOperator([Observation(beam, control), profile], params, NAMES, model=MODEL, steps=steps)
    x = np.array([getattr(params, n) for n in NAMES])
    return operator, x, operator.differentiated()(x)


def test_the_profile_is_an_observation_kind_the_operator_runs(case):
    operator, x, record = case
    profile = operator.observations[1]
    assert isinstance(profile, ObservationKind) and operator.differentiable
    assert record.ok and record.S is not None
    w = record.y[operator.slices()[1]].reshape(3, -1)  # frames x nodes, from the notch tip up
    notch_tip = profile.position[0]
    assert notch_tip == pytest.approx(profile.specimen.notch_depth)
    # the crack opens from the notch tip: the largest opening there, growing with the control
    assert np.all(np.argmax(w, axis=1) == 0) and np.all(np.diff(w[:, 0]) > 0)
    assert w[-1, 0] > 1e-3 and np.all(w >= -1e-3 * w.max())  # the penalty: ahead of the tip |w| is small
    # CMOD (the control, at the mouth below the notch) exceeds the opening at the notch tip
    assert np.all(w[:, 0] < profile.frames)
    np.testing.assert_array_equal(profile.coordinates()["control"], profile.controls)


def test_the_profile_sensitivities_match_central_differences(case):
    operator, x, record = case
    block = operator.slices()[1]
    for j in range(len(NAMES)):
        h = 1e-6 * x[j]
        plus, minus = (operator(x + sign * h * np.eye(len(x))[j]) for sign in (1.0, -1.0))
        assert plus.ok and minus.ok
        difference = (plus.y[block] - minus.y[block]) / (2 * h)
        scale = np.abs(difference).max()
        assert scale > 0
        np.testing.assert_allclose(record.S[block, j], difference, rtol=0, atol=1e-4 * scale)


@pytest.mark.slow
def test_the_profile_identifies_on_a_twin(case):
    operator, x, _ = case
    profile_only = ForwardOperator(operator.observations[1:], operator.base, NAMES, model=MODEL, steps=operator.steps)
    truth = x * np.array([1.1, 0.9])
    y = profile_only(truth).y  # the twin's data, without noise; std 1 % of the largest opening
    covariance = np.diag(np.full(y.size, (0.01 * np.abs(y).max()) ** 2))
    space = ParameterSpace(NAMES, x * 0.7, x * 1.4)
    result = identify(profile_only, y, covariance, space, n=8, k=3, groups="all", max_iterations=4)
    np.testing.assert_allclose(result.x, truth, rtol=0.02)
