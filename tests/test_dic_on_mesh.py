"""Issue 38, items 3 and 6: DIC points located on the specimen's mesh while the configuration is checked
(fracid.inverse.experiments.field_on_mesh), one guard of meshio's errors and exits (fracid.fem.mesh.meshio_files),
standard deviations whose square is not a positive normal float refused (fracid.data.covariance), DIC frames
without a value dropped (fracid.data.dic.field)."""

import math

import numpy as np
import pytest

from fracid.data import DataError
from fracid.data.covariance import STD_RANGE, check_positive_std, unusable_variances, usable_std
from fracid.data.dic import CameraPlacement, DicData, field_block
from fracid.data.experimental import local_block, with_std
from fracid.data.curves import Curve
from fracid.fem.mesh.meshio_files import UnreadableFile, meshio_read
from fracid.inverse.experiments.field_on_mesh import MAX_OUTSIDE_FRACTION, points_on_mesh
from fracid.specimens.beam import NotchedBeam

BEAM = NotchedBeam(h_fine=4.0, h_coarse=8.0)  # a half beam, x 0 to 87.5, y 0 to 50 mm, mirrored about x = 0


# ---------------------------------------------------------------------------- standard deviations


@pytest.mark.parametrize("std", [1e-320, 1e-200, 1e-155, 1.4e154, 1e200, math.inf, math.nan, 0.0, -1.0])
def test_a_std_whose_square_is_not_a_normal_float_is_refused(std):
    assert not usable_std(std)
    with pytest.raises(DataError, match=r"x = .*: every standard deviation must be > 0 with a square that is a "
                                        r"normal number: between 1.49e-154 and 1.34e\+154"):
        check_positive_std(np.array([1.0, std]), "x")


@pytest.mark.parametrize("std", [STD_RANGE[0], 2e-154, 1e-3, 5.0, 1e150, STD_RANGE[1]])
def test_a_std_whose_square_is_a_normal_float_is_kept(std):
    assert usable_std(std)
    check_positive_std(np.array([std]), "x")
    assert not unusable_variances(np.array([std]) ** 2).any()


def test_the_refusal_counts_and_places_the_bad_values():
    with pytest.raises(DataError, match=r"std = 1e-320 \(at 2 of 4 values, the first at index 1\)"):
        check_positive_std(np.array([1.0, 1e-320, 2.0, 0.0]), "std")
    np.testing.assert_array_equal(unusable_variances([1.0, 1e-310, 0.0, np.inf, np.nan, 3e-308]),
                                  [False, True, True, True, True, False])


def _curve():
    control = np.linspace(0.0, 1.0, 11)
    return Curve(control=control, force=100.0 * control * (1.2 - control), source="curve")


@pytest.mark.parametrize("std", [1e-320, 1e-160, 1e160])
def test_curve_and_local_blocks_refuse_the_std_by_name(std):
    with pytest.raises(DataError, match=r"block 'global': std = .*normal number"):
        with_std(_curve(), std, 5)
    with pytest.raises(DataError, match=r"block 'local': std = .*normal number"):
        local_block((np.linspace(0, 1, 5), np.ones(5)), std)
    with pytest.raises(DataError, match=r"block 'global': std = .*normal number"):  # relative std of a small y
        with_std(Curve(control=np.linspace(0, 1, 6), force=np.full(6, 1e-150), source="c"), 1e-10, 4,
                 relative=True, std_floor=0.0)


def _dic(sigma=1e-3, n_frames=3, n_points=8) -> DicData:
    rng = np.random.default_rng(0)
    points = np.column_stack([10.0 + np.arange(n_points), np.full(n_points, 30.0)])
    u = rng.normal(size=(n_frames, n_points, 2))
    std = np.full(u.shape, sigma)
    return DicData(points, tuple(range(1, n_frames + 1)), u, std,
                   {"cmod_mm": 0.01 * np.arange(1, n_frames + 1)}, source=("table", "f1", "f2", "f3"))


@pytest.mark.parametrize("sigma", [1e-200, 1e-160, 1e160])
def test_a_field_refuses_a_files_sigma_or_rigid_std_too_small_or_large_to_square(sigma):
    with pytest.raises(DataError, match=r"the per-point sigma of the files \[mm\] = .*at 48 of 48 values"):
        field_block(_dic(sigma))
    with pytest.raises(DataError, match=r"^rigid_std = .*normal number"):
        field_block(_dic(), rigid_std=sigma)


# ---------------------------------------------------------------------------- frames without a value


@pytest.mark.parametrize("empty", [[1], [2], [3], [1, 3]])
def test_a_frame_without_any_value_is_dropped_and_named(empty):
    dic = _dic()
    u = dic.u.copy()
    u[np.array(empty) - 1] = np.nan
    block = field_block(dic._replace(u=u))
    kept = [f for f in (1, 2, 3) if f not in empty]
    assert block.frame_numbers == tuple(kept) and block.dropped_frames == tuple(empty)
    np.testing.assert_allclose(block.frames, 0.01 * np.array(kept))
    assert block.data.n_y == 16 * len(kept) and block.keep.size == 16 * len(kept)
    warning = [note for note in block.data.notes if note.startswith("WARNING: field 'field'")]
    assert len(warning) == 1 and f"{len(empty)} frame(s) without any valid value" in warning[0]
    assert f"frame {empty[0]} (cmod_mm = {0.01 * empty[0]:.6g} mm, f{empty[0]})" in warning[0]


