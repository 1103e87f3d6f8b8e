"""Readers of DIC data (fracid.data.dic): CSV frames with a frame table, VTU point data, camera placement."""

import math
import os

import numpy as np
import pytest

from fracid.data import DataError, DicData
from fracid.data.dic import CameraPlacement, fit_placement, read_dic_frames, read_dic_vtk
from fracid.data.dic.placement import rotation_matrix

SCALE, THETA = 0.04, math.radians(30.0)  # mm per px, camera axes rotated by 30 degrees
ORIGIN_CAMERA, ORIGIN_SPECIMEN = (512.0, 384.0), (250.0, 50.0)


def specimen_grid():
    """Reference points [mm] on a 6 x 4 grid not aligned with anything."""
    x, y = np.meshgrid(np.linspace(200.0, 300.0, 6), np.linspace(10.0, 90.0, 4))
    return np.column_stack([x.ravel() + 0.3, y.ravel() - 0.7])


def specimen_field(points, frame):
    """A known displacement field [mm] at frame ``frame``: a stretch, a shear and a shift."""
    A = frame * np.array([[1e-4, 2e-4], [-3e-4, 5e-5]])
    return points @ A.T + frame * np.array([1e-3, -2e-3])


def placement():
    return CameraPlacement(SCALE, THETA, ORIGIN_CAMERA, ORIGIN_SPECIMEN)


def to_camera(points_mm, u_mm, p):
    """Camera coordinates and displacements [px] of specimen ones: the inverse of the placement."""
    back = rotation_matrix(p.rotation).T / p.scale
    return (points_mm - p.origin_specimen) @ back.T + p.origin_camera, u_mm @ back.T


def write_cloud(path, X, U, sigma=None, quality=None, holes=()):
    """A DICe-like CSV point cloud; ``holes``: rows whose U, V are written as empty / NaN cells."""
    header = ["X", "Y", "U", "V"] + (["sigma"] if sigma is not None else []) + (["quality"] if quality is not None
                                                                                  else [])
    with open(path, "w") as handle:
        handle.write(",".join(header) + "\n")
        for i in range(len(X)):
            cells = [f"{X[i, 0]:.17g}", f"{X[i, 1]:.17g}"]
            cells += ["", "NaN"] if i in holes else [f"{U[i, 0]:.17g}", f"{U[i, 1]:.17g}"]
            cells += [] if sigma is None else [f"{sigma[i]:.17g}"]
            cells += [] if quality is None else [f"{quality[i]:.17g}"]
            handle.write(",".join(cells) + "\n")


def write_export(folder, frames=(0, 3, 7), p=None, holes=(), sigma=None, quality=None):
    """A frame table and its clouds in ``folder``; returns the table's path, points and fields [mm]."""
    p = placement() if p is None else p
    points = specimen_grid()
    lines = ["frame,file,cmod_mm,force_N"]
    fields = []
    for f in frames:
        u = specimen_field(points, f)
        X, U = to_camera(points, u, p)
        write_cloud(os.path.join(folder, f"frame_{f:04d}.csv"), X, U, sigma, quality, holes)
        lines.append(f"{f},frame_{f:04d}.csv,{0.01 * f},{100.0 * f}")
        fields.append(u)
    table = os.path.join(folder, "frames.csv")
    with open(table, "w") as handle:
        handle.write("\n".join(lines) + "\n")
    return table, points, np.array(fields)


# ---------------------------------------------------------------- placement


def test_placement_maps_a_known_point_and_rotates_by_30_degrees():
    p = placement()
    np.testing.assert_allclose(p.to_specimen([ORIGIN_CAMERA]), [ORIGIN_SPECIMEN], atol=1e-12)
    # a camera step of 100 px along X is 4 mm along (cos 30, sin 30) in the specimen
    step = p.to_specimen([[ORIGIN_CAMERA[0] + 100.0, ORIGIN_CAMERA[1]]])[0] - ORIGIN_SPECIMEN
    np.testing.assert_allclose(step, [4.0 * math.sqrt(3) / 2, 2.0], atol=1e-12)
    np.testing.assert_allclose(p.displacements_to_specimen([[0.0, 25.0]]), [[-0.5, 0.5 * math.sqrt(3)]], atol=1e-12)
    assert np.isnan(p.displacements_to_specimen([[np.nan, 1.0]])).all()


