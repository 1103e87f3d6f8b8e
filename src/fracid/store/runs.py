"""A persistent store of forward runs: SQLite in WAL mode, one row per run, records as JSON with arrays.

A run is identified by a key, the SHA-256 of a canonical JSON of everything that determines it
(:func:`key_for`). Its record is a JSON-like dict that may hold numpy arrays, stored losslessly
(:func:`fracid.store.records.encode_record`, :func:`fracid.store.records.decode_record`).

Concurrency: any number of processes may read a store, but only one process should write it. In a
batch (:func:`fracid.runtime.batch.run_batch`) the workers compute and return records; the parent process
alone writes them. A :class:`RunStore` cannot be sent to another process.

Durability: every :meth:`RunStore.put` is its own transaction. SQLite in WAL mode guarantees that a
process killed at any moment (SIGKILL included) loses no committed run and leaves no partial one.
With ``synchronous=NORMAL`` an operating-system crash or power loss may roll back the last commits,
but never corrupts the file.
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
import math
import numbers
import os
import sqlite3
import threading
import time
from collections.abc import Iterable, Mapping
from typing import Self

import numpy as np

from fracid.store.records import decode_record, encode_record, require_str_key

__all__ = ["NotARunStore", "RunStore", "UndecodableRecord", "key_for"]

_SIGNIFICANT_DIGITS = 12
_EXACT_INT_LIMIT = 10**_SIGNIFICANT_DIGITS
_SQL_VARIABLES_PER_QUERY = 500

_SCHEMA = """
CREATE TABLE IF NOT EXISTS runs (
    key TEXT PRIMARY KEY,
    study TEXT,
    created REAL,
    status TEXT,
    seconds REAL,
    record BLOB
)
"""

# created on the first put_meta only, so that opening an older store changes nothing in it
_META_SCHEMA = "CREATE TABLE IF NOT EXISTS meta (label TEXT PRIMARY KEY, created REAL, record BLOB)"


class NotARunStore(sqlite3.DatabaseError):
    """An SQLite database of another program: fracid does not add its table to it."""


class UndecodableRecord(sqlite3.DatabaseError):
    """A stored record that is not fracid's JSON (a damaged store, or one another program wrote)."""


# ----------------------------------------------------------------------------------------------
# keys


def key_for(**parts) -> str:
    """Key of a run: the SHA-256 (hex) of a canonical JSON of ``parts``.

    Parameters
    ----------
    **parts
        Everything that determines the run, e.g. ``model="gradient"``, ``specimen=bar``,
        ``params=x``, ``control="cmod"``. Accepted values: None, bool, str, numbers, numpy scalars
        and arrays, lists, tuples, sets, dicts with str keys and dataclass instances (as their type
        name and the fields that take part in comparison), nested freely.

    Returns
    -------
    str
        64 hexadecimal characters, the same in every process and session.

    Notes
    -----
    The key ignores dict order, and floats are rounded to 12 significant digits, so that parameter
    vectors that differ by round-off share a key. Integers below 1e12 count as floats (``200`` and
    ``200.0`` give the same key), tuples as lists.

    Raises
    ------
    TypeError
        If a value cannot be put in canonical form; the message names where it is.
    """
    canonical = {name: _canonical(value, name) for name, value in parts.items()}
    text = json.dumps(canonical, sort_keys=True, separators=(",", ":"), ensure_ascii=True, allow_nan=True)
    return hashlib.sha256(text.encode("ascii")).hexdigest()


def _canonical(value, where: str):
    """``value`` as plain JSON types, floats rounded, dataclasses tagged with their type."""
    if value is None or isinstance(value, (bool, np.bool_, str)):
        return value.item() if isinstance(value, np.bool_) else value
    if isinstance(value, numbers.Integral):
        value = int(value)
        return float(value) if abs(value) < _EXACT_INT_LIMIT else value
    if isinstance(value, numbers.Real):
        return _round(float(value))
    if isinstance(value, np.ndarray):
        return _canonical(value.tolist(), where)
    if isinstance(value, Mapping):
        return {require_str_key(k, where): _canonical(v, f"{where}[{k!r}]") for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_canonical(v, f"{where}[{i}]") for i, v in enumerate(value)]
    if isinstance(value, (set, frozenset)):
        items = [_canonical(v, f"{where}{{...}}") for v in value]
        return sorted(items, key=lambda item: json.dumps(item, sort_keys=True))
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        return _canonical_dataclass(value, where)
    raise TypeError(
        f"key_for: cannot put {where} = {value!r} (type {type(value).__name__}) in canonical form; "
        "pass numbers, strings, lists, arrays, dicts with str keys or dataclasses"
    )


def _canonical_dataclass(value, where: str) -> dict:
    """A dataclass as {"__type__": module.qualname, field: value, ...} (compared fields only)."""
    kind = type(value)
    out = {"__type__": f"{kind.__module__}.{kind.__qualname__}"}
    for f in dataclasses.fields(value):
        if f.compare:
            out[f.name] = _canonical(getattr(value, f.name), f"{where}.{f.name}")
    return out


