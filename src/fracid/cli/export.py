"""``fracid export RESULT --to FORMAT``: an identification's parameters as material input for another code (Abaqus,
DIANA, a CSV table of the traction-separation law): :mod:`fracid.exchange`."""

from __future__ import annotations

import sys
from pathlib import Path

from fracid.cli.common import output_file


def add_parser(sub, parents) -> None:
    """The ``export`` subcommand's arguments."""
    from fracid.exchange.formats import EXPORT_FORMATS, REPRESENTATIONS
    from fracid.exchange.units import UNIT_SYSTEMS

    formats = "; ".join(f"{name}: {fmt.name} ({fmt.representations_note})" for name, fmt in EXPORT_FORMATS.items())
    p = sub.add_parser("export", help="the identified parameters as material input for another code",
                       description=f"Formats: {formats}.")
    p.add_argument("result", type=Path, help="result.json of fracid identify")
    p.add_argument("--to", required=True, metavar="FORMAT", help=f"one of {', '.join(EXPORT_FORMATS)}")
    p.add_argument("--units", default="N-mm-MPa", metavar="SYSTEM",
                   help=f"the consistent unit system to write in: {', '.join(UNIT_SYSTEMS)} (default N-mm-MPa)")
    p.add_argument("--as", dest="representation", metavar="KIND",
                   help=f"the crack as {' or '.join(REPRESENTATIONS)} (default: the model's: discrete for the "
                        "cohesive crack, smeared for the others)")
    p.add_argument("-o", "--output", type=Path, help="file to write (default: standard output)")
    p.add_argument("--force", action="store_true", help="replace an existing -o file")
    p.add_argument("--debug", action="store_true", help="show the traceback of a failure")
    p.set_defaults(run=run_export, out_option="-o FILE")


def run_export(args) -> int:
    """Write the export to ``-o FILE`` (never over a file without ``--force``) or to standard output."""
    from fracid.exchange.export import export_text
    from fracid.runtime.exits import UsageError

    text = export_text(args.result, args.to, args.units, args.representation)
    if args.output is None:
        sys.stdout.write(text)
        return 0
    path = output_file(args.output, example=f"material{Path(args.output).suffix or '.txt'}")
    if (path.exists() or path.is_symlink()) and not args.force:
        raise UsageError(f"-o {path}: the file exists; fracid export does not overwrite it (give --force to replace "
                         "it)")
    path.write_text(text, encoding="utf-8")
    print(f"wrote {path}", file=sys.stderr)
    return 0
