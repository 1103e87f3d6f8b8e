"""Hostile-input cases (plausibility of bounds and settings, the posterior's effective sample size, misfit warnings); run by tests/test_hostile_inputs.py."""

from __future__ import annotations

from hostile import IDENTIFY, OUT, case  # noqa: F401

CASES = {
}
