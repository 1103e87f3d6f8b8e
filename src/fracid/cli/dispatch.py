"""The ``fracid`` command's parser and dispatch: a thin layer over the Python API, one module per command
(:data:`COMMANDS`), each adding its subparser and the function that runs it.

.. code-block:: text

    fracid simulate CONFIG    forward analysis: curve (CSV), plot (PNG), fields (VTK)
    fracid identify CONFIG    the inverse method of [identify] method: result (JSON), fitted curves (CSV), figures,
                              HTML report
    fracid posterior CONFIG   identify, then weighted samples of the parameters given the data (adaptive
                              importance sampling on the exact model): CSV, JSON, figures, HTML page
    fracid compare CONFIG     every model that runs on the specimen identified on the same data and ranked by
                              log evidence (:mod:`fracid.cli.compare`): compare.json, figures, HTML report
    fracid study CONFIG       the whole strategy through the method's stages: search, sensitivity, uniqueness,
                              refinement, multi-start, stability, prediction of held-out data, size effect;
                              a verdict per parameter
    fracid uniqueness CONFIG  search, objective maps and valley, refinement, multi-start (no replicates)
    fracid stability CONFIG   search, refinement, identification on noisy replicates (no multi-start)
    fracid sensitivity CONFIG normalised sensitivities and information along the load history at the
                              configured parameter values
    fracid size-effect CONFIG nominal strength versus size at the configured parameter values, Bazant fit
    fracid demo               identification of the bundled real test (Gregoire et al. 2013 beam)
    fracid init               a commented configuration to start from (:mod:`fracid.cli.init`)
    fracid check CONFIG       validate a configuration and print its plan and cost (:mod:`fracid.cli.check`)
    fracid datasets           the bundled data sets by name; fracid init --dataset NAME writes one's configuration
                              (:mod:`fracid.cli.datasets`)
    fracid export RESULT --to FORMAT
                              the identified parameters as material input for another code: Abaqus, DIANA, a CSV
                              table of the traction-separation law (:mod:`fracid.cli.export`)
    fracid serve CONFIG       the configuration's forward model as an UM-Bridge model (evaluate, gradient and
                              Jacobian from the exact sensitivities) for UQ tools (:mod:`fracid.cli.serve`)
    fracid --version

Options common to all: --out DIR, --workers N, --scheduler ADDRESS, --quiet, --retry-failed, --debug.
Every expected failure ends with a one-paragraph message and a documented exit status (see
:mod:`fracid.runtime.exits`): 2 bad input, 3 the computation failed, 4 files and storage, 5 out of memory,
130 interrupted; ``--debug`` shows the traceback.
"""

from __future__ import annotations

import argparse
import importlib
import sys
import traceback
from pathlib import Path
from types import SimpleNamespace

from fracid.runtime.progress import progress_lines

__all__ = ["COMMANDS", "main", "version"]

#: the modules of :mod:`fracid.cli` that add commands, in the order of ``fracid --help``; each has
#: ``add_parser(sub, parents)`` (``parents.common``: the options of every command; ``parents.stored``: those
#: and ``--store``), which sets the subparser's ``run`` (args -> exit status)
COMMANDS = ("simulate", "identify", "posterior", "studies", "identify:add_demo_parser", "init", "check", "compare",
            "datasets", "export", "serve")


def _parents() -> SimpleNamespace:
    common = argparse.ArgumentParser(add_help=False)
    common.add_argument("--out", type=Path, help="output directory (default: the config's output.directory)")
    common.add_argument("--workers", type=int, help="parallel forward runs (default: one per core; 1 = serial)")
    common.add_argument("--scheduler", help="address of a Dask scheduler (tcp://host:port) instead of local workers")
    common.add_argument("--quiet", action="store_true", help="no progress bars or summaries")
    common.add_argument("--retry-failed", action="store_true", help="run again the forward runs stored as failed")
    common.add_argument("--debug", action="store_true", help="show the traceback of a failure")
    stored = argparse.ArgumentParser(add_help=False, parents=[common])  # the commands that keep a run store
    stored.add_argument("--store", type=Path, metavar="FILE",
                        help="the run store to read and write instead of OUT/runs.sqlite: commands that share one "
                             "reuse each other's forward runs (same model, specimen, steps and measured controls)")
    return SimpleNamespace(common=common, stored=stored)


def parser() -> argparse.ArgumentParser:
    """The ``fracid`` command's argument parser, with every command's sub-parser."""
    parser = argparse.ArgumentParser(prog="fracid", description="Parameter identification for localized-failure models.")
    parser.add_argument("--version", action="version", version=f"fracid {version()}")
    sub = parser.add_subparsers(dest="command", required=True)
    parents = _parents()
    for entry in COMMANDS:
        module, _, adder = entry.partition(":")
        getattr(importlib.import_module(f"fracid.cli.{module}"), adder or "add_parser")(sub, parents)
    return parser


def version() -> str:
    """The installed fracid's version (:func:`fracid.store.provenance.fracid_version`)."""
    from fracid.store.provenance import fracid_version

    return fracid_version()


def _options(args) -> dict:
    """The options a failure's advice names to choose another place: ``--store FILE`` for a store given so,
    ``out_option`` as the command declares it (``-o FILE`` of ``fracid init``), else ``--out DIR``."""
    out_option = getattr(args, "out_option", "--out DIR")
    return {"out_option": out_option,
            "store_option": "--store FILE" if getattr(args, "store", None) is not None else out_option}


def main(argv=None) -> int:
    """Run the command; returns its exit status (see :mod:`fracid.runtime.exits`), never raises."""
    from fracid.runtime import exits, stops

    args = None
    with exits.stop_signals():
        try:
            args = parser().parse_args(argv)
            args.argv = ["fracid", *(sys.argv[1:] if argv is None else argv)]
            if getattr(args, "workers", None) is not None and args.workers < 1:
                print(f"fracid: --workers = {args.workers}: it must be at least 1", file=sys.stderr)
                return exits.INPUT
            args.store_path = args.out_dir = None
            with progress_lines(not getattr(args, "quiet", False)):
                return args.run(args)
        except SystemExit:
            raise
        except BaseException as err:  # noqa: BLE001 -- every failure becomes a message and an exit status
            if not isinstance(err, KeyboardInterrupt) and stops.stopped_by() is not None:
                err = stops.stopped_by()  # the signal, seen through the code it struck
            status, text = exits.describe(err, store_path=getattr(args, "store_path", None),
                                          out=getattr(args, "out_dir", None), **_options(args))
            if getattr(args, "debug", False):
                traceback.print_exc()
            print(f"fracid: {text}", file=sys.stderr)
            return status


if __name__ == "__main__":
    sys.exit(main())
