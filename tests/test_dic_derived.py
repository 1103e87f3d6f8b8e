"""Local data derived from a DIC field (fracid issue 27): the crack-opening profile by virtual extensometers and the
process-zone width from the strain, data side (:mod:`fracid.data.dic.derived`) and model side
(:mod:`fracid.inverse.core.derived_observations`).

The twin: the demo beam on a coarse mesh (h_fine 4 mm, the half x >= 0, the crack on x = 0 from the notch tip
y = 25 mm to the top), gradient damage at the demo's estimate, a synthetic DIC field without noise on a 3 mm
grid (~480 points, holes within 3 mm of the lower ligament), 3 frames (CMOD 0.03, 0.08, 0.14 mm). One forward
run at the truth samples every kind (module fixture, ~3 s).
"""

import dataclasses

import numpy as np
import pytest

from fracid.data.dic import DicData, field_block, frame_rigid_motions, opening_profile, process_zone_width
from fracid.specimens.crack_line import crack_line
from fracid.data.errors import DataError
from fracid.fem.material.parameters import DamageParameters
from fracid.fem.path.path_following import StepOptions
from fracid.models.forward import simulate
from fracid.inverse.core.derived_observations import DerivedFieldObservation, derived_observation
from fracid.inverse.core.forward_operator import ForwardOperator
from fracid.inverse.core.field_observations import FieldObservation, field_observation
from fracid.inverse.core.observations import ObservationKind
from fracid.inverse.core.sensitivity import CentralDifferences
from fracid.inverse.studies.dic_twin import rigid_motion, synthetic_dic
from fracid.models import probe_matrix
from fracid.specimens.beam import NotchedBeam

BEAM = NotchedBeam(h_fine=4.0, h_coarse=10.0)
BASE = DamageParameters(E=36250.0, nu=0.2, kappa_i=6.6e-5, alpha=0.99, beta=600.0, c=9.0, eta=10.0)
NAMES = ("kappa_i", "beta", "c")
TRUTH = np.array([4.798e-5, 1086.5, 21.46])  # the demo's estimate
FRAMES = np.array([0.03, 0.08, 0.14])  # CMOD [mm], multiples of the fixed step of the difference test
HEIGHTS = [27.5, 32.0, 37.0, 42.0]  # gauges along the ligament [mm]
GAUGE, RADIUS = 6.0, 5.0  # gauge half-length and plane-fit radius [mm] (grid 3 mm, holes within 3 mm)
WIDTH = dict(heights=[28.0, 33.0], offsets=np.arange(5.0, 26.0, 2.0), radius=4.5, threshold=1.5e-4)
RIGID = (0.004, -0.012, 5e-5)  # t_x, t_y [mm], theta [rad]: the example data set's settling
STD, SUBSET = 1e-3, 6.0  # DIC noise [mm], subset [mm]


def truth_params():
    return dataclasses.replace(BASE, **dict(zip(NAMES, map(float, TRUTH))))


def as_dic(points, u) -> DicData:
    return DicData(points, (1, 2, 3), u, load={"cmod_mm": FRAMES})


@pytest.fixture(scope="module")
def twin():
    return synthetic_dic(BEAM, truth_params(), frames=FRAMES, spacing=3.0, std=0.0, subset_size=SUBSET, holes=3.0,
                         seed=3)


@pytest.fixture(scope="module")
def field(twin):
    """The half face, no rigid motion, correlated noise covariance (the values themselves exact)."""
    return field_block(as_dic(twin.points, twin.U), std=STD, subset_size=SUBSET)


@pytest.fixture(scope="module")
def whole_face(twin):
    """Both halves (the mirror image: u_x changes sign), with the rigid motion RIGID; independent errors."""
    line = crack_line(BEAM)
    other = line.offsets(twin.points) > 1.0  # not the points on the line itself
    points = np.vstack([twin.points, line.mirror(twin.points[other])])
    mirrored = twin.U[:, other] * np.array([-1.0, 1.0])
    u = np.concatenate([twin.U, mirrored], axis=1) + rigid_motion(points, *RIGID)[None]
    return field_block(as_dic(points, u), std=STD)


@pytest.fixture(scope="module")
def blocks(field, whole_face):
    return {"opening": opening_profile(field, BEAM, HEIGHTS, GAUGE, radius=RADIUS),
            "width": process_zone_width(field, BEAM, **WIDTH),
            "pairs": opening_profile(whole_face, BEAM, HEIGHTS, GAUGE, radius=RADIUS, name="pairs")}


