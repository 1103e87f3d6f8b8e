"""A testing machine's log as machines write it, and DIC frames synchronised with it by time (issue 41, item 3):
the reader (header lines, units rows, decimal commas, units declared by the file, time increasing), the three
ways of placing frames on the log's clock (time stamps, frame rate + trigger offset, the offset matching a
virtual extensometer's opening to the log's CMOD), the field block's keys and the check figure."""

import re
import shutil
from pathlib import Path

import numpy as np
import pytest

from fracid.data import DataError
from fracid.data.dic.synchronise import (extensometer_opening, offset_by_opening, synchronised, times_from_rate,
                                         times_given)
from fracid.data.machine_log import MachineLog, declared_unit, read_machine_log

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "dic"


def cmod_of(t):
    """The synthetic test's CMOD [mm] at time t [s]: slow, then faster (a curve, not a line)."""
    return 0.001 * t + 2e-5 * t ** 2


def force_of(t):
    """Its force [N]: rises to 1000 N at t = 40 s, then softens."""
    return 1000.0 * (t / 40.0) * np.exp(1.0 - t / 40.0)


def write_log(path: Path, t, rows_text=None, header="Zeit;Kraft;CMOD", units="ms;kN;µm") -> Path:
    """A European machine export: two text lines, the column names, a units row, ';' and decimal commas;
    time in ms, force in kN, CMOD in µm."""
    rows = rows_text or [f"{1e3 * ti:.3f};{force_of(ti) / 1e3:.6f};{1e3 * cmod_of(ti):.5f}".replace(".", ",")
                         for ti in t]
    path.write_text("\n".join(["Prüfung;Balken 3", "Datum;28.11.2026", header, units, *rows]) + "\n", encoding="utf-8")
    return path


def read(path, **units):
    columns = {"Kraft": units.get("force", "kN"), "CMOD": units.get("cmod", "um")}
    return read_machine_log(path, "Zeit", columns, units.get("time", "ms"), delimiter=";", decimal=",")


def test_a_european_export_with_header_lines_and_a_units_row_reads_in_s_mm_n(tmp_path):
    t = np.linspace(0.0, 100.0, 201)
    log = read(write_log(tmp_path / "log.csv", t))
    np.testing.assert_allclose(log.time, t, atol=1e-6)
    np.testing.assert_allclose(log.columns["Kraft"], force_of(t), atol=1e-3)
    np.testing.assert_allclose(log.columns["CMOD"], cmod_of(t), atol=1e-8)
    assert log.units == {"Kraft": "N", "CMOD": "mm"} and log.rows[0] == 5
    notes = " ".join(log.notes)
    assert "lines 1, 2 above the header" in notes and "[4] below the header skipped (units)" in notes
    # minutes are read into s too
    minutes = tmp_path / "min.csv"
    write_log(minutes, t, [f"{ti / 60:.6f};1,0;1,0".replace(".", ",") for ti in t], units="min;kN;µm")
    np.testing.assert_allclose(read(minutes, time="min").time, t, atol=1e-3)


