"""The report's displacement-field maps (fracid.report.field_figures, fracid.report.views): the rigid motion of every frame recovered
from a synthetic field, the residual at the noise level, the figures' panels and titles, the report's section
per field block (and no curve panel for it), and ``fracid identify`` on a small copy of examples/dic."""

import base64
import re
import shutil
import struct
from pathlib import Path

import numpy as np
import pytest

from fracid.data.covariance_matrix import Diagonal
from fracid.data.dic.rigid import rigid_modes, with_rigid_motion
from fracid.inverse.methods.knn_kalman import IdentificationResult
from fracid.report import write_report

ff = pytest.importorskip("fracid.report.field_figures")  # needs matplotlib
field_fit = pytest.importorskip("fracid.report.field_fit")
block_view = pytest.importorskip("fracid.report.block_view")
figures = pytest.importorskip("fracid.report.figures")

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "dic"
NOISE = 1e-3  # mm: 1 micrometre
FRAMES = np.array([0.02, 0.05, 0.1])  # control of every frame [mm]
MOTIONS = np.array([[0.002, -0.004, 2e-5], [0.003, -0.008, 4e-5], [0.004, -0.012, 6e-5]])  # tx, ty [mm], theta [rad]
DROPPED = (0, 0, 3), (2, 1, 10)  # (frame, component, point) entries missing, as DIC holes


def grid_points() -> np.ndarray:
    """A jittered 12 x 7 grid over a 80 x 40 mm face with a 15 x 12 mm hole (a notch) at its bottom middle."""
    rng = np.random.default_rng(3)
    x, y = np.meshgrid(np.linspace(2.0, 78.0, 12), np.linspace(2.0, 38.0, 7))
    points = np.column_stack([x.ravel(), y.ravel()]) + rng.uniform(-0.6, 0.6, (x.size, 2))
    notch = (np.abs(points[:, 0] - 40.0) < 7.5) & (points[:, 1] < 12.0)
    return points[~notch]


def deformation(points, control: float) -> np.ndarray:
    """A bending-like field [mm] growing with the control (u_x then u_y at every point)."""
    x, y = points.T
    return control * np.concatenate([0.02 * (y - 20.0) * x / 40.0, -0.01 * (x - 40.0) ** 2 / 40.0 + 0.002 * y])


def synthetic_field(seed: int = 0) -> dict:
    """Coordinates, measured (deformation + rigid motion + noise) and computed (deformation) of a field block."""
    points = grid_points()
    n_p = len(points)
    rng = np.random.default_rng(seed)
    keep = np.ones((len(FRAMES), 2, n_p), bool)
    for entry in DROPPED:
        keep[entry] = False
    computed = np.stack([deformation(points, c) for c in FRAMES])  # (frames, 2 * n_p)
    rigid = np.stack([rigid_modes(points, (0, 1)) @ m for m in MOTIONS])
    measured = computed + rigid + NOISE * rng.standard_normal(computed.shape)
    frame, component, point = np.meshgrid(np.arange(len(FRAMES)), [0, 1], np.arange(n_p), indexing="ij")
    kept = keep.ravel()
    return {"frame": frame.ravel()[kept], "component": component.ravel()[kept], "point": point.ravel()[kept],
            "x": points[point.ravel(), 0][kept], "y": points[point.ravel(), 1][kept],
            "control": FRAMES[frame.ravel()][kept], "measured": measured.ravel()[kept],
            "computed": computed.ravel()[kept], "points": points}


def marginalised_covariance(field) -> object:
    """The block covariance of the field: noise NOISE, every frame's rigid motion marginalised (as build_data)."""
    from fracid.data.covariance_matrix import block_diagonal

    n_p, frames = len(field["points"]), []
    for k in range(len(FRAMES)):
        entries = field["frame"] == k
        frame = with_rigid_motion(Diagonal(np.full(2 * n_p, NOISE**2)), field["points"], (0, 1))
        frames.append(frame.take(field["component"][entries] * n_p + field["point"][entries]))
    return block_diagonal(frames)


