"""The keys of a field block (``kind = "field"``) that take each frame's control and force from the testing
machine's log, synchronised by time (:mod:`fracid.data.machine_log`, :mod:`fracid.data.dic.synchronise`).

With ``machine_log`` the frame table needs no control column: the frames are placed on the log's clock

- by their time stamps (``frame_time_column``, plus ``trigger_offset``: the log's clock minus the camera's), or
- by their numbers (``frame_rate``: frame number i at ``trigger_offset + i / frame_rate``), or
- with ``synchronise = "opening"``, by the offset that matches the opening the DIC measures between the two points
  of ``extensometer`` to the log's control column (then the CMOD): the frames' times relative to each other come
  from ``frame_time_column`` or ``frame_rate``, the offset is found, with its uncertainty;

and each frame's control (and force) is the log's, interpolated at its time.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from fracid.data.errors import DataError
from fracid.data.machine_log import FORCE_UNITS, LENGTH_UNITS, TIME_UNITS
from fracid.inverse.experiments.vocabulary import choices_text, file_format
from fracid.settings.keys import UNSET, Key, Said

_WITH_LOG = Said("required with machine_log")


#: the keys of a field block's machine log, each described
LOG_KEY_DOCS = {
    "machine_log": Key(UNSET, "", "a CSV file path", "The testing machine's log (time, control, force): each frame's "
                       "control and force are read from it at the frame's time (control_column is then not given)."),
    "log_time_column": Key(_WITH_LOG, "", "a column name", "The log's column of the time."),
    "log_time_unit": Key("s", "", choices_text(TIME_UNITS), "The unit of the log's time."),
    "log_control_column": Key(_WITH_LOG, "", "a column name", "The log's column of the control quantity (the "
                              "specimen's, e.g. the CMOD; with synchronise = \"opening\" it must be the CMOD)."),
    "log_control_unit": Key("mm", "", choices_text(LENGTH_UNITS), "The unit of the log's control column."),
    "log_force_column": Key(UNSET, "", "a column name", "The log's column of the force (shown on the check figure)."),
    "log_force_unit": Key("N", "", choices_text(FORCE_UNITS), "The unit of the log's force column."),
    "log_delimiter": Key(Said("the block's delimiter"), "", "as delimiter", "The cell separator of the log."),
    "log_decimal": Key(Said("the block's decimal"), "", "as decimal", "The decimal mark of the log."),
    "frame_time_column": Key(UNSET, "", "a column name; this or frame_rate",
                             "The frame table's column of each frame's time stamp."),
    "frame_time_unit": Key("s", "", choices_text(TIME_UNITS), "The unit of frame_time_column."),
    "frame_rate": Key(UNSET, "frames per s", "> 0; this or frame_time_column",
                      "Frame number i is taken at trigger_offset + i / frame_rate."),
    "trigger_offset": Key(Said("0 with frame_time_column; required with frame_rate"), "s", "a number",
                          "The log's time of frame number 0 (frame_rate), or the log's clock minus the camera's "
                          "(frame_time_column); not given with synchronise = \"opening\", which finds it."),
    "synchronise": Key("time", "", '"time" | "opening"', '"time": the frames\' times as given; "opening": shifted '
                       "by the offset matching the opening at extensometer to the log's control (the CMOD), found "
                       "with its uncertainty (at least half a frame interval)."),
    "extensometer": Key(UNSET, "mm", "[[x1, y1], [x2, y2]]", "synchronise = \"opening\": a virtual extensometer's "
                        "two ends across the notch in the specimen frame; the DIC points nearest them are used."),
}
LOG_KEYS = tuple(LOG_KEY_DOCS)


@dataclass(frozen=True)
class LogSettings:
    """The machine-log keys of a field block, checked (``file`` absolute)."""

    file: Path
    time_column: str
    control_column: str
    time_unit: str = "s"
    control_unit: str = "mm"
    force_column: str | None = None
    force_unit: str = "N"
    delimiter: str = ","
    decimal: str = "."
    frame_time_column: str | None = None
    frame_time_unit: str = "s"
    frame_rate: float | None = None
    trigger_offset: float = 0.0
    synchronise: str = "time"
    extensometer: tuple | None = None

    @property
    def control_name(self) -> str:
        """The name of the frames' control values taken from the log (the block's control column)."""
        return f"{self.control_column} (log)"

    @property
    def timing_key(self) -> str:
        """The key that places the frames in time (blamed when a frame falls outside the log)."""
        return "frame_time_column" if self.frame_time_column is not None else "frame_rate"


class LogKeyError(DataError):
    """A DataError of the log or the synchronisation, with the key it is about (``key``)."""

    def __init__(self, key: str, message: str):
        super().__init__(message)
        self.key = key


def _column(ck, prefix: str, raw: dict, name: str) -> str:
    if name not in raw:
        ck.missing(f"{prefix}.{name}", "a column name of the log (machine_log is given)")
    return ck.string(f"{prefix}.{name}", raw[name], "must be a column name (string)")


def _timing(ck, prefix: str, raw: dict, synchronise: str) -> dict:
    """frame_time_column / frame_time_unit / frame_rate / trigger_offset / extensometer, checked together."""
    given = [k for k in ("frame_time_column", "frame_rate") if k in raw]
    if len(given) != 1:
        what = "both are given" if given else "neither is given"
        ck.fail(f"{prefix}.{(given or ['frame_rate'])[-1]}", raw.get((given or ["frame_rate"])[-1]),
                f"give the frames' times by frame_time_column (a column of the frame table) or by frame_rate [per s] "
                f"(frame i at trigger_offset + i / frame_rate), one of them: {what}")
    out = dict(frame_time_unit=ck.choice(f"{prefix}.frame_time_unit", raw.get("frame_time_unit", "s"),
                                         tuple(TIME_UNITS)))
    if "frame_time_column" in raw:
        out["frame_time_column"] = ck.string(f"{prefix}.frame_time_column", raw["frame_time_column"],
                                             "must be a column name of the frame table (string)")
    else:
        out["frame_rate"] = ck.number(f"{prefix}.frame_rate", raw["frame_rate"], "must be a number > 0 [frames per s]",
                                      lambda v: v > 0)
    if synchronise == "opening":
        if "trigger_offset" in raw:
            ck.fail(f"{prefix}.trigger_offset", raw["trigger_offset"], 'synchronise = "opening" finds the offset: '
                    'remove trigger_offset, or set synchronise = "time" to use it')
        if "extensometer" not in raw:
            ck.missing(f"{prefix}.extensometer", 'synchronise = "opening" needs the extensometer\'s two ends '
                       "[[x1, y1], [x2, y2]] [mm] across the notch")
        value, allowed = raw["extensometer"], "must be two points [[x1, y1], [x2, y2]] [mm] across the notch"
        if not isinstance(value, list) or len(value) != 2:
            ck.fail(f"{prefix}.extensometer", value, allowed)
        out["extensometer"] = tuple(ck.pair(f"{prefix}.extensometer", point, allowed) for point in value)
    else:
        if "extensometer" in raw:
            ck.fail(f"{prefix}.extensometer", raw["extensometer"], 'is used by synchronise = "opening" only')
        if "frame_rate" in raw and "trigger_offset" not in raw:
            ck.missing(f"{prefix}.trigger_offset", "the log's time [s] of frame number 0 (frame_rate is given), or "
                       'synchronise = "opening" with an extensometer to find it')
        out["trigger_offset"] = ck.number(f"{prefix}.trigger_offset", raw.get("trigger_offset", 0.0),
                                          "must be a number [s]")
    return out


def read_log_settings(ck, prefix: str, raw: dict, base: Path) -> LogSettings | None:
    """The block's :class:`LogSettings`, None without ``machine_log`` (then no other log key may be given)."""
    if "machine_log" not in raw:
        for name in LOG_KEYS:
            if name in raw:
                ck.fail(f"{prefix}.{name}", raw[name], "needs machine_log = the testing machine's log (CSV)")
        return None
    if "control_column" in raw:
        ck.fail(f"{prefix}.control_column", raw["control_column"], "the frames' control comes from machine_log's "
                "log_control_column: remove control_column (or machine_log)")
    file = ck.file(f"{prefix}.machine_log", raw["machine_log"], base)
    delimiter, decimal = file_format(ck, prefix, raw, "log_", file_format(ck, prefix, raw))
    synchronise = ck.choice(f"{prefix}.synchronise", raw.get("synchronise", "time"), ("time", "opening"))
    force = _column(ck, prefix, raw, "log_force_column") if "log_force_column" in raw else None
    return LogSettings(
        file=file, time_column=_column(ck, prefix, raw, "log_time_column"),
        control_column=_column(ck, prefix, raw, "log_control_column"),
        time_unit=ck.choice(f"{prefix}.log_time_unit", raw.get("log_time_unit", "s"), tuple(TIME_UNITS)),
        control_unit=ck.choice(f"{prefix}.log_control_unit", raw.get("log_control_unit", "mm"), tuple(LENGTH_UNITS)),
        force_column=force,
        force_unit=ck.choice(f"{prefix}.log_force_unit", raw.get("log_force_unit", "N"), tuple(FORCE_UNITS)),
        delimiter=delimiter, decimal=decimal, synchronise=synchronise, **_timing(ck, prefix, raw, synchronise))