def _round(x: float) -> float:
    """``x`` rounded to 12 significant digits; -0.0 becomes 0.0; nan and inf stay."""
    if not math.isfinite(x):
        return x
    return float(f"{x:.{_SIGNIFICANT_DIGITS}g}") + 0.0


# ----------------------------------------------------------------------------------------------
# the store


class RunStore:
    """Persistent store of runs, one SQLite file (WAL mode).

    Parameters
    ----------
    path : str or os.PathLike
        The database file; created (with its table) if missing. Its directory must exist.
    readonly : bool
        Open for reading only (the file must exist); for processes that only look up runs.
    timeout : float
        Seconds to wait for a lock held by another connection.

    Notes
    -----
    Table ``runs(key TEXT PRIMARY KEY, study TEXT, created REAL, status TEXT, seconds REAL,
    record BLOB)``, ``record`` being :func:`encode_record` bytes; once :meth:`put_meta` was called,
    also ``meta(label TEXT PRIMARY KEY, created REAL, record BLOB)``. Many processes may read, one
    writes: in a batch the workers compute and the parent stores. Do not share an open store
    across ``fork``; open one per process. Use it from the thread that opened it.

    Examples
    --------
    >>> with RunStore("runs.sqlite") as store:                                # doctest: +SKIP
    ...     key = key_for(model="gradient", specimen=bar, params=x)
    ...     if key not in store:
    ...         store.put(key, {"force": force}, status="ok", seconds=1.2, study="calibration")
    ...     record = store.get(key)
    """

    def __init__(self, path, *, readonly: bool = False, timeout: float = 30.0):
        self.path = os.fspath(path)
        self.readonly, self.timeout = readonly, timeout
        self._conn = _connect(self.path, readonly, timeout)
        self.journal_mode = self._conn.execute("PRAGMA journal_mode").fetchone()[0]
        # a SQLite connection belongs to its thread: other threads (concurrent filters of a study)
        # get connections of their own, which WAL lets read and write side by side
        self._owner = threading.get_ident()
        self._local = threading.local()
        self._others: list = []
        self._others_lock = threading.Lock()

    # -- writing ------------------------------------------------------------------------------

    def put(self, key: str, record, *, status: str, seconds: float, study: str = "") -> None:
        """Store (or replace) the run ``key`` in one transaction.

        Parameters
        ----------
        key : str
            Usually from :func:`key_for`.
        record : dict or bytes
            The record, or its :func:`encode_record` bytes (e.g. encoded by a worker).
        status : str
            E.g. ``"ok"`` or ``"failed"``.
        seconds : float
            Time the run took [s].
        study : str
            A label to group runs (see :meth:`keys`).
        """
        _check_key(key)
        blob = record if isinstance(record, bytes) else encode_record(record)
        conn = self._writer()
        conn.execute(
            "INSERT OR REPLACE INTO runs (key, study, created, status, seconds, record) VALUES (?, ?, ?, ?, ?, ?)",
            (key, str(study), time.time(), str(status), float(seconds), sqlite3.Binary(blob)),
        )

    def put_meta(self, label: str, record: Mapping) -> None:
        """Store (or replace) a record about the runs, e.g. the provenance of a command's runs under the
        label ``"provenance:identify"``, in the table ``meta(label, created, record)`` (made here)."""
        conn = self._writer()
        conn.execute(_META_SCHEMA)
        conn.execute("INSERT OR REPLACE INTO meta (label, created, record) VALUES (?, ?, ?)",
                     (str(label), time.time(), sqlite3.Binary(encode_record(record))))

    # -- reading ------------------------------------------------------------------------------

    def get_meta(self, label: str) -> dict | None:
        """The record stored by :meth:`put_meta` under ``label``; None if none (or a store without ``meta``)."""
        try:
            row = self._reader().execute("SELECT record FROM meta WHERE label = ?", (str(label),)).fetchone()
        except sqlite3.OperationalError:  # no such table: a store older than put_meta
            return None
        return None if row is None else _decoded(str(label), row[0])

    def get(self, key: str) -> dict | None:
        """The record of ``key``, or None if it is not stored."""
        row = self._reader().execute("SELECT record FROM runs WHERE key = ?", (key,)).fetchone()
        return None if row is None else _decoded(key, row[0])

    def get_many(self, keys: Iterable[str]) -> dict:
        """``{key: record}`` for those of ``keys`` that are stored."""
        rows = list(self._select("key, record", keys))  # all read before decoding: a bad record ends the query
        return {key: _decoded(key, blob) for key, blob in rows}

    def info(self, key: str) -> dict | None:
        """``{"study", "created", "status", "seconds"}`` of the run ``key``, or None."""
        sql = "SELECT study, created, status, seconds FROM runs WHERE key = ?"
        row = self._reader().execute(sql, (key,)).fetchone()
        return None if row is None else dict(zip(("study", "created", "status", "seconds"), row))

    def statuses(self, keys: Iterable[str]) -> dict:
        """``{key: status}`` for those of ``keys`` that are stored (records are not decoded)."""
        return dict(self._select("key, status", keys))

    def keys(self, study: str | None = None) -> list[str]:
        """Stored keys in the order they were written, all or those of one ``study``."""
        sql = "SELECT key FROM runs"
        args: tuple = ()
        if study is not None:
            sql, args = sql + " WHERE study = ?", (study,)
        return [row[0] for row in self._reader().execute(sql + " ORDER BY created, key", args)]

    def __contains__(self, key) -> bool:
        return self._reader().execute("SELECT 1 FROM runs WHERE key = ?", (key,)).fetchone() is not None

    def __len__(self) -> int:
        return self._reader().execute("SELECT COUNT(*) FROM runs").fetchone()[0]

    # -- life cycle ---------------------------------------------------------------------------

    def close(self) -> None:
        """Close the connections (idempotent)."""
        if self._conn is not None:
            with self._others_lock:
                for conn in self._others:
                    conn.close()
                self._others.clear()
            self._conn.close()
            self._conn = None

    @property
    def closed(self) -> bool:
        return self._conn is None

    def __enter__(self) -> Self:
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def __repr__(self) -> str:
        state = "closed" if self.closed else ("read-only" if self.readonly else "open")
        return f"RunStore({self.path!r}, {state})"

    def __getstate__(self):
        raise TypeError(
            f"{self!r} cannot be sent to another process: workers compute and return records, "
            "the parent process stores them"
        )

    # -- helpers ------------------------------------------------------------------------------

    def _reader(self) -> sqlite3.Connection:
        if self._conn is None:
            raise RuntimeError(f"RunStore({self.path!r}) is closed")
        if threading.get_ident() == self._owner:
            return self._conn
        conn = getattr(self._local, "conn", None)
        if conn is None:
            conn = self._local.conn = _connect(self.path, self.readonly, self.timeout, check_same_thread=False)
            with self._others_lock:
                self._others.append(conn)
        return conn

    def _writer(self) -> sqlite3.Connection:
        if self.readonly:
            raise PermissionError(f"RunStore({self.path!r}) was opened read-only")
        return self._reader()

    def _select(self, columns: str, keys: Iterable[str]):
        """Rows of ``columns`` for ``keys``, in chunks that respect SQLite's variable limit."""
        keys = list(dict.fromkeys(keys))
        conn = self._reader()
        for start in range(0, len(keys), _SQL_VARIABLES_PER_QUERY):
            chunk = keys[start : start + _SQL_VARIABLES_PER_QUERY]
            marks = ",".join("?" * len(chunk))
            yield from conn.execute(f"SELECT {columns} FROM runs WHERE key IN ({marks})", chunk)