def fit_of(field, **noise):
    return field_fit.fit_field(field["x"], field["y"], field["frame"], field["component"], field["measured"],
                        field["computed"], control=field["control"], **noise)


@pytest.fixture(scope="module")
def field():
    return synthetic_field()


@pytest.mark.parametrize("noise", ["std", "covariance"])
def test_the_rigid_motion_of_every_frame_is_recovered_and_the_residual_is_the_noise(field, noise):
    given = ({"std": np.full(field["x"].size, NOISE)} if noise == "std"
             else {"covariance": marginalised_covariance(field)})
    fit = fit_of(field, **given)
    assert fit.noise == noise
    np.testing.assert_allclose(fit.controls, FRAMES)
    # 1 um noise over ~150 values a frame: the translations to 0.5 um, the rotation to 1e-5 rad
    np.testing.assert_allclose(fit.motions[:, :2], MOTIONS[:, :2], atol=5e-4)
    np.testing.assert_allclose(fit.motions[:, 2], MOTIONS[:, 2], atol=1e-5)
    assert np.all((0.75 < fit.rms_std) & (fit.rms_std < 1.25)), fit.rms_std  # u_x, u_y, both: ~1 noise std
    np.testing.assert_allclose(fit.rms_mm, fit.rms_std * NOISE, rtol=0.15)  # the noise is 1 um
    assert fit.values.tolist() == [2 * len(field["points"]) - 1, 2 * len(field["points"]),
                                   2 * len(field["points"]) - 1]
    # the residual is measured - rigid - computed, the rigid part that of the motion fitted
    np.testing.assert_allclose(fit.residual, field["measured"] - fit.rigid - field["computed"])
    first = field["frame"] == 0
    assert np.allclose(fit.rigid[first & (field["component"] == 1)],
                       fit.motions[0, 1] + fit.motions[0, 2] * field["x"][first & (field["component"] == 1)])


def test_without_the_rigid_motion_removed_the_residual_would_be_far_above_the_noise(field):
    """What the fit removes is what matters: the raw residual is several noise stds (so the test above can fail)."""
    raw = field["measured"] - field["computed"]
    assert np.sqrt(np.mean(raw**2)) > 5 * NOISE


def test_the_points_are_told_apart_by_position_without_their_index(field):
    std = np.full(field["x"].size, NOISE)
    by_index = fit_of(field, std=std, point=field["point"])
    by_position = fit_of(field, std=std)
    np.testing.assert_allclose(by_position.motions, by_index.motions, rtol=1e-9, atol=1e-15)


def test_a_missing_computed_frame_has_no_residual(field):
    computed = field["computed"].copy()
    computed[field["frame"] == 2] = np.nan  # the run did not reach the last frame
    fit = field_fit.fit_field(field["x"], field["y"], field["frame"], field["component"], field["measured"], computed,
                       std=np.full(computed.size, NOISE))
    assert np.all(np.isnan(fit.motions[2])) and fit.values[2] == 0 and np.isfinite(fit.motions[:2]).all()
    assert np.all(np.isnan(fit.controls))  # no control given: the frames are numbered in the figures
    assert ff.summary_figure(fit).axes[0].get_xlabel() == "frame [-]"


def test_bad_arguments_are_named(field):
    with pytest.raises(ValueError, match="std .* or covariance"):
        field_fit.fit_field(field["x"], field["y"], field["frame"], field["component"], field["measured"], field["computed"])
    with pytest.raises(ValueError, match="one value per entry"):
        field_fit.fit_field(field["x"][:-1], field["y"], field["frame"], field["component"], field["measured"],
                     field["computed"], std=np.ones(field["x"].size))


