"""Hostile-input cases of issue 41, item 3 (a testing machine's log); run by tests/test_hostile_inputs.py.

Each case copies examples/dic, writes the testing machine's log of its load curve as a European machine exports it
(two text lines, the column names, a units row ``ms;kN;µm``, semicolons and decimal commas; CMOD-controlled at
1 µm/s from t = 5 s), replaces the frame table's control column by time stamps [ms] and the field block's
control_column by the log keys, and changes one thing. ``fracid check``: exit 0 with the field's values, or 2 with
the key and the cause.
"""

from __future__ import annotations

import numpy as np

from hostile_dic import EXAMPLE, dic_case

LOG_KEYS = ('machine_log = "log.csv"\nlog_delimiter = ";"\nlog_decimal = ","\nlog_time_column = "Zeit"\n'
            'log_time_unit = "ms"\nlog_control_column = "CMOD"\nlog_control_unit = "um"\n'
            'log_force_column = "Kraft"\nlog_force_unit = "{force}"\nframe_time_column = "t_ms"\n'
            'frame_time_unit = "ms"')


def _keys(force_unit: str = "kN"):
    return [(r'^control_column = "cmod_mm" +# each frame.*$', LOG_KEYS.replace("{force}", force_unit))]


def _log(shift_ms: float = 0.0, restart: bool = False):
    """The frame table's cmod_mm column replaced by the frames' time stamps [ms] (+ ``shift_ms``) and log.csv
    written; ``restart``: the log's clock restarts after its 20th sample."""
    def files(d):
        curve = np.loadtxt(EXAMPLE / "load_cmod.csv", delimiter=",", skiprows=1)
        cmod, force = np.r_[0.0, curve[:, 0]], np.r_[0.0, curve[:, 1]]
        t_ms = 1e3 * (5.0 + 1e3 * cmod)
        if restart:
            t_ms[20:] -= t_ms[20] - 10.0
        rows = [f"{t:.3f};{f / 1e3:.7f};{1e3 * c:.4f}".replace(".", ",") for t, f, c in zip(t_ms, force, cmod)]
        (d / "log.csv").write_text("\n".join(["Prüfung;Balken 3", "Datum;28.11.2026", "Zeit;Kraft;CMOD",
                                               "ms;kN;µm", *rows]) + "\n", encoding="utf-8")
        lines = (d / "frames.csv").read_text(encoding="utf-8").splitlines()
        table = [lines[0].replace("cmod_mm", "t_ms")]
        for line in lines[1:]:
            cells = line.split(",")
            cells[2] = f"{1e3 * (5.0 + 1e3 * float(cells[2])) + shift_ms:g}"
            table.append(",".join(cells))
        (d / "frames.csv").write_text("\n".join(table) + "\n", encoding="utf-8")
    return files


CASES: dict = {
    "machine-log-frames-synchronised": dic_case(0, [], _keys(), frame=_log(), values=3444),
    "machine-log-frame-after-the-log": dic_case(2, [
        "experiments[1].frame_time_column", "frame 6 at t = 210 s outside the log's time range 5 to 205 s",
        "column 'Zeit', rows 5 to 45"], _keys(), frame=_log(shift_ms=5000.0)),
    "machine-log-clock-restarts": dic_case(2, [
        "experiments[1].machine_log", "column 'Zeit' must increase strictly", "row 25 (10 ms) does not follow row 24"],
        _keys(), frame=_log(restart=True)),
    "machine-log-force-in-kN-read-as-N": dic_case(2, [
        "experiments[1].machine_log", "column 'Kraft' is declared in kN (line 4)", "1000 times off"],
        _keys("N"), frame=_log()),
}
