"""The synthetic DIC twin: a forward run on a speckle-like cloud, with rigid motion, noise, holes and a camera."""

import csv

import numpy as np
import pytest

from fracid.data.dic_noise import dic_kernel
from fracid.fem.material.parameters import DamageParameters
from fracid.models.forward import simulate
from fracid.models import probe_matrix
from fracid.data.dic import CameraPlacement
from fracid.inverse.studies.dic_twin import (inside_mesh, rigid_motion, speckle_grid, synthetic_dic,
                                             write_dic)
from fracid.specimens.beam import NotchedBeam
from fracid.specimens.strip import TensionStrip

BEAM = NotchedBeam(h_fine=4.0, h_coarse=10.0)
PARAMS = DamageParameters(E=36250.0, nu=0.2, kappa_i=6.6e-5, alpha=0.99, beta=600.0, c=9.0, eta=10.0)
FRAMES = [0.02, 0.05, 0.1]  # CMOD [mm]: before, near and past the peak
PLACEMENT = CameraPlacement(scale=0.05, rotation=np.radians(2.0), origin_camera=(900.0, 600.0),
                            origin_specimen=(10.0, 5.0))
RIGID = (0.01, -0.02, 2e-4)  # mm, mm, rad
OPTIONS = dict(frames=FRAMES, spacing=4.0, subset_size=6.0, holes=3.0, rigid_body=RIGID, placement=PLACEMENT, seed=7)


@pytest.fixture(scope="module")
def clean():
    return synthetic_dic(BEAM, PARAMS, std=0.0, **OPTIONS)


@pytest.fixture(scope="module")
def noisy():
    return synthetic_dic(BEAM, PARAMS, std=1e-3, **OPTIONS)


def _read(path):
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    return rows[0], rows[1:]


def test_written_files_follow_the_format(clean, tmp_path):
    files = write_dic(tmp_path, clean)
    assert [f.name for f in files] == ["frame_0001.csv", "frame_0002.csv", "frame_0003.csv", "frames.csv"]
    header, table = _read(tmp_path / "frames.csv")
    assert header == ["frame", "file", "cmod_mm", "force_N"]
    assert [int(r[0]) for r in table] == [1, 2, 3]
    np.testing.assert_allclose([float(r[2]) for r in table], FRAMES, rtol=1e-9)
    assert all(float(r[3]) > 0 for r in table)
    coordinates = None
    for row in table:
        header, cells = _read(tmp_path / row[1])
        assert header == ["X", "Y", "U", "V", "sigma"]
        values = np.array([[float(c) for c in r] for r in cells])
        assert values.shape == (len(clean.X), 5)
        if coordinates is None:
            coordinates = values[:, :2]
        np.testing.assert_array_equal(values[:, :2], coordinates)  # the same points every frame
        assert np.array_equal(np.isnan(values[:, 2]), clean.holes) and np.array_equal(np.isnan(values[:, 3]),
                                                                                      clean.holes)
        assert sum(r[2] == "NaN" for r in cells) == clean.holes.sum()
    np.testing.assert_allclose(coordinates, clean.X, rtol=1e-9)


def test_noise_free_data_equal_the_model_field(clean):
    run = simulate(BEAM, PARAMS, target=FRAMES[-1], checkpoints=FRAMES, field_steps="all")
    d = BEAM.describe()
    points = PLACEMENT.to_specimen(clean.X)  # undo the placement
    np.testing.assert_allclose(points, clean.points, atol=1e-10)
    P = probe_matrix(d.nodes, d.cells, points)
    keep = ~clean.holes
    for k, frame in enumerate(FRAMES):
        step = int(np.argmin(np.abs(run.control - frame)))
        model = P @ np.asarray(run.fields[step]["u"]).reshape(-1, 2)
        measured = PLACEMENT.displacements_to_specimen(clean.U[k]) - rigid_motion(points, *RIGID)
        scale = np.abs(model).max()
        np.testing.assert_allclose(measured[keep], model[keep], atol=1e-9 * scale)
        assert clean.force[k] == pytest.approx(run.force[step], rel=1e-9)


