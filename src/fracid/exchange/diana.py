"""DIANA material input: the total strain crack model as a script of DIANA's Python commands (``addMaterial``,
``setParameter``; the forms seen in working DIANA 10.x scripts, sources in docs/export/README.md).

DIANA's tension softening curves are named, not tabulated here: Hordijk's (``HORDYK``, with Hordijk's constants c1 = 3,
c2 = 6.93) and the linear one (``LINEAR``) take the strength ``TENSTR`` and the mode-I fracture energy ``GF1``, and
DIANA scales them by its crack band width. The table is compared with both (:func:`shape_difference`): within
0.2 % of ft it is that curve; a law of another shape (another c1, c2, a bilinear law, a continuum model's equivalent
law) is written as the closest curve with the same strength and energy, and the file says how far the shapes differ. The multilinear curve of DIANA (a table in stress and crack
strain) is not written: its keywords were not confirmed in a documented source.
"""

from __future__ import annotations

import numpy as np

from fracid.exchange.header import header_lines
from fracid.fem.material.laws import HordijkLaw, LinearSoftening
from fracid.fem.material.tsl import ShapeLaw

#: DIANA's tension softening curves fracid writes, as fracid's laws of the same shape (DIANA's Hordijk curve has
#: Hordijk's constants, fracid's law's defaults)
DIANA_CURVES = {"HORDYK": HordijkLaw, "LINEAR": LinearSoftening}
#: a table within this of a DIANA curve (in ft) is that curve: the table's own sampling error is 0.06 % of ft
SAME_SHAPE = 2e-3
MATERIAL = "FRACID_CONCRETE"


def shape_difference(table, curve: str) -> float:
    """The largest difference between the table and DIANA's ``curve`` at the table's ft and Gf, in ft [-]."""
    law: ShapeLaw = DIANA_CURVES[curve]()
    params = law.parameters(E=1.0, nu=0.0, ft=table.strength, Gf=table.fracture_energy)
    w = np.linspace(0.0, max(table.critical_opening, law.critical_opening(params)), 2001)
    mine = np.interp(w, table.opening, table.traction, right=0.0)
    return float(np.max(np.abs(law.traction(w, params)[0] - mine)) / table.strength)


def diana_curve(table) -> tuple[str, str]:
    """(DIANA's curve closest in shape to the table, a sentence on how it matches)."""
    differences = {curve: shape_difference(table, curve) for curve in DIANA_CURVES}
    curve = min(differences, key=differences.get)
    if differences[curve] <= SAME_SHAPE:
        return curve, (f"the same law: DIANA's {curve} curve at the table's strength and fracture energy is within "
                       f"{differences[curve]:.2%} of ft of it")
    return curve, (f"APPROXIMATION: DIANA's {curve} curve (the closest of {', '.join(DIANA_CURVES)}) with the table's "
                   f"strength and fracture energy; its shape differs from the table by {differences[curve]:.1%} of ft "
                   "at most (the whole table: fracid export --to csv)")


def write_diana(identified, table, units, representation) -> str:
    """The DIANA Python command script (``#`` comments): elasticity, total strain rotating crack, tension softening."""
    curve, how = diana_curve(table)
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
