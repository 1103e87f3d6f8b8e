"""Hostile-input cases of issue 38 (status); run by tests/test_hostile_inputs.py."""

from __future__ import annotations

from hostile import case  # noqa: F401 -- the cases' constructor

CASES: dict = {}