def test_the_grid_is_not_aligned_with_the_mesh(clean):
    d = BEAM.describe()
    nearest = np.min(np.hypot(*(clean.points[:, None, :] - d.nodes[None, :, :]).transpose(2, 0, 1)), axis=1)
    assert np.mean(nearest < 1e-6) == 0.0
    assert 150 < len(clean.points) < 400
    notch = (clean.points[:, 0] < BEAM.notch_width / 2) & (clean.points[:, 1] < BEAM.notch_depth)
    assert not notch.any()  # no point in the notch (outside the mesh)


def test_holes_are_where_asked(clean):
    x, y = clean.points.T
    top = 0.5 * (BEAM.notch_depth + BEAM.depth)  # the default span: the notch and the lower half of the ligament
    distance = np.hypot(x, y - np.clip(y, 0.0, top))
    np.testing.assert_array_equal(clean.holes, distance < 3.0)
    assert 3 <= clean.holes.sum() < 0.2 * len(x)
    assert np.all(np.isnan(clean.U[:, clean.holes])) and np.all(np.isfinite(clean.U[:, ~clean.holes]))


def test_noise_has_the_requested_std_and_correlation(clean, noisy):
    np.testing.assert_array_equal(noisy.points, clean.points)  # same seed: same cloud
    keep = ~clean.holes
    noise = PLACEMENT.displacements_to_specimen(noisy.U - clean.U)[:, keep]  # (frames, n, 2) [mm]
    np.testing.assert_allclose(noise, noisy.noise[:, keep], atol=1e-12)
    assert np.std(noise) == pytest.approx(1e-3, rel=0.15)
    assert abs(np.mean(noise)) < 3e-4
    points = clean.points[keep]
    expected = dic_kernel(points, points, 1.0, 6.0)
    samples = noise.transpose(0, 2, 1).reshape(-1, len(points))  # every frame and component a draw
    product = samples.T @ samples / len(samples) / 1e-6
    d = np.hypot(*(points[:, None] - points[None]).transpose(2, 0, 1))
    for low, high in [(2.0, 4.0), (4.0, 6.0), (9.0, 20.0)]:
        pairs = (d > low) & (d < high)
        assert np.mean(product[pairs]) == pytest.approx(np.mean(expected[pairs]), abs=0.12)
    assert noisy.sigma == pytest.approx(1e-3 / PLACEMENT.scale)


def test_placement_round_trip_and_grid():
    x = np.array([[0.0, 0.0], [10.0, -3.0], [87.5, 50.0]])
    np.testing.assert_allclose(PLACEMENT.to_specimen(PLACEMENT.to_camera(x)), x, atol=1e-12)
    u = np.array([[1e-3, 2e-3]])
    np.testing.assert_allclose(PLACEMENT.displacements_to_specimen(PLACEMENT.displacements_to_camera(u)), u, atol=1e-15)
    assert np.linalg.norm(PLACEMENT.displacements_to_camera(u)) == pytest.approx(np.linalg.norm(u) / 0.05)
    grid = speckle_grid((0.0, 0.0), (20.0, 10.0), 1.0, rng=0)
    assert 150 < len(grid) < 250 and grid.min() >= 0.0
    square = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    assert list(inside_mesh(square, [[0, 1, 2, 3]], [[0.5, 0.5], [1.5, 0.5], [0.5, -0.1]])) == [True, False, False]


@pytest.mark.parametrize("kwargs, match", [
    (dict(frames=[0.05, 0.02]), "frames"),
    (dict(frames=[0.02], rigid_body=np.zeros((2, 3))), "rigid_body"),
    (dict(frames=[0.02], std=-1.0), "std = -1.0"),
    (dict(frames=[0.02], spacing=0.0), "spacing = 0.0"),
])
def test_bad_input_is_named(kwargs, match):
    options = dict(frames=[0.02], spacing=4.0, std=0.0, subset_size=6.0) | kwargs
    with pytest.raises(ValueError, match=match):
        synthetic_dic(BEAM, PARAMS, **options)


