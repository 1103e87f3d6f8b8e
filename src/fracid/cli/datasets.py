"""``fracid datasets`` and ``fracid init --dataset NAME``: the bundled data sets (:mod:`fracid.datasets`).

``fracid datasets`` lists them: name, specimen, suggested model, licence, citation. ``fracid init --dataset
NAME -o FILE`` writes the data set's configuration to FILE and copies its data file(s) and the source's
licence text beside it, so that ``fracid identify FILE`` runs as written; without ``-o`` the configuration
goes to standard output with the installed data files named by their absolute paths. An existing FILE is
replaced only with ``--force`` (as ``fracid init``); a file beside it that has a data file's name is never
replaced unless it already holds the same bytes (then it is left as it is).
"""

from __future__ import annotations

import filecmp
import re
import shutil
import sys
from pathlib import Path

from fracid.cli.common import output_file

#: the columns of ``fracid datasets``: (heading, Dataset attribute)
COLUMNS = (("NAME", "name"), ("SPECIMEN", "specimen"), ("MODEL", "model"), ("LICENCE", "licence"),
           ("CITATION", "citation"))


def add_parser(sub, parents) -> None:
    """The ``datasets`` subcommand, and ``--dataset NAME`` of ``init`` (added to the parser that
    :func:`fracid.cli.init.add_parser` made, so that ``init`` keeps one parser)."""
    p = sub.add_parser("datasets", help="list the bundled data sets (fracid init --dataset NAME writes one's config)")
    p.add_argument("--debug", action="store_true", help="show the traceback of a failure")
    p.set_defaults(run=run)
    init = sub.choices["init"]
    init.set_defaults(run=_init_or_dataset(init.get_default("run")))
    init.add_argument(
        "--dataset", metavar="NAME", help="write the configuration of a bundled data set (`fracid datasets` lists "
                                          "them), its data file and licence copied beside -o FILE")


def _init_or_dataset(run_init):
    """``fracid init``'s run: :func:`run` when ``--dataset NAME`` is given, else ``run_init``."""
    return lambda args: run(args) if args.dataset is not None else run_init(args)


def run(args) -> int:
    """``fracid datasets`` or ``fracid init --dataset NAME``."""
    if args.command == "datasets":
        print("\n".join(listing()))
        return 0
    return init_dataset(args)


def listing() -> list[str]:
    """The lines of ``fracid datasets``: a heading, one aligned row per data set, a hint."""
    from fracid.datasets import DATASETS

    rows = [[heading for heading, _ in COLUMNS]]
    rows += [[getattr(ds, attribute) for _, attribute in COLUMNS] for ds in DATASETS.values()]
    widths = [max(len(row[i]) for row in rows) for i in range(len(COLUMNS) - 1)]
    lines = ["  ".join([*(cell.ljust(width) for cell, width in zip(row, widths)), row[-1]]) for row in rows]
    return lines + ["", "fracid init --dataset NAME -o FILE: its configuration, with the data file and licence "
                        "beside FILE; fracid identify FILE runs it. Source, geometry, units and scatter: "
                        "the README of fracid.datasets.get(NAME).readme_path"]


def config_text(ds, references: dict, licence: str) -> str:
    """The configuration of the data set ``ds`` with a heading that cites it, its data files named by
    ``references`` (file name -> the path to write in ``file = ...``).

    Parameters
    ----------
    ds : fracid.datasets.Dataset
        The data set.
    references : dict
        For each data file's name (as the configuration names it), the reference to write instead.
    licence : str
        Where the licence text is, as the heading says it.

    Returns
    -------
    str
        TOML text; the configuration's own text (and comments) otherwise unchanged.
    """
    from fracid.settings.checks import toml_value

    def reference(match):
        name = match.group(2)
        return match.group(1) + toml_value(references[name]) if name in references else match.group(0)

    text = re.sub(r'^(file\s*=\s*)"([^"\n]*)"', reference, ds.config_path.read_text(encoding="utf-8"), flags=re.M)
    head = [f"# fracid data set {ds.name!r} (written by `fracid init --dataset {ds.name}`): {ds.title}.",
            f"# Cite: {ds.citation}.",
            f"# Licence of the data: {ds.licence}; its text: {licence}.",
            f"# Source, geometry, units, scatter and what is assumed: {ds.readme_path}",
            "# Check it: fracid check FILE; run it: fracid identify FILE.", ""]
    return "\n".join(head) + text


def init_dataset(args) -> int:
    """``fracid init --dataset NAME [-o FILE] [--force]``: the configuration on standard output, or written
    to FILE with the data set's files copied beside it."""
    from fracid.datasets import get
    from fracid.runtime.exits import UsageError

    ds = get(args.dataset)  # an unknown name: UnknownDataset, exit 2, the names listed
    if args.list or args.specimen is not None or args.model is not None:
        raise UsageError(f"--dataset {ds.name} writes the data set's own configuration ({ds.specimen}, {ds.model}): "
                         "--specimen, --model and --list do not go with it")
    if args.output is None:
        sys.stdout.write(config_text(ds, {file.name: str(file) for file in ds.file_paths}, str(ds.licence_path)))
        return 0
    path = output_file(args.output, ds.name + ".toml")
    copied = copy_beside(ds, path, args.force)
    text = config_text(ds, {file.name: file.name for file in ds.file_paths}, f"{ds.licence_path.name}, beside this file")
    path.write_text(text, encoding="utf-8")
    print(f"wrote {path} and, beside it, {', '.join(copied)}: check it with "
          f"`fracid check {path}`, run it with `fracid identify {path}`", file=sys.stderr)
    return 0


def copy_beside(ds, path: Path, force: bool) -> list[str]:
    """Copy the data files and the licence of ``ds`` beside the configuration file ``path`` (written next by the
    caller), once nothing would be overwritten (:func:`_copies`); returns the names copied or found there."""
    copies = _copies(ds, path, force)
    for target, source in copies.items():
        if not target.exists():  # an existing one holds the same bytes (_copies checked)
            shutil.copyfile(source, target)
    return sorted(target.name for target in copies)


def bundled_dataset(config: Path):
    """The bundled data set whose configuration is ``config`` (the demo's: :func:`fracid.cli.common.demo_config_path`)."""
    from fracid.datasets import DATASETS

    return next(ds for ds in DATASETS.values() if Path(ds.config_path) == Path(config))


def _copies(ds, path: Path, force: bool) -> dict:
    """{file beside ``path``: installed file} for the data files and the licence, once nothing would be
    overwritten: ``path`` only with ``force``, a copy never (UsageError naming the file)."""
    from fracid.runtime.exits import UsageError

    if path.is_dir():
        raise UsageError(f"-o {path}: a directory; give a file name such as {path / (ds.name + '.toml')}")
    copies = {path.parent / file.name: file for file in (*ds.file_paths, ds.licence_path)}
    if path.name in {target.name for target in copies}:
        raise UsageError(f"-o {path}: the name of a file of the data set, copied beside it; give another name")
    if (path.exists() or path.is_symlink()) and not force:
        raise UsageError(f"-o {path}: the file exists; fracid init does not overwrite it (give --force to replace it)")
    for target, source in copies.items():
        if (target.exists() or target.is_symlink()) and not (target.is_file() and filecmp.cmp(target, source, False)):
            raise UsageError(f"{target}: a different file of this name exists beside -o {path.name}; fracid init "
                             "never overwrites it (--force replaces the -o file only): write the configuration "
                             "into another directory")
    return copies