def frame_table_columns(log: LogSettings | None, control_column: str) -> list[str]:
    """The load columns read from the frame table: the control column without a log, the time stamps with one."""
    if log is None:
        return [control_column]
    return [] if log.frame_time_column is None else [log.frame_time_column]


def _frame_times(dic, log: LogSettings, machine):
    """The frames' :class:`~fracid.data.dic.synchronise.FrameTimes` on the log's clock."""
    from fracid.data.dic.synchronise import extensometer_opening, offset_by_opening, times_from_rate, times_given
    from fracid.data.machine_log import TIME_UNITS as scales

    if log.frame_time_column is not None:
        own = dic.load[log.frame_time_column] * scales[log.frame_time_unit]
        what = f"frame table column {log.frame_time_column!r}"
    else:
        own = np.array(dic.frames, dtype=float) / log.frame_rate
        what = "frame numbers / frame_rate"
    if log.synchronise == "time":
        if log.frame_time_column is not None:
            return times_given(dic.frames, own, log.trigger_offset, what)
        return times_from_rate(dic.frames, log.frame_rate, log.trigger_offset)
    try:
        opening, note = extensometer_opening(dic.points, dic.u, *log.extensometer)
    except DataError as err:
        raise LogKeyError("extensometer", str(err)) from None
    found = offset_by_opening(machine.time, machine.columns[log.control_column], dic.frames, own, opening)
    return replace(found, notes=(note, *found.notes))