@pytest.mark.parametrize("units, header, given, words", [
    ("ms;kN;µm", "Zeit;Kraft;CMOD", {"force": "N"}, ["column 'Kraft' is declared in kN (line 2)", "1000 times off",
                                                     "give 'kN'"]),
    ("ms;kN;µm", "Zeit;Kraft;CMOD", {"cmod": "mm"}, ["column 'CMOD' is declared in um (line 2)", "give 'um'"]),
    ("ms;kN;µm", "Zeit;Kraft;CMOD", {"time": "s"}, ["column 'Zeit' is declared in ms", "give 'ms'"]),
    ("ms;kN;µm", "Zeit;Kraft;CMOD", {"force": "mm"}, ["declared in kN", "a force, not a length",
                                                      "the right column"]),
    ("", "Zeit;Kraft [kN];CMOD", {"force": "N"}, ["column 'Kraft [kN]' is declared in kN (its name", "give 'kN'"]),
])
def test_a_unit_the_file_declares_otherwise_is_refused(tmp_path, units, header, given, words):
    t = np.linspace(0.0, 10.0, 5)
    rows = [f"{1e3 * ti:.1f};1,5;2,5".replace(".", ",") for ti in t]
    path = tmp_path / "log.csv"
    path.write_text("\n".join([header, *([units] if units else []), *rows]) + "\n", encoding="utf-8")
    force = "Kraft [kN]" if "[" in header else "Kraft"
    columns = {force: given.get("force", "kN"), "CMOD": given.get("cmod", "um")}
    with pytest.raises(DataError) as err:
        read_machine_log(path, "Zeit", columns, given.get("time", "ms"), delimiter=";", decimal=",")
    assert str(path) in str(err.value)
    for word in words:
        assert word in str(err.value)
    # as declared, it reads
    columns = {force: "kN", "CMOD": "um"}
    assert read_machine_log(path, "Zeit", columns, "ms", delimiter=";", decimal=",").columns[force][0] == 1500.0


def test_declared_units_in_names_and_rows():
    assert [declared_unit(text) for text in ("[kN]", "Force (kN)", "µm", "sec", "Zeit", "mm/s", "N")] == \
           ["kN", "kN", "um", "s", None, None, "N"]


@pytest.mark.parametrize("times, row, words", [
    ([0.0, 1.0, 0.5, 2.0], 7, "row 7 (500 ms) does not follow row 6 (1000 ms)"),     # a restarted clock
    ([0.0, 1.0, 1.0, 2.0], 7, "row 7 (1000 ms) does not follow row 6 (1000 ms)"),    # a repeated sample
    ([3.0, 2.0, 1.0, 0.0], 5, "(3 rows)"),                                    # sorted the wrong way
])
def test_a_time_not_increasing_is_refused_naming_the_row(tmp_path, times, row, words):
    path = write_log(tmp_path / "log.csv", None, [f"{1e3 * t:g};1;1" for t in times])
    with pytest.raises(DataError) as err:
        read(path)
    message = str(err.value)
    assert str(path) in message and "column 'Zeit' must increase strictly" in message and words in message
    assert f"row {row}" in message


def test_a_frame_outside_the_log_is_refused_naming_it(tmp_path):
    log = read(write_log(tmp_path / "log.csv", np.linspace(0.0, 100.0, 11)))
    log.at([10.0, 100.0], [1, 2])  # the ends are in
    with pytest.raises(DataError) as err:
        log.at([10.0, 50.0, 120.0], [1, 2, 3])
    message = str(err.value)
    assert str(tmp_path / "log.csv") in message and "frame 3 at t = 120 s" in message
    assert "0 to 100 s" in message and "column 'Zeit', rows 5 to 15" in message and "frame 1" not in message


@pytest.fixture
def log():
    t = np.linspace(0.0, 120.0, 1201)
    return MachineLog("log.csv", t, {"CMOD": cmod_of(t), "F": force_of(t)}, {"CMOD": "mm", "F": "N"},
                      np.arange(2, 1203), "time")


def test_time_stamps_and_frame_rate_give_each_frame_the_logs_control(log):
    frames = (3, 5, 8)
    stamps = times_given(frames, [10.0, 30.0, 60.0], offset=2.5)
    values = synchronised(log, stamps, "CMOD", "F").values
    np.testing.assert_allclose(values["CMOD"], cmod_of(np.array([12.5, 32.5, 62.5])), rtol=1e-4)
    np.testing.assert_allclose(values["F"], force_of(np.array([12.5, 32.5, 62.5])), rtol=1e-3)
    # frame i at offset + i / rate: frame 3 at 7 + 3 / 0.2 = 22 s
    rated = times_from_rate(frames, 0.2, 7.0)
    np.testing.assert_allclose(rated.times, [22.0, 32.0, 47.0])
    np.testing.assert_allclose(synchronised(log, rated, "CMOD").values["CMOD"], cmod_of(rated.times), rtol=1e-4)
    with pytest.raises(DataError, match="frame 8 at t = 127 s outside"):
        synchronised(log, times_from_rate(frames, 0.2, 87.0), "CMOD")
    with pytest.raises(DataError, match=r"frame 5 \(20 s\) is not after frame 3 \(30 s\)"):
        times_given(frames, [30.0, 20.0, 60.0])


