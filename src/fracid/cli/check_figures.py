"""The check figures ``fracid check`` writes: a field block's frames synchronised with the testing machine's log
(:mod:`fracid.report.sync_figure`), as ``check/<block>_sync.png`` in the configuration's output directory.

A block whose kind gives ``view_extras`` with a ``sync`` (the frames on the log's clock) gets its figure; the
directory ``check`` is recorded in the output directory's manifest before anything is written, so a file fracid
did not write is never replaced (:func:`fracid.store.outputs.claim_outputs`: exit 2 naming it). The same figure
is in the report of ``fracid identify`` (``figures/<block>_sync.png``).
"""

from __future__ import annotations

from pathlib import Path

#: the directory (in the output directory) of the check figures
CHECK_DIR = "check"


def synchronised_blocks(cfg, specimen) -> list:
    """(block name, SynchronisedFrames) of every block synchronised with a machine log, in the configuration's
    order (the blocks are the ones built for the check: no second read)."""
    found = []
    for exp in cfg.experiments:
        extras = exp.view_extras(specimen) if hasattr(exp, "view_extras") else {}
        if extras.get("sync") is not None:
            found.append((exp.name, extras["sync"]))
    return found


def check_figure_lines(cfg, out: Path, inputs) -> list:
    """Write the check figure of every synchronised block into ``out/check`` and return the lines naming them
    (none when no block has a machine log: then nothing is made, not even the directory).

    Raises
    ------
    fracid.store.outputs.OutputRefused
        ``out/check`` exists and fracid did not write it, or it is an input of the run (exit 2).
    """
    from fracid.config import build_specimen
    from fracid.report.sync_figure import write_synchronisation_figure
    from fracid.store.outputs import claim_outputs

    blocks = synchronised_blocks(cfg, build_specimen(cfg))
    if not blocks:
        return []
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    claim_outputs(out, "check", inputs)
    (out / CHECK_DIR).mkdir(exist_ok=True)
    lines = []
    for name, sync in blocks:
        path = write_synchronisation_figure(sync, out / CHECK_DIR / f"{name}_sync.png", overwrite=True)
        lines.append(f"check figure of {name!r}: {path} (the frames on the machine log's load curve and clock, "
                     f"{sync.times.method}, +- {sync.times.uncertainty:.3g} s; also in the report)")
    return lines


__all__ = ["CHECK_DIR", "check_figure_lines", "synchronised_blocks"]