def test_a_frame_with_one_value_is_kept_and_all_frames_empty_is_refused():
    dic = _dic()
    u = dic.u.copy()
    u[1] = np.nan
    u[1, 4, 0] = 0.5
    block = field_block(dic._replace(u=u))
    assert block.frame_numbers == (1, 2, 3) and block.dropped_frames == ()
    assert not any(note.startswith("WARNING") for note in block.data.notes)
    with pytest.raises(DataError, match="no value left"):
        field_block(dic._replace(u=np.full_like(u, np.nan)))


# ---------------------------------------------------------------------------- points on the mesh


def _grid(n=10):
    """n x n points over most of the half beam's face [mm]."""
    x, y = np.meshgrid(np.linspace(5.0, 80.0, n), np.linspace(3.0, 47.0, n))
    return np.column_stack([x.ravel(), y.ravel()])


def test_points_inside_the_mesh_or_its_mirror_image_are_kept():
    points = np.vstack([_grid(), _grid()[:10] * [-1.0, 1.0]])  # the other half: sampled at its mirror image
    inside, warning = points_on_mesh(BEAM, points)
    assert inside.all() and warning is None


@pytest.mark.parametrize("n_out", [1, 5, 10])
def test_a_few_points_outside_are_dropped_with_a_warning(n_out):
    points = _grid()
    points[:n_out, 1] = 50.0 + 0.5 * np.arange(1, n_out + 1)  # above the top edge: 0.5 to 5 mm
    inside, warning = points_on_mesh(BEAM, points)
    assert inside.sum() == 100 - n_out and not inside[:n_out].any()
    assert f"{n_out} of 100 points of the field fall outside" in warning and f"({n_out:.1f}% of the points" in warning
    assert f"up to {0.5 * n_out:.3g} mm beyond the mesh's box" in warning


def test_more_than_the_fraction_outside_is_refused():
    points = _grid()
    n_out = int(MAX_OUTSIDE_FRACTION * 100) + 1
    points[:n_out, 1] = 60.0
    with pytest.raises(DataError, match=rf"{n_out} of 100 points .* more than 10% outside is a placement error"):
        points_on_mesh(BEAM, points)


@pytest.mark.parametrize("transform, cause", [
    # the grid spans 75 mm, the mesh 87.5 mm; the boxes' centres 1.25 mm apart in x
    (lambda p: 1000.0 * p, r"the points span 857 times the specimen's size: check the units"),
    (lambda p: 20.0 * p, r"the points span 17\.1 times the specimen's size: check the units"),
    (lambda p: p + [300.0, 0.0], r"offset by \(298\.8, 0\) mm from the specimen's: check the origin"),
    (lambda p: p + [0.0, -200.0], r"offset by \(-1\.25, -200\) mm"),
    (lambda p: p * [1.0, -1.0], r"mirrored about the line y = 0 mm fall inside: .*negate the camera's Y column"),
])
def test_every_point_outside_names_the_likely_cause(transform, cause):
    points = transform(_grid())
    with pytest.raises(DataError) as err:
        points_on_mesh(BEAM, points, CameraPlacement(scale=0.1))
    text = str(err.value)
    assert "100 of 100 points" in text and "every point is outside" in text, text
    assert "the mesh x 0 to 87.5, y 0 to 50 mm" in text, text
    assert re_search(cause, text), text


def re_search(pattern, text):
    import re

    return re.search(pattern, text) is not None


# ---------------------------------------------------------------------------- meshio's guard


def _truncated_vtu(path):
    import meshio

    points = np.column_stack([_grid(3), np.zeros(9)])
    meshio.write(path, meshio.Mesh(points, [("vertex", np.arange(9)[:, None])],
                                   point_data={"displacement": np.zeros((9, 3))}))
    data = path.read_bytes()
    path.write_bytes(data[:len(data) // 2])


def test_meshio_exits_and_errors_are_unreadable_files(tmp_path, monkeypatch):
    import meshio

    _truncated_vtu(tmp_path / "cut.vtu")
    with pytest.raises(UnreadableFile, match="Couldn't read file") as err:  # meshio printed it, then sys.exit
        meshio_read(tmp_path / "cut.vtu")
    assert not err.value.os_error
    monkeypatch.setattr(meshio, "read", lambda path: (_ for _ in ()).throw(SystemExit(1)))
    with pytest.raises(UnreadableFile, match="SystemExit"):
        meshio_read(tmp_path / "cut.vtu")


def test_the_dic_reader_names_a_truncated_vtu(tmp_path):
    from fracid.data.dic.vtk_frames import read_vtk_cloud

    _truncated_vtu(tmp_path / "cut.vtu")
    with pytest.raises(DataError, match=r"cut.vtu: not a readable VTU/VTK file \(Couldn't read .*truncated"):
        read_vtk_cloud(str(tmp_path / "cut.vtu"), None, None, None)