def camera(times, rng, noise=0.0005):
    """DIC points on a 2 mm grid around a notch at x = 0 and their displacements at the frame times: the two
    halves open by cmod_of(t) (the right half moves by +cmod/2, the left by -cmod/2), with noise [mm]."""
    x, y = np.meshgrid(np.arange(-9.0, 10.0, 2.0), np.arange(1.0, 10.0, 2.0))
    points = np.column_stack([x.ravel(), y.ravel()])
    side = np.sign(points[:, 0])
    u = np.zeros((len(times), len(points), 2))
    u[:, :, 0] = 0.5 * cmod_of(np.asarray(times))[:, None] * side[None, :]
    return points, u + rng.normal(0.0, noise, u.shape)


@pytest.mark.parametrize("offset, rate, noise", [(17.3, 0.1, 0.0005), (3.05, 0.25, 0.0), (41.0, 0.1, 0.002)])
def test_the_offset_is_found_from_the_opening_within_one_frame_interval(log, offset, rate, noise):
    frames = np.arange(0, 7)
    relative = frames / rate
    points, u = camera(offset + relative, np.random.default_rng(7), noise)
    opening, note = extensometer_opening(points, u, [-1.2, 1.0], [1.2, 1.0])
    assert "points [-1.0, 1.0] and [1.0, 1.0]" in note
    found = offset_by_opening(log.time, log.columns["CMOD"], frames, relative, opening)
    interval = 1.0 / rate
    assert abs(found.offset - offset) < interval
    assert abs(found.offset - offset) <= found.uncertainty and found.uncertainty >= 0.5 * interval
    assert found.method == "extensometer" and not any(n.startswith("WARNING") for n in found.notes)
    np.testing.assert_allclose(found.times, relative + found.offset)


def test_an_opening_that_does_not_fix_the_offset_is_warned(log):
    # the frames see no opening while the log's CMOD is flat: every offset before it rises fits
    t = log.time
    flat = np.where(t < 80.0, 0.0, 0.01 * (t - 80.0))
    relative = np.arange(5) * 1.0
    found = offset_by_opening(t, flat, range(5), relative, np.zeros(5))
    assert any("WARNING: offsets from 0 to" in n and "uncertain" in n for n in found.notes)
    assert found.uncertainty > 30.0
    # the same frames on the rising part: no warning
    rising = offset_by_opening(t, flat, range(5), relative, 0.01 * (relative + 10.0))
    assert not any(n.startswith("WARNING") for n in rising.notes) and abs(rising.offset - 90.0) < 1.0


@pytest.mark.parametrize("a, b, words", [
    ([0.0, 1.0], [0.0, 1.0], "its two ends coincide"),
    ([0.9, 1.0], [1.1, 1.0], "both ends are nearest the same DIC point [1.0, 1.0]"),
    ([-1.0, 1.0], [60.0, 1.0], "the nearest DIC point is 51 mm away"),
])
def test_an_extensometer_off_the_points_is_refused(a, b, words):
    points, u = camera([1.0, 2.0], np.random.default_rng(0))
    with pytest.raises(DataError) as err:
        extensometer_opening(points, u, a, b)
    assert words in str(err.value)


def test_matching_needs_two_frames_and_a_log_long_enough(log):
    with pytest.raises(DataError, match="opening at 1 frame"):
        offset_by_opening(log.time, log.columns["CMOD"], [1, 2], [0.0, 1.0], [0.01, np.nan])
    with pytest.raises(DataError, match="the frames span 200 s, longer than the log"):
        offset_by_opening(log.time, log.columns["CMOD"], [1, 2], [0.0, 200.0], [0.01, 0.02])


