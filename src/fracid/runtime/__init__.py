"""The machinery of long work: the resumable batch of forward runs (:mod:`~fracid.runtime.batch`), its
executors (:mod:`~fracid.runtime.executors`: in-process, a process pool, Dask), progress bars and lines,
the stop signals, the locks on an output directory and a run store, and the exit statuses with their
messages (:mod:`~fracid.runtime.exits`).

May import :mod:`fracid.fem`, :mod:`fracid.specimens` and :mod:`fracid.store`; never the models, the
inverse methods, the configuration, the report or the command.
"""
