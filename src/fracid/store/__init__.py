"""What is kept of a computation: the run store (:mod:`~fracid.store.runs`, SQLite, one row per forward run)
and its records (:mod:`~fracid.store.records`), the output directory's guard (:mod:`~fracid.store.outputs`),
the provenance of a result (:mod:`~fracid.store.provenance`) and result tables as files
(:mod:`~fracid.store.tables`).

May import :mod:`fracid.runtime` (the exit statuses) and the standard library; nothing of the models, the
inverse methods, the configuration or the report.
"""