# ------------------------------------------------------------------------ the field block's keys


def _example_with_log(d: Path, block: str, frame_times=None) -> Path:
    """examples/dic copied to ``d`` with a machine log written from its load curve (CMOD-controlled at 1 µm/s,
    t = 1000 s/mm * cmod + 5 s), the frame table's control column replaced by ``frame_times`` [ms] if given, and
    the field block's control_column replaced by ``block``."""
    for path in EXAMPLE.iterdir():
        if path.suffix in (".csv", ".toml"):
            shutil.copy(path, d / path.name)
    curve = np.loadtxt(EXAMPLE / "load_cmod.csv", delimiter=",", skiprows=1)
    cmod = np.r_[0.0, curve[:, 0]]
    force = np.r_[0.0, curve[:, 1]]
    write_log(d / "log.csv", None, [f"{1e3 * (5.0 + 1e3 * c):.3f};{f / 1e3:.7f};{1e3 * c:.4f}".replace(".", ",")
                                    for c, f in zip(cmod, force)])
    if frame_times is not None:
        lines = (d / "frames.csv").read_text().splitlines()
        rows = [line.split(",") for line in lines]
        rows[0][2] = "t_ms"
        for row, t in zip(rows[1:], frame_times):
            row[2] = f"{t:g}"
        (d / "frames.csv").write_text("\n".join(",".join(row) for row in rows) + "\n")
    text = (EXAMPLE / "identify.toml").read_text()
    text, n = re.subn(r'^control_column = "cmod_mm"( +#.*)?\n(sigma)', block + r"\n\2", text, flags=re.M)
    assert n == 1
    (d / "identify.toml").write_text(text)
    return d / "identify.toml"


LOG_KEYS = ('machine_log = "log.csv"\nlog_delimiter = ";"\nlog_decimal = ","\nlog_time_column = "Zeit"\n'
            'log_time_unit = "ms"\nlog_control_column = "CMOD"\nlog_control_unit = "um"\nlog_force_column = "Kraft"\n'
            'log_force_unit = "kN"\n')
CMOD = np.array([0.02, 0.034, 0.05, 0.08, 0.12, 0.2])


def _field(path):
    from fracid.config import load_config

    config = load_config(path)
    return config, next(exp for exp in config.experiments if exp.kind == "field")


def test_the_field_block_takes_each_frames_control_from_the_log(tmp_path):
    from fracid.config.builders import build_specimen
    from fracid.inverse.experiments.field import field_block

    stamps = 1e3 * (5.0 + 1e3 * CMOD) - 2000.0  # [ms] on the camera's clock, 2 s behind the log's
    cfg = _example_with_log(tmp_path, LOG_KEYS + 'frame_time_column = "t_ms"\nframe_time_unit = "ms"\n'
                            "trigger_offset = 2.0", stamps)
    config, field = _field(cfg)
    assert field.log.file == tmp_path / "log.csv" and field.control_column == "CMOD (log)"
    block = field_block(field, build_specimen(config, field))
    np.testing.assert_allclose(block.frames, CMOD, rtol=1e-6)


BY_STAMPS = LOG_KEYS + 'frame_time_column = "t_ms"\nframe_time_unit = "ms"'
STAMPS = 1e3 * (5.0 + 1e3 * CMOD)


