"""A new specimen and a new damage law, written in this file only, run through ``simulate``, the
``ForwardOperator`` and ``identify`` with no change to the package: the specimen is a description
(nodes, cells, named node sets), the law an object with values and derivatives."""

from dataclasses import dataclass
from typing import ClassVar

import numpy as np
import pytest

import fracid
from fracid.inverse.core.forward_operator import ForwardOperator, Observation
from fracid.inverse.core.space import ParameterSpace
from fracid.inverse.methods.strategy import identify
from fracid.inverse.studies.twin import synthetic_data
from fracid.fem.material.cohesive import CohesiveParameters
from fracid.fem.material.laws import DamageLaw
from fracid.fem.material.ranges import ParameterRange, ParameterSet
from fracid.models import CohesiveCrackModel, DamageModel
from fracid.specimens.description import CrackPath, Description, Load, Measure, Support, ZoneWidth
from fracid.specimens.meshing import structured_quad8

# ------------------------------------------------------------------------------------------------
# a new law: linear softening of the stress-strain curve, from ft = E kappa_i towards zero at kappa_u,
# until the secant stiffness is down to 1 % (a kink at omega = 1 itself stalls Newton's method)

_R = ParameterRange


@dataclass(frozen=True)
class LinearSofteningParameters(ParameterSet):
    """E [MPa], nu [-], damage threshold kappa_i [-], strain of zero stress kappa_u [-], gradient
    parameter c [mm^2], eta [-] of the modified von Mises strain."""

    E: float = 30000.0
    nu: float = 0.2
    kappa_i: float = 1.0e-4
    kappa_u: float = 2.0e-3
    c: float = 4.0
    eta: float = 10.0

    ranges: ClassVar[dict] = {"E": _R(0.0, False, None, False, "MPa"), "nu": _R(-1.0, False, 0.5, False, "-"),
                              "kappa_i": _R(0.0, False, None, False, "-"), "kappa_u": _R(0.0, False, None, False, "-"),
                              "c": _R(0.0, False, None, False, "mm^2"), "eta": _R(1.0, True, None, False, "-")}

    def __post_init__(self):
        super().__post_init__()
        if not self.kappa_u > self.kappa_i:
            raise ValueError(f"kappa_u = {self.kappa_u} must exceed kappa_i = {self.kappa_i}")


OMEGA_MAX = 0.99  # a broken point keeps a little stiffness: the tangent stays regular


@dataclass(frozen=True)
class LinearSoftening:
    def damage(self, kappa, p):
        kappa = np.asarray(kappa, dtype=float)
        k = np.maximum(kappa, p.kappa_i)
        omega = p.kappa_u * (k - p.kappa_i) / (k * (p.kappa_u - p.kappa_i))
        d_omega = p.kappa_u * p.kappa_i / (k * k * (p.kappa_u - p.kappa_i))
        softening = (kappa > p.kappa_i) & (omega < OMEGA_MAX)
        return np.minimum(np.where(kappa > p.kappa_i, omega, 0.0), OMEGA_MAX), np.where(softening, d_omega, 0.0)

    def kappa_at_damage(self, omega, p):
        return p.kappa_u * p.kappa_i / (p.kappa_u - omega * (p.kappa_u - p.kappa_i))

    def onset(self, p):
        return p.kappa_i


LINEAR = DamageLaw(softening=LinearSoftening(), parameters=LinearSofteningParameters, name="linear")

# ------------------------------------------------------------------------------------------------
# a new specimen: a single-edge-notched tension plate, the upper half (symmetry about the crack plane)


@dataclass(frozen=True)
class EdgeNotchedPlate:
    """Plate W x 2H x t with an edge notch of depth a at mid-height, pulled by rigid grips; the upper
    half y >= 0 is meshed. Controls: ``cmod`` (2 u_y at the notch mouth) and ``grip_displacement``."""

    width: float = 40.0
    half_height: float = 40.0
    thickness: float = 10.0
    notch_depth: float = 8.0
    h: float = 4.0

    default_control: ClassVar[str] = "cmod"

    def describe(self) -> Description:
        ys = np.concatenate([np.arange(0.0, 6.0, self.h / 4), [6.0, 10.0, 16.0, 26.0, self.half_height]])
        mesh = structured_quad8(np.linspace(0.0, self.width, round(self.width / self.h) + 1), ys)
        x, y = mesh.nodes[:, 0], mesh.nodes[:, 1]
        top = np.flatnonzero(np.isclose(y, self.half_height))
        sets = {"ligament": np.flatnonzero(np.isclose(y, 0.0) & (x >= self.notch_depth - 1e-9)),
                "top": top[np.argsort(x[top])], "mouth": np.array([mesh.closest_node((0.0, 0.0))])}
        return Description(
            nodes=mesh.nodes, cells=mesh.cells, n_vertices=mesh.n_vertices, section=self.thickness, node_sets=sets,
            symmetry=(("ligament", 1),), supports=(Support("top", 0),),
            loads=(Load("top", 1, 1.0),),  # the half carries the whole force: lambda = force [N]
            functionals={"cmod": (Measure("mouth", 1, 2.0),), "grip_displacement": (Measure("top", 1, 2.0),)},
            symmetry_factor=2.0, symmetry_planes=((1, 0.0),),
            crack=CrackPath("ligament", normal=1, mirrored=True, element_size=self.h),
            zone=ZoneWidth("fpz_width", axis=1, mirror=True, along_range=(self.notch_depth, self.width)))

    def default_steps(self, target):
        return fracid.StepOptions(maximum=target / 40)

    def default_target(self, scales):
        return 100.0 * scales["strain"] * self.width * 0.25