def test_fit_placement_recovers_a_known_similarity_to_1e_9():
    p = placement()
    rng = np.random.default_rng(0)
    specimen = rng.uniform([0.0, 0.0], [500.0, 100.0], size=(5, 2))
    camera, _ = to_camera(specimen, np.zeros_like(specimen), p)
    fitted = fit_placement(camera, specimen)
    assert fitted.scale == pytest.approx(SCALE, rel=1e-9)
    assert fitted.rotation == pytest.approx(THETA, abs=1e-9)
    grid = rng.uniform(0.0, 1000.0, size=(20, 2))
    np.testing.assert_allclose(fitted.to_specimen(grid), p.to_specimen(grid), atol=1e-9)
    assert fitted.fit_rms < 1e-9
    assert not any("WARNING" in note for note in fitted.notes)


def test_fit_placement_with_a_wrong_marked_point_warns_with_its_rms():
    p = placement()
    specimen = np.array([[0.0, 0.0], [500.0, 0.0], [500.0, 100.0], [0.0, 100.0]])
    camera, _ = to_camera(specimen, np.zeros_like(specimen), p)
    camera[2] += [200.0, 0.0]  # 8 mm off
    fitted = fit_placement(camera, specimen)
    assert fitted.fit_rms > 1.0
    assert any("WARNING" in note and "mm" in note for note in fitted.notes)


def test_fit_placement_refuses_two_points_and_collinear_points():
    with pytest.raises(DataError, match="at least 3"):
        fit_placement([[0.0, 0.0], [1.0, 0.0]], [[0.0, 0.0], [1.0, 0.0]])
    with pytest.raises(DataError, match="camera_points.*collinear"):
        fit_placement([[0.0, 0.0], [1.0, 1.0], [2.0, 2.0]], [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]])
    with pytest.raises(DataError, match="specimen_points.*collinear"):
        fit_placement([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]], [[0.0, 0.0], [1.0, 0.0], [3.0, 0.0]])


def test_camera_placement_refuses_a_bad_scale():
    with pytest.raises(DataError, match="scale"):
        CameraPlacement(0.0)


# ---------------------------------------------------------------- CSV frames


def test_csv_round_trip_in_px_with_a_30_degree_camera(tmp_path):
    table, points, fields = write_export(tmp_path)
    data = read_dic_frames(table, coordinate_unit="px", placement=placement(), load_columns=["cmod_mm", "force_N"])
    assert isinstance(data, DicData)
    assert data.frames == (0, 3, 7) and data.n_frames == 3 and data.n_points == len(points)
    np.testing.assert_allclose(data.points, points, atol=1e-9)
    np.testing.assert_allclose(data.u, fields, atol=1e-12)
    np.testing.assert_allclose(data.load["force_N"], [0.0, 300.0, 700.0])
    assert set(data.load) == {"cmod_mm", "force_N"} and data.std is None
    assert not data.missing.any()
    assert data.source[0] == table and len(data.source) == 4
    assert any("px placed on the specimen in mm" in note for note in data.notes)


def test_csv_units_px_to_mm_with_a_given_scale(tmp_path):
    p = CameraPlacement(scale=0.05)  # no rotation, origins at 0
    X = np.array([[100.0, 20.0], [300.0, 40.0], [500.0, 60.0]])
    U = np.array([[2.0, -4.0], [1.0, 0.0], [0.0, 10.0]])
    write_cloud(tmp_path / "a.csv", X, U, sigma=np.array([0.2, 0.4, 0.6]))
    (tmp_path / "frames.csv").write_text("frame,file,force_N\n1,a.csv,5.0\n")
    data = read_dic_frames(tmp_path / "frames.csv", sigma="sigma", coordinate_unit="px", placement=p)
    np.testing.assert_allclose(data.points, 0.05 * X)
    np.testing.assert_allclose(data.u[0], 0.05 * U)
    np.testing.assert_allclose(data.std[0], 0.05 * np.array([[0.2, 0.2], [0.4, 0.4], [0.6, 0.6]]))
    assert list(data.load) == ["force_N"]  # load_columns None: every column but frame and file


def test_px_without_a_placement_is_refused(tmp_path):
    table, _, _ = write_export(tmp_path)
    with pytest.raises(DataError, match="px.*placement"):
        read_dic_frames(table, coordinate_unit="px")


def test_nan_holes_and_low_quality_points_are_missing(tmp_path):
    n = len(specimen_grid())
    quality = np.linspace(0.0, 1.0, n)
    table, points, fields = write_export(tmp_path, holes=(2, 5), quality=quality)
    data = read_dic_frames(table, coordinate_unit="px", placement=placement(), quality="quality", min_quality=0.3)
    low = quality < 0.3
    expected = low.copy()
    expected[[2, 5]] = True
    assert data.n_points == n  # kept, not dropped
    np.testing.assert_array_equal(data.missing[:, :, 0], np.broadcast_to(expected, (3, n)))
    np.testing.assert_array_equal(data.missing[:, :, 1], np.broadcast_to(expected, (3, n)))
    np.testing.assert_allclose(data.u[:, ~expected], fields[:, ~expected], atol=1e-12)
    assert any(f"{int(low.sum())} of {n} points with quality below 0.3" in note for note in data.notes)