@pytest.mark.parametrize("block, stamps, key, words", [
    ('control_column = "cmod_mm"\nlog_time_unit = "ms"', None, "log_time_unit", ["needs machine_log"]),
    ('control_column = "cmod_mm"\n' + BY_STAMPS, STAMPS, "control_column", ["remove control_column"]),
    (LOG_KEYS + "frame_rate = 0.1", None, "trigger_offset", ["frame number 0"]),
    (BY_STAMPS + "\nframe_rate = 0.1", STAMPS, "frame_rate", ["one of them: both are given"]),
    (LOG_KEYS + "frame_rate = 0.1\ntrigger_offset = 1.0\nsynchronise = \"opening\"", None, "trigger_offset",
     ["finds the offset"]),
    (LOG_KEYS + 'frame_rate = 0.1\nsynchronise = "opening"', None, "extensometer", ["two ends"]),
    (BY_STAMPS.replace('log_decimal = ","', 'log_decimal = ";"'), STAMPS, "log_decimal", ["must be one of '.', ','"]),
    (BY_STAMPS.replace('log_force_unit = "kN"', 'log_force_unit = "N"'), STAMPS, "machine_log",
     ["column 'Kraft' is declared in kN (line 4)", "1000 times off"]),
    (BY_STAMPS, STAMPS + 5000.0, "frame_time_column", ["frame 6 at t = 210 s outside the log's time range 5 to 205 s",
                                                        "column 'Zeit', rows 5 to 45"]),
])
def test_the_log_keys_are_refused_naming_the_key(tmp_path, block, stamps, key, words):
    from fracid.config import ConfigError

    with pytest.raises(ConfigError) as err:
        _field(_example_with_log(tmp_path, block, stamps))
    message = str(err.value)
    assert f"experiments[1].{key}" in message, message
    for word in words:
        assert word in message, message


def test_the_check_figure_marks_the_frames_on_the_load_curve(tmp_path, log):
    from fracid.report.sync_figure import synchronisation_figure, write_synchronisation_figure

    sync = synchronised(log, times_from_rate((1, 2, 3), 0.1, 5.0), "CMOD", "F")
    fig = synchronisation_figure(sync)
    left, right = fig.axes[:2]
    assert left.get_xlabel() == "CMOD [mm]" and left.get_ylabel() == "F [N]"
    np.testing.assert_allclose(left.lines[1].get_xdata(), sync.values["CMOD"])  # the frames, on the curve
    assert [t.get_text() for t in left.texts] == ["1", "2", "3"] and "frame rate" in right.get_title()
    path = write_synchronisation_figure(sync, tmp_path / "sync.png")
    assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    with pytest.raises(FileExistsError):
        write_synchronisation_figure(sync, path)
    without_force = synchronisation_figure(synchronised(log, times_from_rate((1, 2), 0.1, 5.0), "CMOD"))
    assert without_force.axes[0].get_xlabel() == "time [s]"


def test_the_field_block_finds_the_offset_from_an_extensometer(tmp_path):
    from fracid.config.builders import build_specimen
    from fracid.inverse.experiments.field import field_block

    _example_with_log(tmp_path, 'control_column = "cmod_mm"')
    # a camera at 0.05 frames per s whose frame 0 is at 10 s on the log's clock: frame i sees the log's CMOD at
    # t = 10 + 20 i, i.e. (t - 5) / 1000 mm; points on either side of the notch (2 mm wide) open by it
    cmod = (10.0 + 20.0 * np.arange(1, 7) - 5.0) / 1e3
    x, y = np.meshgrid([-9.0, -6.0, -3.0, 3.0, 6.0, 9.0], [2.0, 5.0, 8.0])
    rows = ["frame,file", *(f"{i},cloud{i}.csv" for i in range(1, 7))]
    (tmp_path / "cam.csv").write_text("\n".join(rows) + "\n")
    for i, c in enumerate(cmod, start=1):
        u = 0.5 * c * np.sign(x.ravel())
        lines = ["X,Y,U,V", *(f"{a},{b},{du:.9f},0" for a, b, du in zip(x.ravel(), y.ravel(), u))]
        (tmp_path / f"cloud{i}.csv").write_text("\n".join(lines) + "\n")
    text = (tmp_path / "identify.toml").read_text()
    start, end = text.index('[[experiments]]                     # the DIC field'), text.index("[identify]")
    block = ('[[experiments]]\nkind = "field"\nframes_file = "cam.csv"\nstd = 0.001\n' + LOG_KEYS +
             'frame_rate = 0.05\nsynchronise = "opening"\nextensometer = [[-3.0, 2.0], [3.0, 2.0]]\n\n')
    (tmp_path / "identify.toml").write_text(text[:start] + block + text[end:])
    config, field = _field(tmp_path / "identify.toml")
    assert field.log.synchronise == "opening" and field.log.extensometer == ((-3.0, 2.0), (3.0, 2.0))
    built = field_block(field, build_specimen(config, field))
    np.testing.assert_allclose(built.frames, cmod, atol=2e-5)  # the offset within 0.02 s here
    note = next(n for n in built.data.notes if "frames matched to the log's CMOD" in n)
    offset, uncertainty = map(float, re.search(r"offset (\S+) s \+- (\S+) s", note).groups())
    assert abs(offset - 10.0) < 20.0 and abs(offset - 10.0) <= uncertainty and uncertainty == pytest.approx(10.0)