@pytest.fixture(scope="module")
def at_truth(blocks, field):
    """One run at the truth: the three derived kinds and the half field."""
    kinds = [derived_observation(blocks[name], BEAM, control="cmod") for name in ("opening", "width", "pairs")]
    operator = ForwardOperator([*kinds, field_observation(field, BEAM, control="cmod")], BASE, NAMES)
    record = operator(TRUTH)
    assert record.ok
    return {name: record.y[part] for name, part in zip(("opening", "width", "pairs", "field"), operator.slices())}


def test_the_kinds_are_observation_kinds(blocks):
    kind = derived_observation(blocks["opening"], BEAM, control="cmod")
    assert isinstance(kind, ObservationKind) and isinstance(kind, DerivedFieldObservation)
    assert kind.size == FRAMES.size * len(HEIGHTS) == blocks["opening"].data.n_y
    np.testing.assert_array_equal(kind.controls, blocks["opening"].data.control)
    coordinates = kind.coordinates()
    np.testing.assert_array_equal(coordinates["height"], np.tile(HEIGHTS, FRAMES.size))
    np.testing.assert_array_equal(coordinates["frame"], np.repeat(np.arange(FRAMES.size), len(HEIGHTS)))
    assert kind.probe_matrix().shape[0] == len(blocks["opening"].points)  # u_x at the points
    assert kind.key()["estimator"] == "extensometers" and blocks["opening"].data.blocks == (("opening", 0, 12),)


def test_the_crack_line_of_the_demo_beam():
    line = crack_line(BEAM)
    assert (line.normal, line.position, line.side, line.extent, line.mirrored) == (0, 0.0, 1.0, (25.0, 50.0), True)
    np.testing.assert_array_equal(line.place([6.0], [30.0]), [[6.0, 30.0]])


def test_data_side_opening_equals_model_side_at_the_truth(blocks, at_truth):
    """Noise-free data, the same estimator on both sides: equal to round-off; the profile opens from the notch
    tip (largest at the lowest gauge, decreasing up the ligament, growing with the CMOD)."""
    for name in ("opening", "width"):
        y = blocks[name].data.y
        np.testing.assert_allclose(at_truth[name], y, rtol=0, atol=1e-9 * np.abs(y).max())
    w = blocks["opening"].data.y.reshape(FRAMES.size, -1)
    assert np.all(np.diff(w, axis=1) < 0) and np.all(np.diff(w, axis=0) > 0) and w[0, 0] > 0
    assert np.all(w[:, 0] < FRAMES)  # the CMOD (below the notch) exceeds the opening above the notch tip
    width = blocks["width"].data.y
    assert np.all((width > 5.0) & (width < WIDTH["offsets"][-1] * 2 * np.sqrt(3)))


def test_opening_equals_the_meshs_gauge_within_the_estimators_error(blocks):
    """The plane fit (5 mm radius, ~8 points) against the mesh's own 2 u_x at the gauge end: measured
    deviations up to 1.7 % of the frame's largest opening (the field's curvature near the crack)."""
    run = simulate(BEAM, truth_params(), target=FRAMES[-1], checkpoints=FRAMES, field_steps="all")
    d = BEAM.describe()
    P = probe_matrix(d.nodes, d.cells, crack_line(BEAM).place(GAUGE, HEIGHTS))
    w = blocks["opening"].data.y.reshape(FRAMES.size, -1)
    for k, frame in enumerate(FRAMES):
        step = int(np.argmin(np.abs(run.control - frame)))
        mesh = 2.0 * (P @ np.asarray(run.fields[step]["u"]).reshape(-1, 2))[:, 0]
        np.testing.assert_allclose(w[k], mesh, rtol=0, atol=0.03 * mesh.max())


def test_pairs_on_both_halves_remove_the_rigid_motion(twin, blocks, at_truth):
    """Data on the whole face with a rigid motion: the pair differences equal the half's profile without it;
    the model side (the other half's points mirrored) equals the data."""
    assert blocks["pairs"].estimator.pairs and not blocks["opening"].estimator.pairs
    half = blocks["opening"].data.y
    np.testing.assert_allclose(blocks["pairs"].data.y, half, rtol=0, atol=1e-6 * half.max())
    np.testing.assert_allclose(at_truth["pairs"], blocks["pairs"].data.y, rtol=0, atol=1e-6 * half.max())
    # independent errors: the half doubles one end (4 var), the pair adds two (2 var): half the variance, up to
    # the points' different positions in the windows
    half_diagonal = opening_profile(field_block(as_dic(twin.points, twin.U), std=STD), BEAM, HEIGHTS, GAUGE,
                                    radius=RADIUS)
    ratio = blocks["pairs"].data.covariance.diag() / half_diagonal.data.covariance.diag()
    assert np.all((ratio > 0.3) & (ratio < 0.8)), ratio