PLATE = EdgeNotchedPlate()
PARAMS = LinearSofteningParameters()
MODEL = DamageModel("gradient", LINEAR)


def test_linear_softening_derivative_and_inverse():
    kappa = np.linspace(0.5e-4, 1.5e-3, 41)
    omega, d_omega = LINEAR.damage(kappa, PARAMS)
    step = 1e-9
    fd = (LINEAR.damage(kappa + step, PARAMS)[0] - LINEAR.damage(kappa - step, PARAMS)[0]) / (2 * step)
    smooth = (np.abs(kappa - PARAMS.kappa_i) > 2 * step) & (omega < OMEGA_MAX - 1e-6)
    np.testing.assert_allclose(d_omega[smooth], fd[smooth], rtol=1e-6)
    stress = lambda k: PARAMS.E * (1 - LINEAR.damage(k, PARAMS)[0]) * k  # noqa: E731
    assert stress(PARAMS.kappa_i) == pytest.approx(PARAMS.E * PARAMS.kappa_i)  # ft
    assert LINEAR.damage(PARAMS.kappa_u, PARAMS)[0] == OMEGA_MAX  # the linear branch ends in the residual stiffness
    mid = 0.5 * (PARAMS.kappa_i + PARAMS.kappa_u)
    assert PARAMS.E * (1 - LINEAR.damage(mid, PARAMS)[0]) * mid == pytest.approx(0.5 * PARAMS.E * PARAMS.kappa_i)
    assert LINEAR.softening.kappa_at_damage(0.5, PARAMS) == pytest.approx(
        float(np.interp(0.5, omega[kappa >= PARAMS.kappa_i], kappa[kappa >= PARAMS.kappa_i])), rel=0.02)


@pytest.fixture(scope="module")
def plate_run():
    return fracid.simulate(PLATE, PARAMS, model=MODEL, target=0.06, stop_force_fraction=None, damage_threshold=0.9)


def test_new_specimen_and_law_run_through_simulate(plate_run):
    result = plate_run
    assert result.status == "target reached" and result.control[-1] == pytest.approx(0.06)
    peak = int(np.argmax(result.force))
    assert 0 < peak < result.n_steps and result.force[-1] < 0.6 * result.force[peak]
    # before damage (the first steps) the plate is linear elastic: force / CMOD constant
    elastic = result.force[1:3] / result.control[1:3]
    np.testing.assert_allclose(elastic, elastic[0], rtol=1e-6)
    # the zone of damage > 0.9 appears after the peak and grows
    width = result.observables["fpz_width"]
    assert np.all(width[: peak + 1] == 0.0) and 0.0 < width[-1] < 2 * PLATE.half_height
    assert np.all(np.diff(width) >= -1e-9 * width[-1])
    assert set(result.observables) >= {"fpz_width", "grip_displacement"}


def test_the_cohesive_crack_runs_on_the_new_specimen():
    # (the rotating crack band runs too, but locks stress on this eccentric test: the principal
    # directions turn in the band as the crack grows from one side and the force rises again)
    hordijk = CohesiveParameters(E=30000.0, nu=0.2, ft=3.0, Gf=0.08)
    result = CohesiveCrackModel().simulate(PLATE, hordijk, target=0.1, stop_force_fraction=None)
    peak = float(np.max(result.force))
    # the ligament's strength bounds the peak: ft (W - a) t; the notch's stress concentration lowers it
    assert 0.5 < peak / (hordijk.ft * (PLATE.width - PLATE.notch_depth) * PLATE.thickness) < 1.0
    assert result.force[-1] < 0.1 * peak and result.observables["crack_length"][-1] == pytest.approx(
        PLATE.width - PLATE.notch_depth, rel=0.05)  # measured between the outer Gauss points


@pytest.mark.slow
def test_new_specimen_and_law_are_identified_by_the_unchanged_inverse_code(plate_run):
    points = np.linspace(0.005, 0.06, 12)
    op = ForwardOperator([Observation(PLATE, points)], PARAMS, ("kappa_u", "c"), model=MODEL)
    assert op.units == {"kappa_u": "-", "c": "mm^2"} and op.model.key == "gradient-damage-linear"
    # the new law gives no parameter derivatives: its runs are differentiated by central differences
    assert MODEL.differentiable == () and op.differentiated() is op
    truth = np.array([2.0e-3, 4.0])
    data = synthetic_data(op, truth, {"global:relative": 0.01}, seed=None)
    assert data.y.max() == pytest.approx(plate_run.force.max(), rel=0.02)  # the operator runs the same model
    space = ParameterSpace(("kappa_u", "c"), [1.5e-3, 2.0], [4e-3, 8.0])
    result = identify(op, data.y, data.covariance, space, n=12, k=3, groups="all", max_iterations=4)
    np.testing.assert_allclose(result.x, truth, rtol=0.02)
