"""``python -m fracid`` and the ``fracid`` command: the stop signals are handled before anything heavy is
imported, so that a Ctrl-C while the command starts ends it with a message, not a traceback."""

import os
import sys

from fracid.runtime.exits import describe, stop_signals
from fracid.runtime.stops import stopped_by


def run() -> None:
    """Run the command of ``sys.argv`` and exit with its status (see :mod:`fracid.runtime.exits`)."""
    with stop_signals():
        try:
            from fracid.cli.dispatch import main
        except KeyboardInterrupt as stop:
            print("fracid: stopped while starting; nothing was computed.", file=sys.stderr)
            status = describe(stop)[0]
        else:
            status = main()
    if stopped_by() is not None:
        _exit_now(status)
    sys.exit(status)


def _exit_now(status: int) -> None:
    """Exit with ``status`` after a stop signal, everything already closed. Not through the interpreter's
    exit: under ``python -m`` an interrupt that struck code run by ``exec`` (a dataclass being made, a
    module being imported) leaves a flag that turns any exit status into death by SIGINT (-2)."""
    sys.stdout.flush()
    sys.stderr.flush()
    os._exit(status)


if __name__ == "__main__":
    run()