def test_the_report_shows_the_synchronised_frames_on_the_load_curve(tmp_path):
    from fracid.config import build_data, build_operator, build_view_coordinates, load_config
    from fracid.report.field_figures import field_view

    stamps = 1e3 * (5.0 + 1e3 * CMOD) - 2000.0
    cfg = load_config(_example_with_log(tmp_path, LOG_KEYS + 'frame_time_column = "t_ms"\nframe_time_unit = "ms"\n'
                                        "trigger_offset = 2.0", stamps))
    data = build_data(cfg)
    operator = build_operator(cfg, data)
    info = build_view_coordinates(cfg, operator, data)["field"]
    assert info["sync"] is not None
    np.testing.assert_allclose(info["sync"].values["CMOD"], CMOD, rtol=1e-6)
    _, start, stop = data.blocks[1]
    view = field_view("field", info, data.y[start:stop], data.y[start:stop], None, "CMOD [mm]")
    assert "field_sync" in view.figures and view.png("field_sync")[:4] == b"\x89PNG"


# ------------------------------------------------------------------------ fracid check writes the check figure


def _check(config, out, *extra):
    from fracid.cli.dispatch import main

    return main(["check", str(config), "--no-time", "--out", str(out), *extra])


def test_check_writes_the_synchronisation_figure_and_names_it(tmp_path, capsys):
    from fracid.store.outputs import MANIFEST

    stamps = 1e3 * (5.0 + 1e3 * CMOD)
    config = _example_with_log(tmp_path, LOG_KEYS + 'frame_time_column = "t_ms"\nframe_time_unit = "ms"', stamps)
    out = tmp_path / "out"
    assert _check(config, out) == 0
    figure = out / "check" / "field_sync.png"
    assert figure.read_bytes()[:4] == b"\x89PNG" and "check" in (out / MANIFEST).read_text()
    text = capsys.readouterr().out
    assert f"check figure of 'field': {figure} (the frames on the machine log's load curve and clock, time stamps" \
        in text
    assert _check(config, out) == 0  # its own file: written again


def test_check_without_a_log_writes_nothing(tmp_path):
    config = _example_with_log(tmp_path, 'control_column = "cmod_mm"')
    out = tmp_path / "out"
    assert _check(config, out) == 0
    assert not out.exists()


def test_check_does_not_replace_a_check_directory_it_did_not_write(tmp_path, capsys):
    stamps = 1e3 * (5.0 + 1e3 * CMOD)
    config = _example_with_log(tmp_path, LOG_KEYS + 'frame_time_column = "t_ms"\nframe_time_unit = "ms"', stamps)
    (tmp_path / "out" / "check").mkdir(parents=True)
    (tmp_path / "out" / "check" / "field_sync.png").write_text("mine")
    assert _check(config, tmp_path / "out") == 2
    assert "was not written by fracid" in capsys.readouterr().err
    assert (tmp_path / "out" / "check" / "field_sync.png").read_text() == "mine"
