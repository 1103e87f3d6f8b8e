"""Hostile-input cases (data files: signs, order, separators, spreadsheet exports, comment lines, swapped columns); run by tests/test_hostile_inputs.py."""

from __future__ import annotations

from hostile import IDENTIFY, OUT, case  # noqa: F401

CASES = {
}
