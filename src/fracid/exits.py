"""Exit statuses of the ``fracid`` command and the one-paragraph message of every expected failure.

======  =====================================================================================
status  meaning
======  =====================================================================================
0       done (warnings, e.g. a poor fit or an estimate at a bound, are printed but do not fail)
1       an internal error (a bug): rerun with ``--debug`` for the traceback and report it
2       bad input: configuration, data file, command-line argument, a limit exceeded
3       the computation failed: a forward analysis did not converge, too few forward runs of a
        population succeeded, or the result is not finite
4       files and storage: a path that cannot be read or written, a full disk, a corrupt run
        store, an output directory in use by another fracid process
5       out of memory
130     interrupted (Ctrl-C); 143: terminated (SIGTERM). Finished runs are stored: run again to resume
======  =====================================================================================
"""

from __future__ import annotations

import errno
import sqlite3

OK, INTERNAL, INPUT, FAILED, FILES, MEMORY, INTERRUPTED, TERMINATED = 0, 1, 2, 3, 4, 5, 130, 143


class Terminated(KeyboardInterrupt):
    """SIGTERM, raised in the main thread so that the run ends as cleanly as after Ctrl-C."""


class UsageError(ValueError):
    """A command-line argument that cannot be used (the message names the option)."""


class OutputInUse(OSError):
    """Another fracid process holds the lock of the output directory."""


def describe(err: BaseException, *, store_path=None, out=None) -> tuple[int, str]:
    """(exit status, message) for an exception that ended a command."""
    from fracid.config import ConfigError
    from fracid.data import DataError
    from fracid.inverse.knn import AllRunsFailed
    from fracid.inverse.sensitivity import ForwardRunError
    from fracid.fem.path_following import ConvergenceError

    resume = f"Finished runs are stored in {store_path}; run the same command again to resume." if store_path else ""
    if isinstance(err, Terminated):
        return TERMINATED, f"terminated (SIGTERM). {resume}".strip()
    if isinstance(err, KeyboardInterrupt):
        return INTERRUPTED, f"interrupted. {resume}".strip()
    if isinstance(err, MemoryError):
        return MEMORY, ("out of memory. Use a coarser mesh (h_fine, n_elements), a smaller population "
                        "([identify.knn] n), fewer data points (n_points) or fewer workers (--workers).")
    if isinstance(err, (ConfigError, DataError, UsageError)):
        return INPUT, str(err)
    if isinstance(err, ConvergenceError):
        return FAILED, _convergence_text(err)
    if isinstance(err, AllRunsFailed):
        return FAILED, (f"{err} Check the parameter values and bounds against the data's units, or the control "
                        f"(an indirect control such as cmod or weak_zone_elongation passes snap-back). "
                        f"Failed runs are stored; --retry-failed runs them again.")
    if isinstance(err, ForwardRunError):
        return FAILED, str(err)
    if isinstance(err, OutputInUse):
        return FILES, str(err)
    if isinstance(err, sqlite3.Error):
        where = store_path or "the run store"
        return FILES, (f"the run store {where} cannot be used ({err}). If it is corrupt or truncated, move it away "
                       f"(e.g. rename it to runs.sqlite.bad) and run again: the runs will be recomputed.")
    if isinstance(err, OSError):
        return FILES, _os_text(err, out)
    return INTERNAL, (f"internal error ({type(err).__name__}: {err}). Run again with --debug to see the traceback, "
                      "and please report it.")


def _convergence_text(err) -> str:
    partial = getattr(err, "partial", None)
    reached = ""
    if partial is not None and getattr(partial, "n_steps", 0):
        reached = f" after {partial.n_steps} steps, at control {float(partial.control[-1]):.6g} mm"
    return (f"the forward analysis did not converge{reached}: {err}. Try an indirect control that passes "
            "snap-back (bar: control = \"weak_zone_elongation\"; beam: \"cmod\"; dogbone: \"elongation\"), "
            "a smaller [simulate] target, or parameter values within the usual ranges (kappa_i ~ 1e-4, c of "
            "a few mm^2).")


def _os_text(err: OSError, out) -> str:
    if err.filename is None and err.errno is None:  # not about a file (e.g. a connection)
        return f"{err}"
    name = err.filename or out or ""
    if err.errno == errno.ENOSPC:
        return f"the disk is full (writing {name}). Free some space and run again: finished runs are kept."
    if err.errno in (errno.EACCES, errno.EPERM, errno.EROFS):
        return f"permission denied: {name}. Choose a directory you can write (--out DIR) or fix the permissions."
    if err.errno in (errno.ENOTDIR, errno.EEXIST) or isinstance(err, (NotADirectoryError, FileExistsError)):
        return f"{name} is a file, not a directory: give another output directory (--out DIR)."
    if isinstance(err, IsADirectoryError):
        return f"{name} is a directory where a file was expected."
    if isinstance(err, FileNotFoundError):
        return f"no such file or directory: {name}."
    return f"{err.strerror or err}: {name}".rstrip(": ")
