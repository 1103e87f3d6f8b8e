"""Reading a file with meshio, every failure of the reader turned into one exception that says why.

meshio raises its own errors, parser errors of any type, or prints an error and calls ``sys.exit`` on a file it
cannot read (a truncated VTU, a Gmsh 1 file): :func:`meshio_read` is the one guard of every reader of fracid that
goes through meshio (the specimen's mesh, the DIC frames in VTU/VTK), so that a bad file is a bad input, never an
exit of the process nor an internal error.
"""

from __future__ import annotations

import contextlib
import io


class UnreadableFile(ValueError):
    """meshio could not read the file: ``reason`` in words; ``os_error`` True when the system refused to read it
    (missing, permission), False when its contents are not a format meshio reads."""

    def __init__(self, reason: str, os_error: bool = False):
        super().__init__(reason)
        self.reason, self.os_error = reason, os_error


def meshio_read(path):
    """meshio's mesh of ``path``; :class:`UnreadableFile` for any failure of the reader (what it printed, else the
    exception), ImportError naming the dependency when meshio is not installed. MemoryError passes through."""
    try:
        import meshio
    except ImportError as err:
        raise ImportError(f"reading {path} needs meshio, a dependency of fracid: pip install meshio ({err})") from err
    said = io.StringIO()
    try:
        with contextlib.redirect_stderr(said), contextlib.redirect_stdout(said):
            return meshio.read(path)
    except MemoryError:
        raise
    except OSError as err:
        raise UnreadableFile(err.strerror or str(err), os_error=True) from None
    except (SystemExit, Exception) as err:  # noqa: BLE001 -- every failure of the reader is a bad file
        printed = " ".join(said.getvalue().split()).removeprefix("Error: ")
        raise UnreadableFile(printed or f"{type(err).__name__}: {err}") from None


__all__ = ["UnreadableFile", "meshio_read"]