def test_rigid_motion_on_a_half_is_twice_its_normal_displacement_and_is_subtracted(twin, blocks, at_truth):
    field = field_block(as_dic(twin.points, twin.U + rigid_motion(twin.points, *RIGID)[None]), std=STD)
    moved = opening_profile(field, BEAM, HEIGHTS, GAUGE, radius=RADIUS)
    t_x, _, theta = RIGID
    bias = np.tile(2.0 * (t_x - theta * np.asarray(HEIGHTS)), FRAMES.size)  # 2 u_x of the motion at the gauge
    np.testing.assert_allclose(moved.data.y - blocks["opening"].data.y, bias, rtol=1e-3, atol=1e-8)
    motions = frame_rigid_motions(field, at_truth["field"])  # fitted on the residual to the model's field
    np.testing.assert_allclose(motions, np.tile(RIGID, (FRAMES.size, 1)), rtol=1e-4, atol=1e-9)
    # the twin's rotation is exact, (R(theta) - I) x, the modes linear: they differ by theta^2 / 2 x, ~1e-7 mm
    for motion in (RIGID, motions):
        back = opening_profile(field, BEAM, HEIGHTS, GAUGE, radius=RADIUS, rigid_motion=motion)
        np.testing.assert_allclose(back.data.y, blocks["opening"].data.y, rtol=0, atol=5e-6 * at_truth["opening"].max())
    assert any("rigid motion subtracted" in note for note in back.data.notes)


def test_the_opening_covariance_is_w_c_wt_monte_carlo(field, blocks):
    """Draws of the field noise C.color(z) through the data side: the derived values move by W n (the
    pipeline is the linear map ``jacobian``), and 4000 draws of W n have the covariance W C W^T: the whitened
    sample covariance is the identity within sampling error (5 / sqrt(4000) per entry)."""
    block = blocks["opening"]
    C = field.data.covariance
    rng = np.random.default_rng(11)
    for _ in range(2):  # the pipeline on noisy data is y + W n
        noise = C.color(rng.standard_normal(field.data.n_y))
        noisy = dataclasses.replace(field, data=dataclasses.replace(field.data, y=field.data.y + noise))
        again = opening_profile(noisy, BEAM, HEIGHTS, GAUGE, radius=RADIUS)
        np.testing.assert_allclose(again.data.y, block.data.y + block.jacobian @ noise, rtol=0, atol=1e-12)
    n = 4000
    draws = block.jacobian @ C.color(rng.standard_normal((field.data.n_y, n)))
    white = block.data.covariance.whiten(draws)
    sample = white @ white.T / n
    assert np.abs(sample - np.eye(len(sample))).max() < 5.0 / np.sqrt(n)
    assert np.abs(draws.mean(axis=1) / block.data.covariance.std()).max() < 5.0 / np.sqrt(n)


def test_the_width_jacobian_is_the_data_sides_derivative(field, blocks):
    """The width's covariance J C J^T linearises the data side: J = central differences of the widths along
    field perturbations (draws of the noise scaled to 1 nm), to 1e-4 of their size."""
    block = blocks["width"]
    rng = np.random.default_rng(5)
    for _ in range(3):
        direction = field.data.covariance.color(rng.standard_normal(field.data.n_y)) * 1e-3
        plus, minus = (process_zone_width(dataclasses.replace(field, data=dataclasses.replace(
            field.data, y=field.data.y + sign * direction)), BEAM, **WIDTH).data.y for sign in (1.0, -1.0))
        difference = (plus - minus) / 2.0
        np.testing.assert_allclose(block.jacobian @ direction, difference, rtol=0,
                                   atol=1e-4 * np.abs(difference).max())
    np.testing.assert_allclose(block.data.covariance.dense(),
                               block.jacobian @ field.data.covariance.dense() @ block.jacobian.T, rtol=1e-10,
                               atol=0)


def test_derived_sensitivities_equal_central_differences_at_fixed_steps(blocks):
    """Fixed increments (no jump to onset, a checkpoint at every step): differences of runs differentiate the
    discrete path DDM does. The opening on the half, the pairs (the other half's points mirrored, u_x
    changing sign) and the width (through the strain's excess, C1), per parameter: max |S - S_cd| / max |S_cd|.
    Measured at relative steps 1e-3, 3e-4, 1e-4: kappa_i 1.4e-4, 1.1e-4, 1.4e-5 (the raw field at the same
    points alike: the differences' truncation error), beta and c <= 6e-5; the test uses 1e-4 (7 runs, ~2 s)."""
    steps = StepOptions(initial=0.01, max_factor=1.0, onset_fraction=1.0, jump_to_onset=False)
    kinds = [derived_observation(blocks[name], BEAM, control="cmod") for name in ("opening", "width", "pairs")]
    operator = ForwardOperator(kinds, BASE, NAMES, steps=steps)
    record = operator.differentiated()(TRUTH)
    assert record.ok and record.S is not None
    _, S_cd, _ = CentralDifferences(relative_step=1e-4)(operator, TRUTH)
    for part in operator.slices():
        deviation = np.abs(record.S[part] - S_cd[part]).max(axis=0) / np.abs(S_cd[part]).max(axis=0)
        assert np.all(deviation <= 1e-4), deviation


