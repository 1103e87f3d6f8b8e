"""Abaqus material input (keywords of the Abaqus Keywords Reference; the sources of each are in docs/export/README.md
and in the file's comments).

- A discrete crack: a cohesive section with traction-separation response, ``*ELASTIC, TYPE=TRACTION`` (a penalty
  stiffness K), ``*DAMAGE INITIATION, CRITERION=MAXS`` at ft and ``*DAMAGE EVOLUTION, TYPE=DISPLACEMENT,
  SOFTENING=TABULAR``: the damage D against the effective separation after initiation u, from the law sigma(u) by
  t = (1 - D) K delta with delta = delta0 + u, delta0 = ft / K: D = 1 - sigma(u) / (K (delta0 + u)).
- A smeared crack: concrete damaged plasticity's tension, ``*CONCRETE TENSION STIFFENING, TYPE=DISPLACEMENT`` (the
  traction against the cracking displacement, so that Abaqus keeps the fracture energy whatever the element size).
"""

from __future__ import annotations

import numpy as np

from fracid.exchange.header import header_lines

#: the interface's penalty stiffness in the law's ft / wc: the elastic separation at ft, delta0 = wc / 1e4, keeps the
#: interface rigid to 0.01 % of the law's openings (as fracid's own penalty does)
STIFFNESS_IN_LAW_SLOPES = 1e4
#: concrete damaged plasticity's dilation angle [deg]: not identified by fracid, a placeholder (30 to 40 in decks)
DILATION_ANGLE = 35.0
#: the compressive yield stress's placeholder, in ft (fracid identifies no compression)
COMPRESSION_IN_FT = 10.0
#: the largest tension damage written (Abaqus's material guide advises against d_t above 0.99, secondary sources)
MAX_TENSION_DAMAGE = 0.99
#: the growth of the damage table's openings from delta0 / 50 on (rows enough for Abaqus's linear interpolation)
ROW_GROWTH = 1.05
#: which keywords the file's comments cite (docs/export/README.md lists the sources)
SOURCES = "Abaqus Keywords Reference: *COHESIVE SECTION, *ELASTIC, *DAMAGE INITIATION, *DAMAGE EVOLUTION"


def _comments(lines) -> list[str]:
    return [f"** {line}" for line in lines]


def _number(value: float) -> str:
    return f"{value:.12g}"


def damage_table(table, stiffness: float) -> tuple[np.ndarray, np.ndarray]:
    """(D, u) of the tabular damage evolution: u = the opening after initiation [length], D = 1 - sigma(u) /
    (K (delta0 + u)), delta0 = ft / K; D = 0 at u = 0 and 1 where the law ends.

    Abaqus interpolates D linearly between rows, and 1 - D falls like delta0 / (delta0 + u) over a few delta0: the rows
    are the law's openings and openings growing geometrically from delta0 / 50 by :data:`ROW_GROWTH` (the
    traction between two rows is then within 0.1 % of ft of the law's, measured 0.06 %: tests/test_export_files.py)."""
    delta0 = table.strength / stiffness
    steps = np.ceil(np.log(50.0 * table.critical_opening / delta0) / np.log(ROW_GROWTH))
    geometric = 0.02 * delta0 * ROW_GROWTH ** np.arange(steps)
    u = np.union1d(table.opening, geometric[geometric < table.critical_opening])
    sigma = np.interp(u, table.opening, table.traction)
    damage = np.clip(1.0 - sigma / (stiffness * (delta0 + u)), 0.0, 1.0)
    damage[0] = 0.0  # 1 - ft / (K delta0), zero but for rounding
    return damage, u


def cohesive_lines(identified, table, units) -> list[str]:
    """The material and the section of a cohesive interface."""
    converted = table.scaled(units.to_length, units.to_stress)
    ft, wc = converted.strength, converted.critical_opening
    stiffness = STIFFNESS_IN_LAW_SLOPES * ft / wc
    damage, opening = damage_table(converted, stiffness)
    return [
        *_comments([
            f"cohesive interface (discrete crack): {SOURCES}",
            f"K = {STIFFNESS_IN_LAW_SLOPES:g} ft / wc [{units.stiffness}]: delta0 = ft / K = wc / {STIFFNESS_IN_LAW_SLOPES:g}; "
            "the table's D depends on K: change K only with the table (D = 1 - t(u) / (K (delta0 + u)))",
            "fracid identified the opening mode only: the shear stiffnesses Kss = Ktt = Knn and shear strengths = ft "
            "are placeholders; set them for your structure",
            "columns of the damage evolution: D, effective separation after initiation (delta_m - delta_m0); the last "
            "row (D = 1) deletes the element by default: see *SECTION CONTROLS, MAX DEGRADATION",
            "constitutive thickness T0 = 1 on the section's data line (traction-separation response): the separation is "
            "the nominal strain; second field: the out-of-plane thickness of 2D cohesive elements (fill in)"]),
        "*MATERIAL, NAME=FRACID_COHESIVE",
        "*ELASTIC, TYPE=TRACTION",
        ", ".join(_number(stiffness) for _ in range(3)),
        "*DAMAGE INITIATION, CRITERION=MAXS",
        ", ".join(_number(ft) for _ in range(3)),
        "*DAMAGE EVOLUTION, TYPE=DISPLACEMENT, SOFTENING=TABULAR",
        *(f"{d:.15g}, {_number(u)}" for d, u in zip(damage, opening)),
        "** *COHESIVE SECTION, ELSET=<your cohesive elements>, MATERIAL=FRACID_COHESIVE, "
        "RESPONSE=TRACTION SEPARATION, THICKNESS=SPECIFIED",
        "** 1.0,",
    ]


