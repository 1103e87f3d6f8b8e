"""Hostile-input cases (Gmsh meshes: disconnected, duplicate nodes, overlapping groups, unreadable formats, size and unit plausibility); run by tests/test_hostile_inputs.py."""

from __future__ import annotations

from hostile import IDENTIFY, OUT, case  # noqa: F401

CASES = {
}