def test_values_flatten_frame_component_point_and_region(tmp_path):
    table, points, fields = write_export(tmp_path, holes=(1,))
    data = read_dic_frames(table, coordinate_unit="px", placement=placement())
    values, missing = data.values([2, 0], components=(1, 0))
    n = data.n_points
    expected = np.concatenate([fields[2, :, 1], fields[2, :, 0], fields[0, :, 1], fields[0, :, 0]])
    expected_missing = np.zeros(4 * n, dtype=bool)
    expected_missing[[1, n + 1, 2 * n + 1, 3 * n + 1]] = True
    np.testing.assert_array_equal(missing, expected_missing)
    np.testing.assert_allclose(values[~missing], expected[~expected_missing], atol=1e-12)
    right = data.region(lambda p: p[:, 0] > 250.0)
    assert right.n_points == int((points[:, 0] > 250.0).sum())
    np.testing.assert_allclose(right.u, data.u[:, points[:, 0] > 250.0])
    assert "region of interest" in right.notes[-1]
    late = data.at_frames([7, 3])
    assert late.frames == (7, 3)
    np.testing.assert_allclose(late.u, data.u[[2, 1]])
    np.testing.assert_allclose(late.load["cmod_mm"], [0.07, 0.03])
    with pytest.raises(DataError, match=r"frames \[5\] are not in the data"):
        data.at_frames([5])
    with pytest.raises(DataError, match="components"):
        data.values(components=2)


def test_frame_table_missing_a_column_names_it_and_the_columns_found(tmp_path):
    table, _, _ = write_export(tmp_path)
    with pytest.raises(DataError, match=r"frames\.csv.*no column 'time_s'.*'cmod_mm'"):
        read_dic_frames(table, coordinate_unit="px", placement=placement(), load_columns=["time_s"])


def test_a_missing_frame_file_is_named_with_its_table_row(tmp_path):
    table, _, _ = write_export(tmp_path)
    os.remove(tmp_path / "frame_0003.csv")
    with pytest.raises(DataError, match=r"row 3, column 'file'.*frame_0003\.csv does not exist"):
        read_dic_frames(table, coordinate_unit="px", placement=placement())


def test_frames_with_different_points_are_refused(tmp_path):
    table, _, _ = write_export(tmp_path)
    path = tmp_path / "frame_0007.csv"
    lines = path.read_text().splitlines()
    cells = lines[4].split(",")
    cells[0] = f"{float(cells[0]) + 0.5:.17g}"
    lines[4] = ",".join(cells)
    path.write_text("\n".join(lines) + "\n")
    with pytest.raises(DataError, match=r"frame_0007\.csv: row 5: reference point.*differs from.*frame_0000\.csv"):
        read_dic_frames(table, coordinate_unit="px", placement=placement())
    path.write_text("\n".join(lines[:-1]) + "\n")
    with pytest.raises(DataError, match=r"frame_0007\.csv: 23 points, but .*frame_0000\.csv has 24"):
        read_dic_frames(table, coordinate_unit="px", placement=placement())


def test_a_non_numeric_cell_is_named_by_file_row_and_column(tmp_path):
    table, _, _ = write_export(tmp_path)
    path = tmp_path / "frame_0003.csv"
    lines = path.read_text().splitlines()
    cells = lines[6].split(",")
    cells[3] = "n/a"
    lines[6] = ",".join(cells)
    path.write_text("\n".join(lines) + "\n")
    with pytest.raises(DataError, match=r"frame_0003\.csv: row 7, column 'V': 'n/a' is not a number"):
        read_dic_frames(table, coordinate_unit="px", placement=placement())


def test_a_missing_reference_coordinate_is_refused(tmp_path):
    table, _, _ = write_export(tmp_path)
    path = tmp_path / "frame_0000.csv"
    lines = path.read_text().splitlines()
    lines[2] = "," + lines[2].split(",", 1)[1]
    path.write_text("\n".join(lines) + "\n")
    with pytest.raises(DataError, match=r"frame_0000\.csv: row 3, column 'X': empty cell"):
        read_dic_frames(table, coordinate_unit="px", placement=placement())


def test_a_cloud_missing_a_column_names_it(tmp_path):
    table, _, _ = write_export(tmp_path)
    with pytest.raises(DataError, match=r"frame_0000\.csv.*no column 'sigma'.*'U'"):
        read_dic_frames(table, coordinate_unit="px", placement=placement(), sigma="sigma")


