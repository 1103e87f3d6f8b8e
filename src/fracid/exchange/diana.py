"""DIANA material input: the total strain crack model as a script of DIANA's Python commands (``addMaterial``,
``setParameter``; the forms seen in working DIANA 10.x scripts, sources in docs/export/README.md).

DIANA's tension softening curves are named, not tabulated here: Hordijk's (``HORDYK``, with Hordijk's constants c1 = 3,
c2 = 6.93) and the linear one (``LINEAR``) take the strength ``TENSTR`` and the mode-I fracture energy ``GF1``, and
DIANA scales them by its crack band width. A law of another shape (another c1, c2, a bilinear law, a continuum
model's equivalent law) is written as DIANA's Hordijk curve with the same strength and energy, and the file says how
far the shapes differ (:func:`shape_difference`). The multilinear curve of DIANA (a table in stress and crack
strain) is not written: its keywords were not confirmed in a documented source.
"""

from __future__ import annotations

import numpy as np

from fracid.exchange.header import header_lines
from fracid.fem.material.laws import HordijkLaw, LinearSoftening
from fracid.fem.material.tsl import ShapeLaw

#: fracid's laws that DIANA has by name: the DIANA curve and the shape parameters its own curve fixes
NATIVE = {"hordijk": ("HORDYK", {"c1": 3.0, "c2": 6.93}), "linear": ("LINEAR", {})}
#: DIANA's curve for any other shape (same ft and Gf)
FALLBACK = "HORDYK"
MATERIAL = "FRACID_CONCRETE"


def shape_difference(table, curve: str) -> float:
    """The largest difference between the table and DIANA's ``curve`` at the table's ft and Gf, in ft [-]."""
    law: ShapeLaw = HordijkLaw() if curve == "HORDYK" else LinearSoftening()
    params = law.parameters(E=1.0, nu=0.0, ft=table.strength, Gf=table.fracture_energy)
    w = np.linspace(0.0, max(table.critical_opening, law.critical_opening(params)), 2001)
    mine = np.interp(w, table.opening, table.traction, right=0.0)
    return float(np.max(np.abs(law.traction(w, params)[0] - mine)) / table.strength)


def diana_curve(identified, table) -> tuple[str, str]:
    """(DIANA's curve, a sentence on how it matches the table)."""
    law = getattr(identified.model, "law", None)
    native = NATIVE.get(getattr(law, "name", None)) if table.relation == "same" else None
    if native is not None and all(np.isclose(getattr(identified.params, k), v) for k, v in native[1].items()):
        return native[0], f"the same law: DIANA's {native[0]} curve is fracid's {law.name} law"
    difference = shape_difference(table, FALLBACK)
    return FALLBACK, (f"APPROXIMATION: DIANA's {FALLBACK} curve with the table's strength and fracture energy; its "
                      f"shape differs from the table by {difference:.1%} of ft at most (the whole table: fracid export "
                      "--to csv)")


def write_diana(identified, table, units, representation) -> str:
    """The DIANA Python command script (``#`` comments): elasticity, total strain rotating crack, tension softening."""
    curve, how = diana_curve(identified, table)
    E, _ = units.converted(identified.params.E, "MPa")
    ft, _ = units.converted(table.strength, "MPa")
    gf, _ = units.converted(table.fracture_energy, "N/mm")
    lines = [f"# {line}" for line in header_lines(identified, table, units,
                                                 "DIANA total strain crack model (Python commands of DIANA 10.x)")]
    lines += [f"# tension softening: {how}",
              "# crack band width: DIANA's own rule from the element (CBSPEC); fracid's crack band scales the law by the "
              "element's width across the crack. 'ROTS' is the only CBSPEC value confirmed (seen in working scripts); "
              "set the rule your mesh needs",
              "# compression, density and Poisson reduction: not identified by fracid; set them (e.g. COMPRS/COMCRV "
              "PARABO with COMSTR and GC, seen in working scripts)",
              f"addMaterial( \"{MATERIAL}\", \"CONCR\", \"TSCR\", [] )",
              f"setParameter( MATERIAL, \"{MATERIAL}\", \"LINEAR/ELASTI/YOUNG\", {E:.12g} )",
              f"setParameter( MATERIAL, \"{MATERIAL}\", \"LINEAR/ELASTI/POISON\", {identified.params.nu:.12g} )",
              f"setParameter( MATERIAL, \"{MATERIAL}\", \"MODTYP/TOTCRK\", \"ROTATE\" )",
              f"setParameter( MATERIAL, \"{MATERIAL}\", \"TENSIL/TENCRV\", \"{curve}\" )",
              f"setParameter( MATERIAL, \"{MATERIAL}\", \"TENSIL/TENSTR\", {ft:.12g} )",
              f"setParameter( MATERIAL, \"{MATERIAL}\", \"TENSIL/GF1\", {gf:.12g} )",
              f"# setParameter( MATERIAL, \"{MATERIAL}\", \"TENSIL/CBSPEC\", \"ROTS\" )",
              "# the same in a .dat file's MATERIALS table (DIANA 10.x style, as written by working input writers):",
              *(f"#   {line}" for line in (f'1 NAME "{MATERIAL}"', "  MCNAME CONCR", "  MATMDL TSCR", f"  YOUNG  {E:.12g}",
                                          f"  POISON {identified.params.nu:.12g}", "  TOTCRK ROTATE",
                                          f"  TENCRV {curve}", f"  TENSTR {ft:.12g}", f"  GF1    {gf:.12g}"))]
    return "\n".join(lines) + "\n"