def write_abaqus(identified, table, units, representation) -> str:
    """The Abaqus input text: the header as ``**`` comments, then the material of the representation."""
    target = {"discrete": "Abaqus cohesive interface with tabular damage evolution",
              "smeared": "Abaqus concrete damaged plasticity, tension stiffening by cracking displacement"}
    lines = _comments(header_lines(identified, table, units, target[representation]))
    body = cohesive_lines(identified, table, units) if representation == "discrete" else \
        smeared_lines(identified, table, units)
    return "\n".join([*lines, *body]) + "\n"


def tension_damage(table, E: float, reference_length: float) -> np.ndarray:
    """d_t at each cracking displacement u_ck of the table for secant unloading (fracid's crack band unloads to the
    origin): Abaqus's plastic displacement u_pl = u_ck - d_t / (1 - d_t) sigma l0 / E0 is zero when d_t = u_ck E0
    / (u_ck E0 + sigma l0); capped at :data:`MAX_TENSION_DAMAGE` (u_pl then grows, never decreases)."""
    u, sigma = table.opening, table.traction
    return np.minimum(u * E / (u * E + sigma * reference_length), MAX_TENSION_DAMAGE)


def smeared_lines(identified, table, units) -> list[str]:
    """Concrete damaged plasticity with its tension by cracking displacement; the plasticity and compression
    parameters fracid does not identify are written as marked placeholders."""
    converted = table.scaled(units.to_length, units.to_stress)
    E, _ = units.converted(identified.params.E, "MPa")
    nu = identified.params.nu
    ft = converted.strength
    damage = tension_damage(converted, E, 1.0)
    return [
        *_comments([
            "concrete damaged plasticity (smeared crack): Abaqus Keywords Reference *CONCRETE DAMAGED PLASTICITY, "
            "*CONCRETE COMPRESSION HARDENING, *CONCRETE TENSION STIFFENING, *CONCRETE TENSION DAMAGE",
            "tension stiffening TYPE=DISPLACEMENT: remaining stress against the cracking displacement, the law's "
            "(opening, traction) as it is: its area is the fracture energy, whatever the element size",
            f"PLACEHOLDERS (fracid identified none of them): dilation angle {DILATION_ANGLE:g} deg, eccentricity 0.1, "
            "fb0/fc0 1.16, K 2/3, viscosity 0 (Abaqus's usual values, the angle typical of decks); compression "
            f"perfectly plastic at {COMPRESSION_IN_FT:g} ft. Replace them with your concrete's",
            "tension damage d_t: chosen so that the plastic displacement u_pl = u_ck - d_t / (1 - d_t) sigma l0 / E0 "
            f"is zero (secant unloading, as fracid's crack band), l0 = 1 {units.length} (Abaqus's reference length "
            f"when REF LENGTH is not given), capped at {MAX_TENSION_DAMAGE:g}; the formula is from secondary sources "
            "(docs/export/README.md): drop the *CONCRETE TENSION DAMAGE block if unsure, the monotonic response is "
            "the same"]),
        "*MATERIAL, NAME=FRACID_CONCRETE",
        "*ELASTIC",
        f"{_number(E)}, {_number(nu)}",
        "*CONCRETE DAMAGED PLASTICITY",
        f"{DILATION_ANGLE:g}, 0.1, 1.16, 0.666667, 0.0",
        "*CONCRETE COMPRESSION HARDENING",
        f"{_number(COMPRESSION_IN_FT * ft)}, 0.0",
        "*CONCRETE TENSION STIFFENING, TYPE=DISPLACEMENT",
        *(f"{_number(s)}, {_number(u)}" for s, u in zip(converted.traction, converted.opening)),
        "*CONCRETE TENSION DAMAGE, TYPE=DISPLACEMENT",
        *(f"{_number(d)}, {_number(u)}" for d, u in zip(damage, converted.opening)),
    ]
