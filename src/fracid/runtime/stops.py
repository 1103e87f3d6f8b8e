"""The stop signals this process received (SIGINT, SIGTERM, SIGHUP), on the lowest floor: the command's
handlers (:func:`fracid.runtime.exits.stop_signals`) record them here, and long work below the command (the batch of
forward runs) asks :func:`raise_if_stopped` at its checkpoints."""

from __future__ import annotations

import signal


class Terminated(KeyboardInterrupt):
    """SIGTERM, raised in the main thread so that the run ends as cleanly as after Ctrl-C."""


class HungUp(Terminated):
    """SIGHUP (the terminal or the SSH session closed), ended as SIGTERM is."""


RAISED_BY = {"SIGINT": KeyboardInterrupt, "SIGTERM": Terminated, "SIGHUP": HungUp}
#: the stop signals received by this process (the first one raised; the others were ignored)
received: list[int] = []


def stopped_by() -> BaseException | None:
    """The exception of the first stop signal received, or None: a signal that struck inside an import or
    a library may reach the command as another exception (``ImportError: initialization failed``)."""
    return RAISED_BY[signal.Signals(received[0]).name]() if received else None


def raise_if_stopped() -> None:
    """Raise the first stop signal's exception if one was received: a checkpoint where long work goes on
    (every finished forward run of a batch), for a signal whose exception a library
    swallowed. After the exception has propagated the work is over and no checkpoint is reached again."""
    if received:
        raise stopped_by()