def test_frame_figure_maps_measured_computed_and_residual_per_component(field):
    fit = fit_of(field, std=np.full(field["x"].size, NOISE))
    fig = ff.frame_figure(fit, 1, name="dic", control_name="CMOD")
    maps = [ax for ax in fig.axes if ax.get_label() != "<colorbar>"]
    bars = [ax for ax in fig.axes if ax.get_label() == "<colorbar>"]
    assert len(maps) == 6 and len(bars) == 6  # u_x, u_y x measured - rigid, computed, residual; a colour bar each
    titles = [ax.get_title() for ax in maps]
    assert titles[:2] == ["u_x measured - rigid", "u_x computed"] and titles[3:5] == ["u_y measured - rigid",
                                                                                        "u_y computed"]
    assert titles[2].startswith("u_x residual (RMS") and titles[5].startswith("u_y residual (RMS")
    assert all(ax.get_aspect() == 1.0 and ax.get_xlabel() == "x [mm]" and ax.get_ylabel() == "y [mm]" for ax in maps)
    assert [bar.get_ylabel() for bar in bars] == ["u_x [µm]", "u_x [µm]", "u_x residual [µm]", "u_y [µm]",
                                                  "u_y [µm]", "u_y residual [µm]"]
    suptitle = fig._suptitle.get_text()
    assert "dic: frame 2 of 3, CMOD = 0.05 mm" in suptitle and "t_x = 3" in suptitle and "t_y = -8" in suptitle
    assert figures.to_png(fig)[:4] == b"\x89PNG"


def test_one_component_gives_one_row_and_a_few_points_are_scattered():
    points = np.array([[0.0, 0.0], [10.0, 0.0]])  # two points: no triangle, coloured points instead
    fit = field_fit.fit_field(points[:, 0], points[:, 1], [0, 0], [1, 1], [0.001, 0.002], [0.0, 0.001],
                       std=[NOISE, NOISE])
    fig = ff.frame_figure(fit, 0)
    assert len([ax for ax in fig.axes if ax.get_label() != "<colorbar>"]) == 3
    assert fig.axes[0].get_title() == "u_y measured - rigid"


def test_the_triangulation_does_not_bridge_a_hole(field):
    points = field["points"]
    triangulation = ff.hole_free_triangulation(points[:, 0], points[:, 1])
    kept = triangulation.triangles[~triangulation.mask]
    centres = points[kept].mean(axis=1)
    assert not np.any((np.abs(centres[:, 0] - 40.0) < 5.0) & (centres[:, 1] < 8.0))  # none over the notch
    assert triangulation.mask.sum() > 0 and len(kept) > 100  # the face itself is covered


def test_summary_figure_rms_and_rigid_motion_per_frame(field):
    fit = fit_of(field, std=np.full(field["x"].size, NOISE))
    fig = ff.summary_figure(fit, name="dic", control_label="CMOD [mm]")
    rms, translation, rotation = fig.axes
    assert [ax.get_xlabel() for ax in fig.axes] == ["CMOD [mm]"] * 3
    assert rms.get_ylabel() == "residual RMS [noise std]"
    assert translation.get_ylabel() == "rigid translation [µm]"
    assert rotation.get_ylabel() == "rigid rotation theta [µrad]"
    np.testing.assert_allclose(translation.lines[1].get_ydata(), 1e3 * MOTIONS[:, 1], atol=0.5)  # t_y [um]
    np.testing.assert_allclose(rotation.lines[0].get_ydata(), 1e6 * MOTIONS[:, 2], atol=10.0)  # theta [urad]


# ------------------------------------------------------------------------------------ the report


Y_FORCE = np.array([0.0, 10.0, 20.0, 30.0, 20.0, 10.0, 5.0, 2.0])
CONTROL_FORCE = np.linspace(0.0, 0.1, 8)