def _connect(path: str, readonly: bool, timeout: float, check_same_thread: bool = True) -> sqlite3.Connection:
    """Open ``path``: autocommit (each statement its own transaction), WAL, synchronous=NORMAL.

    ``check_same_thread=False`` for the connections of other threads, which the owner closes."""
    if readonly and not os.path.exists(path):
        raise FileNotFoundError(f"RunStore: no store at {path!r} to open read-only")
    directory = os.path.dirname(os.path.abspath(path))
    if not readonly and not os.path.isdir(directory):
        raise FileNotFoundError(f"RunStore: the directory {directory!r} of {path!r} does not exist")
    target = f"file:{_uri_path(path)}?mode=ro" if readonly else path
    conn = sqlite3.connect(target, timeout=timeout, isolation_level=None, uri=readonly,
                           check_same_thread=check_same_thread)
    try:
        if not readonly:
            _refuse_foreign(conn, path)
            conn.execute("PRAGMA journal_mode=WAL")
            conn.execute(_SCHEMA)
        conn.execute("PRAGMA synchronous=NORMAL")
        conn.execute("SELECT 1 FROM runs LIMIT 1").fetchone()
    except NotARunStore:
        conn.close()
        raise
    except sqlite3.DatabaseError as exc:
        conn.close()
        error = type(exc)(f"RunStore: cannot open {path!r} as a run store: {exc}")
        error.sqlite_errorcode = getattr(exc, "sqlite_errorcode", None)  # what went wrong, for the message
        raise error from exc
    return conn


def _refuse_foreign(conn: sqlite3.Connection, path: str) -> None:
    """NotARunStore if the database holds tables but no ``runs`` table: another program's file."""
    tables = [row[0] for row in conn.execute("SELECT name FROM sqlite_master WHERE type = 'table'")]
    if tables and "runs" not in tables:
        raise NotARunStore(f"{path} is an SQLite database of another program (tables: {', '.join(tables[:5])}), "
                           "not a fracid run store")


def _decoded(key: str, blob) -> dict:
    try:
        return decode_record(blob)
    except (ValueError, TypeError, KeyError) as exc:  # JSONDecodeError, UnicodeDecodeError, a bad array tag
        raise UndecodableRecord(f"the stored record of run {key[:12]}... cannot be decoded ({exc})") from None


def _uri_path(path: str) -> str:
    from urllib.parse import quote

    return quote(os.path.abspath(path))


def _check_key(key) -> None:
    if not isinstance(key, str) or not key:
        raise TypeError(f"a run key must be a non-empty str (see key_for), got {key!r}")