@pytest.mark.parametrize("change, error, match", [
    (dict(heights=[20.0, 30.0]), ValueError, r"heights = \[20.0, 30.0\]: \[20.0\] mm lie outside the ligament"),
    (dict(heights=[30.0, 55.0]), ValueError, r"\[55.0\] mm lie outside the ligament \[25, 50\]"),
    (dict(heights=[35.0, 30.0]), ValueError, "must increase strictly"),
    (dict(gauge=0.0), ValueError, r"gauge = 0.0 \[mm\]"),
    (dict(radius=-1.0), ValueError, r"radius = -1.0 \[mm\]"),
    (dict(radius=1.0), DataError, r"gauge end at height 27.5 mm, offset \+6 mm .* within radius = 1 mm"),
    (dict(pairs=True), DataError, r"offset -6 mm"),
    (dict(rigid_motion=np.zeros((2, 3))), DataError, r"rigid_motion has shape \(2, 3\)"),
])
def test_bad_opening_input_is_named(field, change, error, match):
    arguments = dict(heights=HEIGHTS, gauge=GAUGE, radius=RADIUS) | change
    with pytest.raises(error, match=match):
        opening_profile(field, BEAM, **arguments)


def test_no_data_near_a_gauge_end_is_named(twin):
    """The data cover x < 10 mm only: a gauge of 12 mm has no points at its end."""
    near = field_block(as_dic(twin.points, twin.U), std=STD, region=lambda p: p[:, 0] < 10.0)
    with pytest.raises(DataError, match=r"frame at control 0.03 mm: gauge end at height 27.5 mm, offset \+12 mm .* "
                                         r"[0-2] DIC point\(s\) within radius = 5 mm"):
        opening_profile(near, BEAM, HEIGHTS, 12.0, radius=RADIUS)
    only_v = field_block(as_dic(twin.points, twin.U), components="v", std=STD)
    with pytest.raises(DataError, match=r"components \[1\].* include 'u'"):
        opening_profile(only_v, BEAM, HEIGHTS, GAUGE, radius=RADIUS)


@pytest.mark.parametrize("change, error, match", [
    (dict(offsets=[0.0, 2.0, 4.0]), ValueError, "offsets"),
    (dict(offsets=[5.0]), ValueError, "offsets"),
    (dict(threshold=float("nan")), ValueError, "threshold = nan"),
    (dict(threshold=1e-2), DataError, "has no variance"),
    (dict(heights=[10.0]), ValueError, r"heights = \[10.0\]"),
])
def test_bad_width_input_is_named(field, change, error, match):
    with pytest.raises(error, match=match):
        process_zone_width(field, BEAM, **(WIDTH | change))


def test_bad_model_side_input_is_named(blocks):
    block = blocks["opening"]
    with pytest.raises(ValueError, match=r"present has dtype bool and shape \(2, "):
        DerivedFieldObservation(BEAM, block.points, FRAMES, block.estimator, present=block.present[:2])
    with pytest.raises(ValueError, match="frames"):
        DerivedFieldObservation(BEAM, block.points, FRAMES[::-1], block.estimator)
    with pytest.raises(ValueError, match="outside"):
        FieldObservation(BEAM, [[200.0, 30.0]], FRAMES)  # the wrapped observation names points off the mesh


def test_a_derived_variance_too_small_to_be_normal_is_refused(twin):
    """A field whose std squares to a normal variance (2e-154 mm: 4e-308 mm^2) whose openings' variances, averages
    of it, fall below the smallest normal float: refused naming the block, not an internal error later."""
    tiny = field_block(as_dic(twin.points, twin.U), std=2e-154)
    with pytest.raises(DataError, match=r"'opening'.*has no variance \(.*mm\^2, not a positive normal number"):
        opening_profile(tiny, BEAM, HEIGHTS, GAUGE, radius=RADIUS)
    usual = opening_profile(field_block(as_dic(twin.points, twin.U), std=1e-150), BEAM, HEIGHTS, GAUGE, radius=RADIUS)
    assert np.all(np.diag(usual.data.covariance.dense()) > np.finfo(float).tiny)
