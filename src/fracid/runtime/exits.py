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
130     interrupted (Ctrl-C); 143: terminated (SIGTERM); 129: hang-up (SIGHUP, the terminal closed).
        Finished runs are stored: run again to resume
======  =====================================================================================
"""

from __future__ import annotations

import contextlib
import errno
import os
import shutil
import signal
import sqlite3
import sys

from fracid.runtime.stops import RAISED_BY, HungUp, Terminated, received

OK, INTERNAL, INPUT, FAILED, FILES, MEMORY, INTERRUPTED, TERMINATED, HUNG_UP = 0, 1, 2, 3, 4, 5, 130, 143, 129


@contextlib.contextmanager
def stop_signals():
    """Within: the first of SIGINT, SIGTERM or SIGHUP raises KeyboardInterrupt, Terminated or HungUp in
    the main thread; every later one is ignored, so that a second Ctrl-C (or GNU ``timeout``, which
    signals twice) cannot break the cleanup or the message. The previous handlers are restored after,
    unless a signal came (the process is ending: later ones stay ignored). Outside the main thread (a
    test runner's thread) nothing is installed."""
    def handler(signum, frame):
        received.append(signum)
        if len(received) == 1:
            # ignored by the operating system from now on: also while the interpreter shuts down, when
            # Python puts back the default action of the signals it handled
            ignore_stop_signals()
            raise RAISED_BY[signal.Signals(signum).name]()

    previous = {}
    hooks = sys.unraisablehook, sys.excepthook
    sys.unraisablehook, sys.excepthook = _quiet_about_stops(*hooks)
    try:
        for name in RAISED_BY:
            if hasattr(signal, name):
                previous[name] = signal.signal(getattr(signal, name), handler)
    except ValueError:  # not the main thread
        pass
    try:
        yield
    finally:
        sys.unraisablehook, sys.excepthook = hooks
        if not received:  # after a stop signal the process is ending: a late second one stays ignored
            for name, old in previous.items():
                signal.signal(getattr(signal, name), old)


def _quiet_about_stops(unraisable_hook, except_hook):
    """``sys.unraisablehook`` and ``sys.excepthook`` that say nothing of a stop signal's exception swallowed
    by a library (compiled code that cannot pass exceptions on, e.g. scipy's Sobol initialisation, prints the
    traceback and "Exception ignored in" and goes on): the signal is on record and :func:`raise_if_stopped`
    raises it again at the next checkpoint."""
    def unraisable(what):
        if not (received and isinstance(what.exc_value, KeyboardInterrupt)):
            unraisable_hook(what)

    def uncaught(kind, value, traceback):
        if not (received and isinstance(value, KeyboardInterrupt)):
            except_hook(kind, value, traceback)
    return unraisable, uncaught


def ignore_stop_signals() -> None:
    """Ignore SIGINT, SIGTERM and SIGHUP from now on (while a last message is written)."""
    with contextlib.suppress(ValueError):  # not the main thread
        for name in RAISED_BY:
            if hasattr(signal, name):
                signal.signal(getattr(signal, name), signal.SIG_IGN)


def _loaded(module: str, name: str) -> tuple:
    """The class ``name`` of ``module`` if that module is imported, else (): an exception of a module
    never imported cannot have been raised, and describing a failure must import nothing heavy."""
    found = getattr(sys.modules.get(module), name, None)
    return () if found is None else (found,)


class UsageError(ValueError):
    """A command-line argument that cannot be used (the message names the option)."""


class OutputInUse(OSError):
    """Another fracid process holds the lock of the output directory."""


def describe(err: BaseException, *, store_path=None, out=None, store_option="--out DIR",
             out_option="--out DIR") -> tuple[int, str]:
    """(exit status, message) for an exception that ended a command; ``store_option`` and ``out_option``: the
    options that choose the run store's place (``--store FILE`` when given) and the command's outputs' (``-o
    FILE`` of ``fracid init``), named in the advice."""
    config_error = _loaded("fracid.config.schema", "ConfigError")
    data_error = _loaded("fracid.data.errors", "DataError")
    mesh_error = _loaded("fracid.specimens.mesh_reading", "MeshError")
    all_failed = _loaded("fracid.inverse.methods.knn", "AllRunsFailed")
    run_error = _loaded("fracid.inverse.core.sensitivity", "ForwardRunError")
    no_convergence = _loaded("fracid.fem.path.path_following", "ConvergenceError")
    resume = f"Finished runs are stored in {store_path}; run the same command again to resume." if store_path else ""
    if isinstance(err, HungUp):
        return HUNG_UP, f"hang-up (SIGHUP: the terminal closed). {resume}".strip()
    if isinstance(err, Terminated):
        return TERMINATED, f"terminated (SIGTERM). {resume}".strip()
    if isinstance(err, KeyboardInterrupt):
        return INTERRUPTED, f"interrupted. {resume}".strip()
    if isinstance(err, MemoryError):
        return MEMORY, ("out of memory. Use a coarser mesh (h_fine, n_elements), a smaller population "
                        "([identify.knn] n), fewer data points (n_points) or fewer workers (--workers).")
    if isinstance(err, (*config_error, *data_error, *mesh_error, UsageError)):
        return INPUT, str(err)
    if isinstance(err, no_convergence):
        return FAILED, _convergence_text(err)
    if isinstance(err, all_failed):
        return FAILED, (f"{err} Check the parameter values and bounds against the data's units, or the control "
                        f"(an indirect control such as cmod or weak_zone_elongation passes snap-back). "
                        f"Failed runs are stored; --retry-failed runs them again.")
    if isinstance(err, run_error):
        return FAILED, str(err)
    if isinstance(err, OutputInUse):
        return FILES, str(err)
    if isinstance(err, sqlite3.Error):
        return FILES, _store_text(err, store_path or "the run store", store_option)
    if isinstance(err, OSError):
        name = err.filename or out or ""
        on_store = store_path is not None and str(name).startswith(str(store_path))
        return FILES, _os_text(err, name, store_option if on_store else out_option)
    return INTERNAL, (f"internal error ({type(err).__name__}: {err}). Run again with --debug to see the traceback, "
                      "and please report it.")


#: SQLite's primary result codes (https://sqlite.org/rescode.html) -> what happened and what to do
_STORE_ADVICE = {
    13: "the disk that holds it{disk} is full. Free some space and run the same command again: the runs "
        "stored before are intact and will be reused",  # SQLITE_FULL
    10: "a disk input/output error (a removed drive, a network file system that went away?). Check the disk "
        "and run again: the runs stored before the error are kept",  # SQLITE_IOERR
    8: "it is read-only (file or directory permissions, or a read-only file system). Give another "
       "{place} you can write ({option}) or fix the permissions",  # SQLITE_READONLY
    3: "access was denied. Give another {place} you can write ({option})",  # SQLITE_PERM
    14: "it cannot be opened: is it a directory, or is its directory gone or not writable? Give "
        "another {place} ({option})",  # SQLITE_CANTOPEN
    5: "another program holds a lock on it. Close that program (a database browser?) and run again",  # BUSY
    6: "another connection holds a lock on it. Close that program and run again",  # SQLITE_LOCKED
}
_DAMAGED = ("it is damaged (truncated, or not written by fracid); move it away (e.g. rename it to "
            "{name}.bad) and run again: its runs will be recomputed")
#: free bytes [B] below which an input/output error of the store is taken for a full disk: SQLite grows the
#: write-ahead log a page (4 KiB) and its index a 32 KiB region at a time, and a full file system makes some
#: of these writes fail as I/O errors (SQLITE_IOERR_SHMSIZE, _WRITE) rather than SQLITE_FULL
NEARLY_FULL = 1 << 20


def store_failure(code, free) -> int:
    """The primary SQLite result code that explains a store failure: ``code`` masked to its primary part
    (None: not known), but SQLITE_FULL (13) for an input/output error (10) on a file system with fewer than
    :data:`NEARLY_FULL` bytes ``free`` (None: not known).

    Examples
    --------
    >>> store_failure(4874, 24_576), store_failure(4874, 70 * 2**30), store_failure(10, None), store_failure(None, 0)
    (13, 10, 10, None)
    """
    primary = code & 0xFF if isinstance(code, int) else None
    if primary == 10 and free is not None and free < NEARLY_FULL:
        return 13
    return primary


def _store_text(err, where, option="--out DIR") -> str:
    """The message of a run-store failure, by SQLite's result code and the free space of its file system: only
    a damaged file is to be moved away."""
    if isinstance(err, _loaded("fracid.store.runs", "NotARunStore")):
        other = "" if option == "--store FILE" else " or run store (--store FILE)"
        return (f"the run store {where} cannot be used: {err}. fracid does not write into it: give another "
                f"{_place(option)} ({option}){other}.")
    code = getattr(err, "sqlite_errorcode", None)
    code = code if code is not None else getattr(err.__cause__, "sqlite_errorcode", None)
    advice = _STORE_ADVICE.get(store_failure(code, _free(where)), _DAMAGED)
    advice = advice.format(disk=_disk(where), option=option, place=_place(option), name=os.path.basename(str(where)))
    return f"the run store {where} cannot be used ({err}): {advice}."


def _mount(path) -> str:
    """The mount point of the file system that holds ``path`` (or would, for a file not made yet)."""
    mount = os.path.abspath(path)
    while not os.path.ismount(mount):
        mount = os.path.dirname(mount)
    return mount


def _free(path) -> int | None:
    """Free bytes [B] of the file system that holds ``path``; None if that cannot be told."""
    try:
        return shutil.disk_usage(_mount(path)).free
    except (OSError, ValueError, TypeError):
        return None


def _disk(path) -> str:
    """`` (the file system mounted at /data, 0 bytes free)``, or '' if that cannot be told."""
    free = _free(path)
    return "" if free is None else f" (the file system mounted at {_mount(path)}, {free:,} bytes free)"


def _convergence_text(err) -> str:
    partial = getattr(err, "partial", None)
    reached = ""
    if partial is not None and getattr(partial, "n_steps", 0):
        reached = f" after {partial.n_steps} steps, at control {float(partial.control[-1]):.6g} mm"
    text = f"the forward analysis did not converge{reached}: {err}. "
    if getattr(err, "snap_back", False):
        return text + _snap_back_advice(err.control, getattr(err, "functionals", ()))
    return text + ("Try an indirect control that passes snap-back (bar: control = \"weak_zone_elongation\"; beam: "
                   "\"cmod\"; dogbone: \"elongation\"), a smaller [simulate] target, or parameter values within "
                   "the usual ranges (kappa_i ~ 1e-4, c of a few mm^2).")


def _snap_back_advice(control, functionals) -> str:
    """What to do when the curve snaps back under ``control``: the specimen's control that follows it."""
    from fracid.specimens import snap_back_control

    indirect = snap_back_control(control, functionals)
    what = (f"The curve snaps back under control {control!r} (the force falls faster than the {control} can "
            f"follow): ")
    if indirect is not None:
        return what + f"use an indirect control that follows snap-back: [specimen] control = \"{indirect}\"."
    return what + ("use a control that grows through the snap-back (an opening across the crack), or parameters "
                   "that make the specimen less brittle (a larger c, a smaller beta).")


#: the place each option chooses, as the advice names it
_PLACES = {"--out DIR": "output directory", "--store FILE": "run store file", "-o FILE": "file"}


def _place(option: str) -> str:
    """``output directory`` for ``--out DIR``: what ``option`` gives."""
    return _PLACES.get(option, "place")


def _os_text(err: OSError, name, option="--out DIR") -> str:
    """The message of a failed file operation on ``name`` (the error's file, or the output directory); ``option``
    chooses another place (``--out DIR``, ``--store FILE``, ``-o FILE``)."""
    if err.filename is None and err.errno is None:  # not about a file (e.g. a connection)
        return f"{err}"
    if err.errno == errno.ENOSPC:
        return (f"the disk is full (writing {name}{_disk(name)}). Free some space and run again: finished runs "
                "are kept.")
    if err.errno == errno.EROFS:
        return (f"the file system holding {name} is read-only{_disk(name)}. Choose another {_place(option)} on a "
                f"writable disk ({option}); the runs stored there can be copied along with the run store.")
    if err.errno in (errno.EACCES, errno.EPERM):
        return (f"permission denied: {name}. Choose another {_place(option)} you can write ({option}) or fix the "
                "permissions.")
    if err.errno in (errno.ENOTDIR, errno.EEXIST) or isinstance(err, (NotADirectoryError, FileExistsError)):
        return f"{name} is a file, not a directory: give another {_place(option)} ({option})."
    if isinstance(err, IsADirectoryError):
        return f"{name} is a directory where a file was expected."
    if isinstance(err, FileNotFoundError):
        return f"no such file or directory: {name}."
    return f"{err.strerror or err}: {name}".rstrip(": ")
