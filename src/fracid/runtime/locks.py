"""Exclusive locks on an output directory and on a shared run store, so that two fracid processes never
compute into one (a run store has one writer, :mod:`fracid.store.runs`).

A lock is an operating-system lock on a file (``.fracid.runtime.locks`` in the directory; ``<store>.fracid.runtime.locks``
beside a store given with ``--store``; ``fcntl.flock`` on POSIX, ``msvcrt.locking`` on Windows): it is
released when the process ends in any way, SIGKILL included, so a stale lock file never blocks a rerun.
"""

from __future__ import annotations

import contextlib
import os
from pathlib import Path

from fracid.runtime.exits import OutputInUse

LOCK_NAME = ".fracid.runtime.locks"


def directory_lock(directory):
    """Hold the lock of ``directory`` for the duration; :class:`~fracid.runtime.exits.OutputInUse` if another
    process holds it (the message names that process's pid)."""
    return _file_lock(Path(directory) / LOCK_NAME, f"the output directory {directory}",
                      "give another directory with --out DIR")


def store_lock(store):
    """Hold the lock of the run store file ``store`` (shared between commands with ``--store``) for the
    duration; :class:`~fracid.runtime.exits.OutputInUse` if another process holds it."""
    store = Path(store)
    return _file_lock(store.with_name(store.name + LOCK_NAME), f"the run store {store}",
                      "give another store with --store FILE")


@contextlib.contextmanager
def _file_lock(path, what: str, instead: str):
    handle = open(path, "a+")
    try:
        if not _try_lock(handle):
            handle.seek(0)
            holder = handle.read().strip() or "unknown"
            raise OutputInUse(f"another fracid process (pid {holder}) is using {what}. Wait until it ends, or {instead}.")
        _write_pid(handle, path)
        yield path
    finally:
        handle.close()  # closing releases the lock


def _write_pid(handle, path) -> None:
    """This process's id into the lock file (for the message of another process); a failed write (a full
    disk) names the lock file, so that the message names its file system, not the output directory's."""
    try:  # unbuffered: a failed write leaves nothing for close() to write again
        os.ftruncate(handle.fileno(), 0)
        os.write(handle.fileno(), str(os.getpid()).encode("ascii"))
    except OSError as err:
        if err.filename is not None:
            raise
        raise type(err)(err.errno, err.strerror, str(path)) from err


def _try_lock(handle) -> bool:
    try:
        import fcntl
    except ImportError:  # Windows
        import msvcrt

        try:
            handle.seek(0)
            msvcrt.locking(handle.fileno(), msvcrt.LK_NBLCK, 1)
            return True
        except OSError:
            return False
    try:
        fcntl.flock(handle.fileno(), fcntl.LOCK_EX | fcntl.LOCK_NB)
        return True
    except BlockingIOError:
        return False
