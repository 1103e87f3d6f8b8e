"""The plumbing every ``fracid`` command shares: loading the configuration, the output directory and its
claim, the directory's lock and run store, the executor of ``--workers`` / ``--scheduler``, the progress
choice, the provenance record and the messages (``say``, ``warn``, ``wrote``).

:mod:`fracid.cli.dispatch` (the parser, the dispatch and simulate / identify / posterior / demo),
:mod:`fracid.cli.studies`, :mod:`fracid.cli.init` and :mod:`fracid.cli.check` import from here, so none of
them imports another's internals.
"""

from __future__ import annotations

import contextlib
import sys
from importlib import resources
from pathlib import Path


def demo_config_path() -> Path:
    """The bundled demo configuration (next to the Gregoire data)."""
    return Path(str(resources.files("fracid.datasets") / "gregoire2013_beam4" / "demo.toml"))


def say(args, text) -> None:
    """Print ``text`` unless ``--quiet``."""
    if not args.quiet:
        print(text, flush=True)


def wrote(args, out, names) -> None:
    """Say which files a command wrote into ``out``: the names, those of a subdirectory counted when many."""
    groups = {}
    for name in map(str, names):
        folder, _, _ = name.rpartition("/")
        groups.setdefault(folder, []).append(name)
    shown = [name for folder, items in groups.items()
             for name in (items if len(items) <= 3 or not folder else [f"{folder}/ ({len(items)} files)"])]
    say(args, f"wrote in {out}: " + ", ".join(shown))


def warn(text) -> None:
    """A warning on stderr, even with ``--quiet``."""
    print(f"fracid: warning: {text}", file=sys.stderr, flush=True)


def load(args, path, purpose):
    """The configuration at ``path`` checked for ``purpose`` (:func:`fracid.config.load_config`); its
    warnings go to stderr."""
    from fracid.config import load_config

    cfg = load_config(path, purpose=purpose)
    for text in cfg.warnings:
        warn(text)
    return cfg


def out_dir(args, cfg) -> Path:
    """The output directory, made if needed, once the command's outputs are known to replace neither an
    input of the run nor a file fracid did not write (:func:`fracid.store.outputs.claim_outputs`), and the
    file of ``--store`` (if given) is known to be usable (:func:`shared_store`)."""
    from fracid.store.outputs import claim_outputs

    inputs = list(run_inputs(cfg))
    if getattr(args, "store", None) is not None:
        shared_store(args.store, inputs)
    out = output_path(args, cfg)
    out.mkdir(parents=True, exist_ok=True)
    claim_outputs(out, args.command, inputs)
    args.out_dir = out
    return out


def output_path(args, cfg) -> Path:
    """The output directory of ``--out`` or ``[output] directory``, not made; NotADirectoryError (exit 4, as
    when a run writes there) if it is a file."""
    out = args.out.expanduser() if args.out is not None else Path(cfg.output.directory)
    if out.exists() and not out.is_dir():
        raise NotADirectoryError(20, "not a directory", str(out))
    return out


def run_inputs(cfg):
    """(what it is, path) of every file the run reads: the configuration, the data files, a mesh."""
    yield "the configuration", Path(cfg.path)
    for exp in cfg.experiments:
        yield f"experiments[{exp.index}].file", Path(exp.file)
    mesh = dict(cfg.specimen.options).get("path")
    if mesh is not None:
        yield "specimen.file", Path(mesh)


@contextlib.contextmanager
def working_in(args, out, store=False):
    """The output directory's lock, and (``store``) its run store: ``OUT/runs.sqlite``, or the file of
    ``--store`` (shared between commands, under a lock of its own); the store's path goes to messages."""
    from fracid.runtime.locks import directory_lock, store_lock
    from fracid.store.runs import RunStore

    shared = getattr(args, "store", None)
    with directory_lock(out):
        if not store:
            yield None
            return
        args.store_path = out / "runs.sqlite" if shared is None else shared_store(shared)
        with contextlib.ExitStack() as stack:
            if shared is not None:
                stack.enter_context(store_lock(args.store_path))
            yield stack.enter_context(RunStore(args.store_path))


