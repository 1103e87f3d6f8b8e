"""A field block built once per process: reading the configuration, building the data and the observation
all ask for it, and its covariance's factorisation is its costly part (issue 41: three builds per ``fracid
check``, a fourth by ``identify``).

:func:`built_once` keeps the last :data:`KEPT` blocks, keyed by the block's configuration, the specimen and the
size and modification time of every file beside the frame table and of the machine log (a file rewritten builds
it afresh). A block is immutable: sharing it is safe.
"""

from __future__ import annotations

import os
from pathlib import Path

#: blocks kept (a field block may hold hundreds of MB)
KEPT = 2
_BUILT: dict = {}


def files_stat(exp) -> tuple:
    """(name, size, modification time [ns]) of every file in the frame table's folder and of the machine log
    (``exp.file``, ``exp.log.file``); a file that cannot be read gives its name alone (the build says why)."""
    def stat(path):
        try:
            info = os.stat(path)
        except (OSError, TypeError, ValueError):
            return (str(path),)
        return (str(path), info.st_size, info.st_mtime_ns)

    try:
        folder = sorted(entry.path for entry in os.scandir(Path(exp.file).parent) if entry.is_file())
    except (OSError, TypeError, ValueError):
        folder = [exp.file]
    log = getattr(getattr(exp, "log", None), "file", None)
    return tuple(stat(path) for path in (*folder, *([log] if log is not None else [])))


def built_once(exp, specimen, build) -> tuple:
    """``build(exp, specimen)``, or the value it gave for the same configuration, specimen and files."""
    key = (exp, specimen, files_stat(exp))
    if key not in _BUILT:
        while len(_BUILT) >= KEPT:
            _BUILT.pop(next(iter(_BUILT)))
        _BUILT[key] = build(exp, specimen)
    return _BUILT[key]


__all__ = ["KEPT", "built_once", "files_stat"]