def synchronise_frames(dic, log: LogSettings, frames=None):
    """(the DicData with the log's control, and force, as load columns; the
    :class:`~fracid.data.dic.synchronise.SynchronisedFrames`) of the frames ``frames`` (all if None).

    Raises
    ------
    LogKeyError
        Naming the key: the log unreadable (``machine_log``), a frame outside its time range (the timing key), the
        extensometer off the measured points.
    """
    from fracid.data.dic.synchronise import synchronised
    from fracid.data.machine_log import read_machine_log

    columns = {log.control_column: log.control_unit, **({log.force_column: log.force_unit} if log.force_column else {})}
    try:
        machine = read_machine_log(log.file, log.time_column, columns, log.time_unit, log.delimiter, log.decimal)
    except DataError as err:
        raise LogKeyError("machine_log", str(err)) from None
    dic = dic if frames is None else dic.at_frames(frames)
    try:
        times = _frame_times(dic, log, machine)
        synced = synchronised(machine, times, log.control_column, log.force_column)
    except LogKeyError:
        raise
    except DataError as err:
        raise LogKeyError(log.timing_key if log.synchronise == "time" else "extensometer", str(err)) from None
    load = {log.control_name: synced.values[log.control_column]}
    if log.force_column is not None:
        load[f"{log.force_column} (log)"] = synced.values[log.force_column]
    notes = (*machine.notes, *times.notes)
    return replace(dic, load={**dic.load, **load}, source=(*dic.source, str(log.file)),
                   notes=(*dic.notes, *notes)), synced


__all__ = ["LOG_KEYS", "LOG_KEY_DOCS", "LogKeyError", "LogSettings", "frame_table_columns", "read_log_settings",
           "synchronise_frames"]
