"""Hostile-input cases (outputs that would overwrite inputs or files fracid did not write, the configuration path, signals, the run store's SQLite errors, paths); run by tests/test_hostile_inputs.py."""

from __future__ import annotations

from hostile import IDENTIFY, OUT, case  # noqa: F401

CASES = {
}
