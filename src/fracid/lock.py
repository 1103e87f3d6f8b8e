"""An exclusive lock on an output directory, so that two fracid processes never compute into one.

The lock is an operating-system lock on the file ``.fracid.lock`` in the directory (``fcntl.flock``
on POSIX, ``msvcrt.locking`` on Windows): it is released when the process ends in any way, SIGKILL
included, so a stale lock file never blocks a rerun.
"""

from __future__ import annotations

import contextlib
import os
from pathlib import Path

from fracid.exits import OutputInUse

LOCK_NAME = ".fracid.lock"


@contextlib.contextmanager
def directory_lock(directory):
    """Hold the lock of ``directory`` for the duration; :class:`~fracid.exits.OutputInUse` if another
    process holds it (the message names that process's pid)."""
    path = Path(directory) / LOCK_NAME
    handle = open(path, "a+")
    try:
        if not _try_lock(handle):
            handle.seek(0)
            holder = handle.read().strip() or "unknown"
            raise OutputInUse(f"another fracid process (pid {holder}) is using the output directory {directory}. "
                              "Wait until it ends, or give another directory with --out DIR.")
        handle.seek(0)
        handle.truncate()
        handle.write(str(os.getpid()))
        handle.flush()
        yield path
    finally:
        handle.close()  # closing releases the lock


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