def test_a_non_integer_frame_number_is_refused(tmp_path):
    (tmp_path / "frames.csv").write_text("frame,file\n1.5,a.csv\n")
    with pytest.raises(DataError, match=r"row 2, column 'frame': 1.5 is not an integer"):
        read_dic_frames(tmp_path / "frames.csv")


# ---------------------------------------------------------------- VTU


def write_vtu(path, X, U, name="displacement"):
    meshio = pytest.importorskip("meshio")
    points = np.column_stack([X, np.zeros(len(X))])
    cells = [("vertex", np.arange(len(X)).reshape(-1, 1))]
    data = {name: np.column_stack([U, np.zeros(len(X))])}
    meshio.write(str(path), meshio.Mesh(points, cells, point_data=data))


def test_vtu_round_trip_equals_the_csv_reader(tmp_path):
    p = placement()
    points = specimen_grid()
    paths, fields = [], []
    for f in (0, 3):
        u = specimen_field(points, f)
        u[4] = np.nan  # a hole
        X, U = to_camera(points, u, p)
        write_vtu(tmp_path / f"f{f}.vtu", X, U, name="U")
        paths.append(tmp_path / f"f{f}.vtu")
        fields.append(u)
    data = read_dic_vtk(paths, [0, 3], coordinate_unit="px", placement=p, load={"force_N": [0.0, 300.0]})
    np.testing.assert_allclose(data.points, points, atol=1e-9)
    np.testing.assert_allclose(data.u, np.array(fields), atol=1e-12)
    assert data.missing[:, 4].all() and data.missing.sum() == 4
    np.testing.assert_allclose(data.load["force_N"], [0.0, 300.0])


def test_vtu_without_the_displacement_array_names_the_arrays_found(tmp_path):
    points = specimen_grid()
    write_vtu(tmp_path / "f.vtu", points, np.zeros_like(points), name="strain")
    with pytest.raises(DataError, match=r"f\.vtu: no point-data array 'displacement' or 'U'.*'strain'"):
        read_dic_vtk([tmp_path / "f.vtu"], [0])
    with pytest.raises(DataError, match=r"nope\.vtu: cannot be read"):
        read_dic_vtk([tmp_path / "nope.vtu"], [0])


def test_fit_placement_of_a_mirror_image_says_so():
    specimen = np.array([[0.0, 0.0], [10.0, 0.0], [10.0, 5.0], [0.0, 5.0]])
    camera = specimen * [1.0, -1.0]  # an image whose Y axis points down
    fitted = fit_placement(camera, specimen)
    assert fitted.fit_rms > 1.0
    assert any("mirror image" in note for note in fitted.notes)


def test_dic_data_refuses_fields_of_the_wrong_shape_and_repeated_frames():
    points = specimen_grid()
    with pytest.raises(DataError, match=r"u must have shape \(2, 24, 2\)"):
        DicData(points, (0, 1), np.zeros((2, 23, 2)))
    with pytest.raises(DataError, match=r"frame numbers \[1\] appear more than once"):
        DicData(points, (1, 1), np.zeros((2, 24, 2)))
    with pytest.raises(DataError, match=r"load\['force_N'\] must have one value per frame"):
        DicData(points, (0, 1), np.zeros((2, 24, 2)), load={"force_N": [1.0]})


def test_a_frame_table_may_list_vtu_files(tmp_path):
    """The configuration's reader (read_dic_frames) takes VTU frames from the table's file column: same data as the
    CSV clouds; a missing array names the key ``displacement``."""
    p = placement()
    table, points, fields = write_export(tmp_path, frames=(0, 3))
    lines = ["frame,file,cmod_mm,force_N"]
    for f, u in zip((0, 3), fields):
        X, U = to_camera(points, u, p)
        write_vtu(tmp_path / f"f{f}.vtu", X, U, name="disp")
        lines.append(f"{f},f{f}.vtu,{0.01 * f},{100.0 * f}")
    (tmp_path / "vtu_frames.csv").write_text("\n".join(lines) + "\n")
    from_csv = read_dic_frames(table, coordinate_unit="px", placement=p)
    from_vtu = read_dic_frames(tmp_path / "vtu_frames.csv", coordinate_unit="px", placement=p, displacement="disp")
    np.testing.assert_allclose(from_vtu.points, from_csv.points, atol=1e-12)
    np.testing.assert_allclose(from_vtu.u, from_csv.u, atol=1e-12)
    np.testing.assert_allclose(from_vtu.load["cmod_mm"], [0.0, 0.03])
    with pytest.raises(DataError, match=r"f0\.vtu: no point-data array 'displacement' or 'U'.*'disp'"):
        read_dic_frames(tmp_path / "vtu_frames.csv", coordinate_unit="px", placement=p)
