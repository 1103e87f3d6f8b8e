"""``python -m fracid`` and the ``fracid`` command: the stop signals are handled before anything heavy is
imported, so that a Ctrl-C while the command starts ends it with a message, not a traceback."""

import sys

from fracid.exits import INTERRUPTED, TERMINATED, stop_signals


def run() -> None:
    """Run the command of ``sys.argv`` and exit with its status (see :mod:`fracid.exits`)."""
    with stop_signals():
        try:
            from fracid.cli import main
        except KeyboardInterrupt as stop:
            print("fracid: stopped while starting; nothing was computed.", file=sys.stderr)
            sys.exit(TERMINATED if type(stop).__name__ == "Terminated" else INTERRUPTED)
        status = main()
    sys.exit(status)


if __name__ == "__main__":
    run()
