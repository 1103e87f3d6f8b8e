"""Provenance of a result: what ran, on what, with what, where and when.

:func:`collect` gathers, as a JSON-safe dict: the fracid version, the command line, the configuration
(given by the caller as a dict or a dataclass: this module sits below :mod:`fracid.config` and does not
import it), the data files with their SHA-256, the specimen's geometry (its dataclass fields) and mesh
size, the fixed parameters, the bounds, the date (UTC, ISO 8601) and the machine (platform, Python,
numpy and scipy versions, CPU count). Results keep it (``MethodResult.provenance``, saved in
``result.json``), the HTML reports show it ("How this was run") and the run store records it per run
label (:meth:`fracid.store.runs.RunStore.put_meta`).
"""

from __future__ import annotations

import dataclasses
import datetime
import hashlib
import math
import os
import platform
import shlex
import sys
from collections.abc import Mapping
from importlib import metadata
from pathlib import PurePath

import numpy as np

#: bytes read at a time when hashing a data file
_CHUNK = 1 << 20


def json_safe(value):
    """``value`` as JSON types: dataclasses as dicts of their fields, paths as str, tuples and sets as
    lists, numpy arrays and scalars as lists and numbers, non-finite floats as str (``"inf"``,
    ``"nan"``), anything else as its ``repr``."""
    if value is None or isinstance(value, (bool, str, int)):
        return value
    if isinstance(value, float):
        return value if math.isfinite(value) else str(value)
    if isinstance(value, np.generic):
        return json_safe(value.item())
    if isinstance(value, np.ndarray):
        return json_safe(value.tolist())
    if isinstance(value, PurePath):
        return str(value)
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        return {f.name: json_safe(getattr(value, f.name)) for f in dataclasses.fields(value) if f.repr}
    if isinstance(value, Mapping):
        return {str(k): json_safe(v) for k, v in value.items()}
    if isinstance(value, (list, tuple, set, frozenset)):
        return [json_safe(v) for v in value]
    if callable(value):
        return getattr(value, "__qualname__", repr(value))
    return repr(value)


def sha256_of(path) -> str:
    """SHA-256 (hex) of a file's bytes."""
    digest = hashlib.sha256()
    with open(path, "rb") as stream:
        for chunk in iter(lambda: stream.read(_CHUNK), b""):
            digest.update(chunk)
    return digest.hexdigest()


def data_file(path) -> dict:
    """``{"path" (absolute), "bytes", "sha256"}`` of a data file, or ``{"path", "error"}`` if unreadable."""
    path = os.path.abspath(os.fspath(path))
    try:
        return {"path": path, "bytes": os.path.getsize(path), "sha256": sha256_of(path)}
    except OSError as err:
        return {"path": path, "error": f"{type(err).__name__}: {err.strerror or err}"}


def fracid_version() -> str:
    """The installed fracid's version (its metadata), else :data:`fracid.__version__` (a source tree)."""
    try:
        return metadata.version("fracid")
    except metadata.PackageNotFoundError:
        from fracid import __version__

        return __version__


def machine() -> dict:
    """Platform, Python, numpy and scipy versions and CPU count of this machine."""
    try:
        import scipy

        scipy_version = scipy.__version__
    except ImportError:
        scipy_version = None
    return {"platform": platform.platform(), "python": sys.version.split()[0], "implementation":
            platform.python_implementation(), "numpy": np.__version__, "scipy": scipy_version,
            "cpu_count": os.cpu_count()}


def mesh_size(specimen) -> dict | None:
    """Nodes, elements and unknowns of the specimen's mesh (its ``describe()``); None without one.

    ``unknowns``: displacements (dimension x nodes) plus one nonlocal strain per corner node (the
    gradient-damage model's; models without that field have ``displacement_unknowns`` only).
    """
    describe = getattr(specimen, "describe", None)
    if describe is None:
        return None
    try:
        d = describe()
    except (TypeError, ValueError, OSError) as err:  # a mesh file that cannot be read now
        return {"error": f"{type(err).__name__}: {err}"}
    nodes, dim = int(np.shape(d.nodes)[0]), int(np.shape(d.nodes)[1])
    corners = int(np.unique(np.asarray(d.corners)).size)
    return {"dimension": dim, "nodes": nodes, "elements": int(np.shape(d.cells)[0]),
            "displacement_unknowns": dim * nodes, "unknowns": dim * nodes + corners}


def specimen_record(specimen) -> dict | None:
    """The specimen's type, geometry (its dataclass fields) and mesh size; None without a specimen."""
    if specimen is None:
        return None
    return {"type": type(specimen).__name__, "geometry": json_safe(specimen), "mesh": mesh_size(specimen)}


def bounds_record(bounds) -> dict | None:
    """Bounds as ``{name: [lower, upper]}``: from such a mapping, or from an object with ``names``,
    ``lower`` and ``upper`` (a :class:`~fracid.inverse.core.space.ParameterSpace`)."""
    if bounds is None:
        return None
    if isinstance(bounds, Mapping):
        return {str(k): json_safe(list(v)) for k, v in bounds.items()}
    return {str(n): [json_safe(lo), json_safe(hi)] for n, lo, hi in zip(bounds.names, bounds.lower, bounds.upper)}


def collect(*, argv, config=None, data_files=(), specimen=None, parameters=None, bounds=None) -> dict:
    """The provenance of a run, JSON-safe.

    Parameters
    ----------
    argv : sequence of str
        The command line (``sys.argv``).
    config : dict or dataclass, optional
        The configuration as read, defaults filled (e.g. ``fracid.config.Config``, or
        ``dataclasses.asdict`` of it).
    data_files : sequence of path
        The measured data files; each is hashed (SHA-256).
    specimen : object, optional
        The specimen (a dataclass): its type, fields and mesh size are recorded.
    parameters : dataclass or dict, optional
        The model parameters, the fixed ones at their values (e.g. ``ForwardOperator.base``).
    bounds : mapping or ParameterSpace, optional
        Bounds of the identified parameters (units of the parameters).

    Returns
    -------
    dict
        ``fracid``, ``command``, ``argv``, ``date`` (UTC, ISO 8601), ``machine``, ``config``,
        ``data_files``, ``specimen``, ``parameters`` and ``bounds``.
    """
    argv = [str(a) for a in argv]
    return {"fracid": fracid_version(), "command": shlex.join(argv), "argv": argv,
            "date": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
            "machine": machine(), "config": json_safe(config), "data_files": [data_file(p) for p in data_files],
            "specimen": specimen_record(specimen), "parameters": json_safe(parameters), "bounds": bounds_record(bounds)}


__all__ = ["bounds_record", "collect", "data_file", "fracid_version", "json_safe", "machine", "mesh_size",
           "sha256_of", "specimen_record"]