def shared_store(path, inputs=()) -> Path:
    """The run store file of ``--store PATH``.

    Parameters
    ----------
    path : path-like
        As given (``~`` expanded).
    inputs : iterable of (str, Path)
        What the run reads and where (the configuration, the data files, a mesh): the store is none of them.

    Raises
    ------
    UsageError
        For a directory, a missing directory, a path that is not a regular file (a device such as
        ``/dev/null``, a pipe), an input of the run, or a file that is not an SQLite database (fracid writes
        only into a store it made); the message names ``--store``.
    """
    from fracid.runtime.exits import UsageError

    path = Path(path).expanduser()
    if path.is_dir():
        raise UsageError(f"--store {path} is a directory; give the run store's file, e.g. --store {path / 'runs.sqlite'}")
    _parent_exists(path, "--store", "a store")
    if not path.exists():
        return path
    instead = f"give the run store's own file, e.g. --store {path.parent / 'runs.sqlite'}"
    if not path.is_file():
        raise UsageError(f"--store {path}: not a regular file (a device, a pipe or a socket): fracid keeps its runs in "
                         "an SQLite file; give the run store's own file, e.g. --store runs.sqlite")
    for what, source in inputs:
        if _same_file(path, source):
            raise UsageError(f"--store {path} is {what}, an input of this run: fracid never writes into its inputs; "
                             f"{instead}")
    head = _head(path)
    if head and not head.startswith(SQLITE_HEADER):
        raise UsageError(f"--store {path}: not a run store (its first bytes {head[:16]!r} are not an SQLite "
                         f"database's): fracid writes only into a store it made; {instead}")
    return path


#: the first bytes of every SQLite 3 database file (https://sqlite.org/fileformat.html)
SQLITE_HEADER = b"SQLite format 3\x00"


def _same_file(a: Path, b: Path) -> bool:
    """Whether ``a`` and ``b`` are the same file (through links); False if either cannot be read."""
    try:
        return a.samefile(b)
    except (OSError, ValueError):
        return False


def _head(path: Path) -> bytes:
    """The first bytes of the file at ``path`` (b"" if it cannot be read: opening it will say why)."""
    try:
        with open(path, "rb") as handle:
            return handle.read(len(SQLITE_HEADER))
    except OSError:
        return b""


def _parent_exists(path: Path, option: str, noun: str) -> None:
    """:class:`~fracid.runtime.exits.UsageError` naming ``option`` when the directory of ``path`` does not exist
    (fracid makes no directory for a file the user names)."""
    from fracid.runtime.exits import UsageError

    if not path.parent.is_dir():
        raise UsageError(f"{option} {path}: the directory {path.parent} does not exist; create it, or give {noun} in an "
                         "existing directory")


def output_file(path, example="fracid.toml") -> Path:
    """The file of ``-o FILE`` (``fracid init``), ``~`` expanded; :class:`~fracid.runtime.exits.UsageError` naming
    ``-o`` for a directory or a missing directory (fracid init makes no directories)."""
    from fracid.runtime.exits import UsageError

    path = Path(path).expanduser()
    if path.is_dir():
        raise UsageError(f"-o {path}: a directory; give a file name such as {path / example}")
    _parent_exists(path, "-o", "a file")
    return path


def progress_choice(args):
    """The ``progress`` argument of the API for this command: False with ``--quiet``, else None (bars on a
    terminal, lines otherwise)."""
    return False if args.quiet else None


@contextlib.contextmanager
def command_executor(args):
    """The executor of --workers / --scheduler; an unusable option is named (exit 2)."""
    from fracid.runtime.exits import UsageError
    from fracid.runtime.executors import executor_session

    if args.scheduler is not None and args.workers is not None:
        raise UsageError(f"--workers {args.workers} and --scheduler {args.scheduler}: give one of them (the Dask "
                         "cluster has its own workers)")
    stack = contextlib.ExitStack()
    try:
        executor = stack.enter_context(executor_session(args.workers, args.scheduler))
    except (ValueError, ImportError, OSError) as err:
        raise UsageError(f"--scheduler {args.scheduler}: cannot use this Dask scheduler ({err}); give its address "
                         "as tcp://host:port, with the dask extra installed (pip install 'fracid[dask]')") from None
    with stack:
        yield executor


def provenance(args, cfg, operator, space, store=None) -> dict:
    """How this run was made (:func:`fracid.store.provenance.collect`), also kept in the run store's meta table."""
    from fracid.store.provenance import collect

    record = collect(argv=getattr(args, "argv", ["fracid"]), config=cfg, data_files=[e.file for e in cfg.experiments],
                     specimen=operator.observations[0].specimen, parameters=operator.base, bounds=space)
    if store is not None:
        store.put_meta(f"provenance:{args.command}", record)
    return record