def field_result(field, std_field):
    """A result of a force curve ("global", 8 points) and the field block ("dic")."""
    n = field["x"].size
    return IdentificationResult(
        names=["c", "beta"], x=np.array([2.5, 300.0]), C=np.diag([0.01, 100.0]),
        y_exp=np.concatenate([Y_FORCE, field["measured"]]), y_fit=np.concatenate([Y_FORCE + 0.5, field["computed"]]),
        std_exp=np.concatenate([np.full(8, 1.0), std_field]), blocks=[("global", 0, 8), ("dic", 8, 8 + n)],
        control=np.concatenate([CONTROL_FORCE, field["control"]]), control_names=["cmod", "cmod"],
        quantities=["force", "u"], converged=True, status="converged")


def images(text) -> list[tuple[str, bytes]]:
    return [(alt, base64.b64decode(data)) for data, alt in re.findall(r'<img src="data:image/png;base64,([^"]+)" '
                                                                      r'alt="([^"]*)"', text)]


def png_width(png: bytes) -> int:
    return struct.unpack(">II", png[16:24])[0]


@pytest.fixture(scope="module")
def field_report(field, tmp_path_factory):
    """The report of a result with a field block, its coordinates given with the marginalised covariance (the
    data's std of the field block is then ~RIGID_STD = 1 mm, as in build_data: useless as a noise level)."""
    covariance = marginalised_covariance(field)
    result = field_result(field, np.sqrt(covariance.diag()))
    coordinates = {k: field[k] for k in ("control", "frame", "component", "point", "x", "y")}
    path = tmp_path_factory.mktemp("field") / "report.html"
    write_report(path, result, fields={"dic": {**coordinates, "covariance": covariance}})
    return result, coordinates, covariance, path.read_text(encoding="utf-8")


def test_report_has_a_field_section_with_maps_and_a_table_per_frame(field_report):
    _, _, _, text = field_report
    assert text.count("<h2>Displacement field dic</h2>") == 1
    section = text[text.index("<h2>Displacement field dic</h2>"):]
    section = section[:section.index("<h2>", 10)]
    alts = [alt for alt, _ in images(section)]
    assert alts == ["field dic summary", "field dic frame1", "field dic frame2", "field dic frame3",
                    "field dic strain frame1", "field dic strain frame2", "field dic strain frame3"]
    rows = re.findall(r"<tr>(.*?)</tr>", section)
    cells = [re.findall(r"<t[dh][^>]*>(.*?)</t[dh]>", row) for row in rows]
    assert cells[0][:3] == ["frame", "CMOD [mm]", "values"] and len(cells) == 1 + len(FRAMES)
    assert [c[1] for c in cells[1:]] == ["0.02", "0.05", "0.1"]
    header = cells[0]
    for row, motion in zip(cells[1:], MOTIONS):
        assert 0.75 < float(row[header.index("RMS [std]")]) < 1.25  # whitened by the covariance: the noise
        assert float(row[header.index("t_y [µm]")]) == pytest.approx(1e3 * motion[1], abs=0.5)


def test_report_draws_no_curve_panel_of_the_field_block(field_report):
    result, _, _, text = field_report
    fit = text[text.index("<h2>Fit</h2>"):text.index("<h2>Displacement field dic</h2>")]
    (alt, png), = images(fit)
    assert alt == "measured and computed curves"
    assert png_width(png) == round(6.4 * figures.DPI)  # one panel (the curve "global"), not two
    assert '<td class="text">global</td>' in fit and '<td class="text">dic</td>' not in fit
    assert "Displacement field block(s) dic" in fit
    fig = figures.fit_figure(result, skip={"dic"})
    assert [ax.get_title() for ax in fig.axes if ax.get_visible()] == ["global"]
    assert len(images(text)) == 2 + 4 + 3  # correlation, fit; the field's summary, 3 frames and their strains


def test_report_of_a_field_block_without_coordinates_names_it_and_draws_no_curve(field, tmp_path):
    result = field_result(field, np.full(field["x"].size, NOISE))
    text = write_report(tmp_path / "r.html", result).read_text(encoding="utf-8")
    assert "<h2>Displacement field dic</h2>" in text and "its point coordinates are not given" in text
    assert len(images(text)) == 2  # correlation, fit (the curve only)
    fit = text[text.index("<h2>Fit</h2>"):text.index("<h2>Displacement field dic</h2>")]
    assert png_width(images(fit)[0][1]) == round(6.4 * figures.DPI)


