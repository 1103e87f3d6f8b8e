"""``python -m fracid`` and the ``fracid`` command: the stop signals are handled before anything heavy is
imported, so that a Ctrl-C while the command starts ends it with a message, not a traceback.

OpenBLAS runs on one thread in the command's own process unless the user set ``OPENBLAS_NUM_THREADS``:
fracid's dense work is many mid-sized factorisations (the correlated-noise SVDs), where OpenBLAS's threads
spin-wait for each other and for the other processes on the cores. Measured on 2 cores (issue 41):
``fracid check examples/dic/identify.toml`` 17 to 44 s with the default threads against 5 to 8 s with one, beside
two busy processes; a 4000 x 1000 SVD 1.9 s against 1.0 s on a quiet machine. The variable must be set before
numpy is first imported (OpenBLAS reads it once). MKL (PARDISO's threads) is left as it is; the workers of
process pools limit every library themselves (:mod:`fracid.runtime.executors`)."""

import os
import sys

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

from fracid.runtime.exits import describe, stop_signals  # noqa: E402 -- after the thread setting, see above
from fracid.runtime.stops import stopped_by  # noqa: E402


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