def test_placement_checks_its_values():
    with pytest.raises(ValueError, match="scale"):
        CameraPlacement(scale=0.0)


def test_the_example_data_set_follows_the_format():
    from pathlib import Path

    example = Path(__file__).resolve().parents[1] / "examples" / "dic"
    header, table = _read(example / "frames.csv")
    assert header == ["frame", "file", "cmod_mm", "force_N"] and len(table) == 6
    clouds = [np.genfromtxt(example / row[1], delimiter=",", names=True) for row in table]
    assert all(c.dtype.names == ("X", "Y", "U", "V", "sigma") for c in clouds)
    for c in clouds:
        np.testing.assert_array_equal(c["X"], clouds[0]["X"])
        np.testing.assert_array_equal(np.isnan(c["U"]), np.isnan(clouds[0]["U"]))
    assert 250 <= len(clouds[0]) <= 350 and 0 < np.isnan(clouds[0]["U"]).sum() < 30
    assert sum(f.stat().st_size for f in example.iterdir()) < 1e6


def test_the_readers_read_the_twins_files_back_in_the_specimen_frame(noisy, tmp_path):
    """The writer and the readers speak the same format: the files of a twin, read with its placement, give
    its points and displacements (rigid motion and noise included) in the specimen frame, its holes as missing
    and its load."""
    from fracid.data.dic import read_dic_frames

    write_dic(tmp_path, noisy)
    data = read_dic_frames(tmp_path / "frames.csv", sigma="sigma", coordinate_unit="px", placement=PLACEMENT)
    np.testing.assert_allclose(data.points, noisy.points, atol=1e-8)
    expected = PLACEMENT.displacements_to_specimen(noisy.U)
    np.testing.assert_allclose(data.u, expected, atol=1e-9, equal_nan=True)
    assert np.array_equal(data.missing.any(axis=(0, 2)), noisy.holes)
    np.testing.assert_allclose(data.load["cmod_mm"], noisy.control, rtol=1e-9)
    np.testing.assert_allclose(data.std[0, ~noisy.holes, 0], 1e-3, rtol=1e-9)


def test_a_camera_on_both_halves_sees_the_mirror_image():
    """both_halves: the grid covers the half beam and its mirror across the crack line x = 0; a point of the other
    half carries the mirror image's displacement (u_x negated), as the field observation computes it."""
    from fracid.inverse.core.field_observations import FieldObservation

    data = synthetic_dic(BEAM, PARAMS, frames=FRAMES[:2], spacing=5.0, std=0.0, subset_size=6.0, both_halves=True)
    left = data.points[:, 0] < 0
    assert 0.3 < left.mean() < 0.7 and data.points[:, 0].min() < -80.0
    field = FieldObservation(BEAM, data.points, FRAMES[:2])
    run = simulate(BEAM, PARAMS, target=FRAMES[1], checkpoints=FRAMES[:2], probes=field.probe_matrix())
    model, _ = field.sample(run)
    measured = data.U.transpose(0, 2, 1).reshape(-1)  # frame, component, point (camera = specimen frame here)
    np.testing.assert_allclose(measured, model, atol=1e-9 * np.abs(model).max())
    d = BEAM.describe()
    mirror = data.points[left] * [-1.0, 1.0]
    step = int(np.argmin(np.abs(run.control - FRAMES[1])))
    u = probe_matrix(d.nodes, d.cells, mirror) @ np.asarray(
        simulate(BEAM, PARAMS, target=FRAMES[1], checkpoints=FRAMES[:2], field_steps="all").fields[step]["u"]
    ).reshape(-1, 2)
    np.testing.assert_allclose(data.U[1][left], u * [-1.0, 1.0], atol=1e-9 * np.abs(u).max())
    with pytest.raises(ValueError, match="both_halves needs"):
        synthetic_dic(TensionStrip(), PARAMS, frames=[0.01], spacing=5.0, std=0.0, subset_size=6.0, both_halves=True)
