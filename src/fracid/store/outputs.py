"""What a command writes into its output directory, and the guard that keeps it from destroying anything
else: an output is never one of the run's inputs (the configuration, a data file, a mesh), and fracid
replaces only files it wrote itself, which it lists in the directory's manifest ``.fracid-written`` (the
run store, which it only adds to, may come from elsewhere).

The guard runs before any computation: a refused output costs nothing and changes nothing.
"""

from __future__ import annotations

import json
import os
from pathlib import Path
from typing import Iterable

from fracid.runtime.exits import UsageError

#: the directory's record of the names fracid wrote there (files, or directories it fills)
MANIFEST = ".fracid-written"

_IDENTIFY = ("runs.sqlite", "result.json", "fit.csv", "report.html", "figures")
_POSTERIOR = ("posterior.csv", "posterior.json", "posterior.nc", "posterior.html")
_STUDY = ("runs.sqlite", "study.json", "verdict.txt", "population.csv", "sensitivity.csv", "stability.csv",
          "size_effect.csv", "size_effect.json", "report.html", "figures", *_POSTERIOR)

#: every name (relative to the output directory) each command may write
OUTPUTS = {
    "simulate": ("curve.csv", "curve.png", "vtk"),
    "identify": _IDENTIFY,
    "demo": _IDENTIFY,
    "posterior": (*_IDENTIFY, *_POSTERIOR),
    "study": _STUDY,
    "uniqueness": _STUDY,
    "stability": _STUDY,
    "sensitivity": ("runs.sqlite", "sensitivity.csv", "sensitivity.png"),
    "size-effect": ("size_effect.csv", "size_effect.json", "size_effect.png"),
    "compare": ("runs.sqlite", "compare.json", "compare.html", "figures"),  # not report.html: identify's in a shared --out
    "check": ("check",),  # the check figures (fracid.cli.check_figures), written only for a block with a machine log
    "serve": ("runs.sqlite", "serve.json"),
}


#: outputs that fracid adds to rather than replaces: a run store copied from another output directory is
#: reused (:class:`fracid.store.runs.RunStore` refuses an SQLite database of another program)
APPENDED = frozenset({"runs.sqlite"})


class OutputRefused(UsageError):
    """An output that would replace an input of the run, or a file fracid did not write (exit 2)."""


def claim_outputs(out: Path, command: str, inputs: Iterable[tuple[str, Path]]) -> None:
    """Check that ``command`` may write its outputs into ``out``, then record them as fracid's.

    Parameters
    ----------
    out : Path
        The output directory (it exists).
    command : str
        A key of :data:`OUTPUTS`.
    inputs : iterable of (str, Path)
        What the run reads, each with what it is (``"the configuration"``, ``"experiments[0].file"``...).

    Raises
    ------
    OutputRefused
        Naming the output and the input it would replace, or the existing file fracid did not write.
    """
    written = check_outputs(out, command, inputs)
    if not set(OUTPUTS[command]) <= written:
        _write_manifest(Path(out), written | set(OUTPUTS[command]))


def check_outputs(out: Path, command: str, inputs: Iterable[tuple[str, Path]]) -> set[str]:
    """What :func:`claim_outputs` checks, recording nothing (``out`` need not exist: ``fracid check``); returns
    the names already recorded as fracid's in ``out``.

    Raises
    ------
    OutputRefused
        Naming the output and the input it would replace, or the existing file fracid did not write.
    """
    out = Path(out)
    written = read_manifest(out)
    sources = [(role, _real(Path(path))) for role, path in inputs]
    for name in OUTPUTS[command]:
        target = out / name
        real = _real(target)
        for role, source in sources:
            if source == real or real in source.parents:
                raise OutputRefused(
                    f"{target} would be written by `fracid {command}`, and it is {role} ({source}) of this run: "
                    "fracid never overwrites its inputs. Give another output directory (--out DIR or "
                    "[output] directory), or move the input elsewhere.")
        if (target.exists() or target.is_symlink()) and name not in written | APPENDED:
            raise OutputRefused(
                f"{target} exists and was not written by fracid (it is not listed in {out / MANIFEST}); "
                f"`fracid {command}` would replace it. Give another output directory (--out DIR or [output] "
                "directory), or move the file away if it may be replaced.")
    return written


def read_manifest(out: Path) -> set[str]:
    """The names fracid recorded as written in ``out`` (empty if it has no manifest or an unreadable one)."""
    try:
        names = json.loads((Path(out) / MANIFEST).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return set()
    return {n for n in names if isinstance(n, str)} if isinstance(names, list) else set()


def _write_manifest(out: Path, names: set[str]) -> None:
    path = Path(out) / MANIFEST
    temporary = path.with_name(MANIFEST + ".tmp")
    temporary.write_text(json.dumps(sorted(names), indent=0) + "\n", encoding="utf-8")
    os.replace(temporary, path)


def _real(path: Path) -> Path:
    """``path`` with every symbolic link resolved, as far as it exists (a loop is left as it is)."""
    try:
        return Path(os.path.realpath(path))
    except (OSError, RuntimeError):  # a symlink loop on some Pythons
        return Path(os.path.abspath(path))
