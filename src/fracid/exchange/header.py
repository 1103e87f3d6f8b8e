"""The comment block every exported file starts with: where the values come from, how far to trust them, what the
law is (the model's own or an equivalence) and the unit system."""

from __future__ import annotations

from fracid.exchange.law_uncertainty import law_std

#: what an equivalent law is not, said in every file that carries one
EQUIVALENCE_NOTE = ("EQUIVALENCE, not the same model: the {model} model dissipates like this cohesive law in 1D "
                    "(same strength and fracture energy); in 2D its band widens and interacts with the geometry, "
                    "so a structure computed with this law may differ from the {model} model's prediction")


def header_lines(identified, table, units, target: str) -> list[str]:
    """The header's lines (without a comment sign): ``target`` says what the file holds, e.g. ``"Abaqus cohesive
    section with tabular damage evolution"``."""
    lines = [f"fracid export: {target}",
             f"source: {identified.source}",
             f"model: {identified.model_type} ({identified.model.key}); identification status: {identified.status}"]
    lines += [f"  {identified.value_text(name)}" for name in identified.params.names()]
    lines.append(f"law: {table.how}")
    spread = law_std(identified)
    strength, energy = (f" +- {units.converted(s, unit)[0]:.2g}" for s, unit in zip(spread or (0, 0), ("MPa", "N/mm")))
    if spread is None:
        strength = energy = ""
    lines.append(f"  strength {units.converted(table.strength, 'MPa')[0]:.6g}{strength} {units.stress}, fracture energy "
                 f"(area of the table) {units.converted(table.fracture_energy, 'N/mm')[0]:.6g}{energy} {units.energy}, "
                 f"last opening {units.converted(table.critical_opening, 'mm')[0]:.6g} {units.length}")
    if spread is not None:
        lines.append("  (+- one std, the identification's covariance carried to the law by linearisation)")
    if table.relation == "equivalent":
        lines.append(EQUIVALENCE_NOTE.format(model=identified.model_type))
    lines.append(f"units: {units.name} (force N, length {units.length}, stress {units.stress}); every value of the "
                 f"model using this file must be in the same system")
    if identified.std:
        lines.append("the std are the identification's (from its covariance C); the tables are at the estimate")
    return lines