def test_a_result_without_fields_keeps_its_report(tmp_path):
    """Curve blocks only: no field section, the fit figure as before (two blocks, two panels)."""
    result = IdentificationResult(names=["c"], x=np.array([2.0]), C=np.array([[0.01]]),
                                  y_exp=np.concatenate([Y_FORCE, [1.0, 2.0]]),
                                  y_fit=np.concatenate([Y_FORCE, [1.0, 2.5]]), std_exp=np.ones(10),
                                  blocks=[("global", 0, 8), ("fpz_width", 8, 10)])
    text = write_report(tmp_path / "r.html", result).read_text(encoding="utf-8")
    assert "Displacement field" not in text
    fit = text[text.index("<h2>Fit</h2>"):]
    assert png_width(images(fit)[0][1]) == round(2 * 6.4 * figures.DPI)


def test_write_figures_writes_the_field_maps_as_png(field_report, tmp_path):
    from fracid.cli.identify import write_figures as _write_figures

    result, coordinates, covariance, _ = field_report
    _write_figures(tmp_path / "figures", result, result.control, fields={"dic": {**coordinates,
                                                                                 "covariance": covariance}})
    names = {p.name for p in (tmp_path / "figures").glob("*.png")}
    assert names == {"fit.png", "correlation.png", "field_dic_summary.png", "field_dic_frame1.png",
                     "field_dic_frame2.png", "field_dic_frame3.png", "field_dic_strain_frame1.png",
                     "field_dic_strain_frame2.png", "field_dic_strain_frame3.png"}


def test_a_block_name_is_made_fit_for_a_file_name():
    assert block_view.file_stem("dic/left face 1") == "dic_left_face_1"


# ------------------------------------------------------------------------------------ fracid identify


def small_dic_config(directory: Path) -> Path:
    """examples/dic copied with 2 frames, a coarse mesh and a population of 4: fracid identify in ~15 s."""
    for path in EXAMPLE.glob("*.csv"):
        shutil.copy(path, directory / path.name)
    text = (EXAMPLE / "identify.toml").read_text(encoding="utf-8")
    for old, new in (("h_fine = 2.0", "h_fine = 5.0"), ("h_coarse = 6.0", "h_coarse = 10.0"),
                     ("frames = [1, 2, 3, 4, 5, 6]", "frames = [2, 6]"), ("n = 32", "n = 4"), ("k = 5", "k = 2"),
                     ("groups = 4", "groups = 1\nmax_iterations = 1\nmax_starts = 1")):
        assert old in text, old
        text = text.replace(old, new)
    path = directory / "identify.toml"
    path.write_text(text, encoding="utf-8")
    return path


@pytest.mark.slow
def test_identify_on_a_small_copy_of_the_dic_example_writes_the_field_maps(tmp_path):
    from fracid import cli

    out = tmp_path / "out"
    assert cli.main(["identify", str(small_dic_config(tmp_path)), "--out", str(out), "--workers", "1", "--quiet"]) == 0
    names = {p.name for p in (out / "figures").glob("*.png")}
    assert {"fit.png", "field_summary.png", "field_frame1.png", "field_frame2.png"} <= names
    assert "field_frame3.png" not in names and not any(n.startswith("field_field") for n in names)
    text = (out / "report.html").read_text(encoding="utf-8")
    assert "<h2>Displacement field</h2>" in text and "Displacement field field" not in text
    assert png_width((out / "figures" / "fit.png").read_bytes()) == round(6.4 * figures.DPI)  # the curve alone
    section = text[text.index("<h2>Displacement field</h2>"):]
    alts = [alt for alt, _ in images(section)]
    assert alts[:3] == ["field summary", "field frame1", "field frame2"]
