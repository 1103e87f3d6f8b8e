"""The consistent unit systems ``fracid export`` writes in (:data:`UNIT_SYSTEMS`): fracid computes in N, mm and MPa;
a code that has no units of its own (Abaqus, DIANA) takes whatever system its whole model uses."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class UnitSystem:
    """A consistent unit system: force N always, length ``length``; the factors turn fracid's values into it.

    Attributes
    ----------
    name : str
        e.g. ``"N-mm-MPa"``.
    length, stress, energy, stiffness : str
        Unit names of a length, a stress, an energy per area (fracture energy) and a stiffness per area
        (an interface's stiffness, stress per opening).
    to_length, to_stress, to_energy, to_stiffness : float
        Factors from mm, MPa, N/mm and MPa/mm.
    """

    name: str
    length: str
    stress: str
    energy: str
    stiffness: str
    to_length: float
    to_stress: float
    to_energy: float
    to_stiffness: float

    def converted(self, value: float, unit: str) -> tuple[float, str]:
        """A parameter ``value`` in fracid's ``unit`` (mm, MPa, N/mm, mm^2, -) -> (value, unit) in this system."""
        factors = {"mm": (self.to_length, self.length), "MPa": (self.to_stress, self.stress),
                   "N/mm": (self.to_energy, self.energy), "mm^2": (self.to_length ** 2, f"{self.length}^2")}
        factor, name = factors.get(unit, (1.0, unit))
        return value * factor, name


#: ``--units`` of ``fracid export``: the system the file is written in
UNIT_SYSTEMS = {
    "N-mm-MPa": UnitSystem("N-mm-MPa", "mm", "MPa", "N/mm", "MPa/mm", 1.0, 1.0, 1.0, 1.0),
    "N-m-Pa": UnitSystem("N-m-Pa", "m", "Pa", "N/m", "Pa/m", 1e-3, 1e6, 1e3, 1e9),
}
