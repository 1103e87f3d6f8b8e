"""The Abaqus and DIANA files of ``fracid export`` parsed back by small readers: keywords, tables and units carry the
values of result.json."""

import numpy as np
import pytest

from fracid.exchange.export import export_text
from fracid.models.registry import model_from_type
from test_export import CRACK, DAMAGE, write_result

SI = {"length": 1e-3, "stress": 1e6, "energy": 1e3}
MM = {"length": 1.0, "stress": 1.0, "energy": 1.0}


def abaqus_blocks(text):
    """[(keyword, {parameter: value}, rows)] of an Abaqus input: ``**`` comments skipped, a row a list of floats."""
    blocks = []
    for line in text.splitlines():
        if line.startswith("**") or not line.strip():
            continue
        if line.startswith("*"):
            name, *options = [part.strip() for part in line[1:].split(",")]
            blocks.append((name.upper(), dict(o.split("=", 1) if "=" in o else (o, "") for o in options), []))
        else:
            blocks[-1][2].append([float(v) for v in line.split(",") if v.strip()])
    return blocks


def block(blocks, name, **options):
    found = [rows for n, opts, rows in blocks if n == name and all(opts.get(k) == v for k, v in options.items())]
    assert len(found) == 1, (name, options, [b[:2] for b in blocks])
    return np.array(found[0])


CASES = [("cohesive-crack", CRACK, ("ft", "Gf")), ("crack-band", CRACK, ("ft", "Gf")),
         ("gradient-damage", DAMAGE, ("kappa_i", "beta", "c"))]


@pytest.mark.parametrize("units, scale", [("N-mm-MPa", MM), ("N-m-Pa", SI)], ids=["mm", "m"])
@pytest.mark.parametrize("model_type, values, identified", CASES, ids=[c[0] for c in CASES])
def test_the_abaqus_cohesive_interface_gives_back_the_law(tmp_path, model_type, values, identified, units, scale):
    law = model_from_type(model_type).cohesive_law(model_from_type(model_type).parameters(**values))
    blocks = abaqus_blocks(export_text(write_result(tmp_path, model_type, values, identified), "abaqus", units,
                                       representation="discrete"))
    K = block(blocks, "ELASTIC", TYPE="TRACTION")[0]
    strengths = block(blocks, "DAMAGE INITIATION", CRITERION="MAXS")[0]
    table = block(blocks, "DAMAGE EVOLUTION", TYPE="DISPLACEMENT", SOFTENING="TABULAR")
    assert np.allclose(strengths, law.strength * scale["stress"], rtol=1e-10) and np.all(K == K[0])
    damage, u = table[:, 0], table[:, 1]
    assert damage[0] == 0.0 and damage[-1] == pytest.approx(1.0) and np.all(np.diff(damage) >= 0)
    traction = (1.0 - damage) * K[0] * (strengths[0] / K[0] + u)  # t = (1 - D) K delta, delta = delta0 + u
    expected = np.interp(u, law.opening * scale["length"], law.traction * scale["stress"])
    assert np.allclose(traction, expected, rtol=1e-8, atol=1e-9 * strengths[0])
    nearest = np.min(np.abs(law.opening[:, None] * scale["length"] - u[None, :]), axis=1)
    assert np.all(nearest <= 1e-9 * u[-1])  # the law's own points are rows
    assert np.trapezoid(traction, u) == pytest.approx(law.fracture_energy * scale["energy"], rel=1e-8)


@pytest.mark.parametrize("units, scale", [("N-mm-MPa", MM), ("N-m-Pa", SI)], ids=["mm", "m"])
@pytest.mark.parametrize("model_type, values, identified", CASES, ids=[c[0] for c in CASES])
def test_the_abaqus_concrete_damaged_plasticity_keeps_the_law_and_its_energy(tmp_path, model_type, values, identified,
                                                                              units, scale):
    law = model_from_type(model_type).cohesive_law(model_from_type(model_type).parameters(**values))
    blocks = abaqus_blocks(export_text(write_result(tmp_path, model_type, values, identified), "abaqus", units,
                                       representation="smeared"))
    assert [b[0] for b in blocks][:1] == ["MATERIAL"]
    E, nu = block(blocks, "ELASTIC")[0]
    assert E == pytest.approx(values["E"] * scale["stress"]) and nu == values["nu"]
    assert block(blocks, "CONCRETE DAMAGED PLASTICITY").shape == (1, 5)
    assert block(blocks, "CONCRETE COMPRESSION HARDENING").shape[1] == 2
    stiffening = block(blocks, "CONCRETE TENSION STIFFENING", TYPE="DISPLACEMENT")
    assert stiffening[0, 1] == 0.0 and stiffening[0, 0] == pytest.approx(law.strength * scale["stress"])
    assert np.trapezoid(stiffening[:, 0], stiffening[:, 1]) == pytest.approx(law.fracture_energy * scale["energy"],
                                                                             rel=1e-8)
    damage = block(blocks, "CONCRETE TENSION DAMAGE", TYPE="DISPLACEMENT")
    assert np.array_equal(damage[:, 1], stiffening[:, 1]) and damage[0, 0] == 0.0
    assert np.all(np.diff(damage[:, 0]) >= 0) and damage[:, 0].max() <= 0.99
    # below the cap the plastic displacement u_ck - d / (1 - d) sigma l0 / E0 (l0 = 1 length unit) is zero: secant
    below = damage[:, 0] < 0.99
    plastic = stiffening[:, 1] - damage[:, 0] / (1 - damage[:, 0]) * stiffening[:, 0] / E
    assert np.allclose(plastic[below], 0.0, atol=1e-9 * stiffening[-1, 1])


def diana_parameters(text):
    """{path: value} of the ``setParameter( MATERIAL, name, path, value )`` commands (comments skipped) and the
    ``addMaterial`` arguments."""
    import ast

    values, material = {}, None
    for line in text.splitlines():
        line = line.strip()
        if line.startswith("addMaterial("):
            material = ast.literal_eval(line[len("addMaterial"):])
        elif line.startswith("setParameter("):
            _, name, path, value = (part.strip() for part in line[len("setParameter("):-1].split(","))
            values[ast.literal_eval(path)] = ast.literal_eval(value)
    return material, values


@pytest.mark.parametrize("units, scale", [("N-mm-MPa", MM), ("N-m-Pa", SI)], ids=["mm", "m"])
@pytest.mark.parametrize("model_type, law, values, curve, words", [
    ("crack-band", None, CRACK, "HORDYK", "the same law"),
    ("crack-band", "linear", {k: CRACK[k] for k in ("E", "nu", "ft", "Gf")}, "LINEAR", "the same law"),
    ("cohesive-crack", None, {**CRACK, "c2": 5.0}, "HORDYK", "APPROXIMATION"),
    ("gradient-damage", None, DAMAGE, None, "APPROXIMATION"),  # the closest curve, whichever it is
], ids=["hordijk", "linear", "other-hordijk", "gradient-damage"])
def test_the_diana_total_strain_crack_carries_strength_energy_and_curve(tmp_path, model_type, law, values, curve,
                                                                        words, units, scale):
    model = model_from_type(model_type, law)
    table = model.cohesive_law(model.parameters(**values))
    text = export_text(write_result(tmp_path, model_type, values, ("ft", "Gf") if "ft" in values else ("kappa_i",),
                                    law=law), "diana", units)
    material, parameters = diana_parameters(text)
    assert material[1:3] == ("CONCR", "TSCR")
    from fracid.exchange.diana import DIANA_CURVES, shape_difference

    assert parameters["MODTYP/TOTCRK"] == "ROTATE" and parameters["TENSIL/TENCRV"] == (curve or min(
        DIANA_CURVES, key=lambda c: shape_difference(table, c)))
    assert parameters["TENSIL/TENSTR"] == pytest.approx(table.strength * scale["stress"], rel=1e-10)
    assert parameters["TENSIL/GF1"] == pytest.approx(table.fracture_energy * scale["energy"], rel=1e-10)
    assert parameters["LINEAR/ELASTI/YOUNG"] == pytest.approx(values["E"] * scale["stress"])
    assert parameters["LINEAR/ELASTI/POISON"] == values["nu"]
    assert words in text and ("EQUIVALENCE" in text) == (model_type == "gradient-damage")
    assert ("representation: smeared, while the cohesive-crack model's crack is discrete" in text) == \
        (model_type == "cohesive-crack")


def test_the_shape_difference_diana_reports_is_zero_for_its_own_curve_and_large_for_another():
    from fracid.exchange.diana import shape_difference
    from fracid.fem.material.laws import BilinearSoftening, HordijkLaw
    from fracid.models.cohesive_law import law_table

    hordijk = HordijkLaw()
    assert shape_difference(law_table(hordijk, hordijk.parameters(**CRACK)), "HORDYK") < 1e-3
    bilinear = BilinearSoftening()
    table = law_table(bilinear, bilinear.parameters(E=3e4, nu=0.2, ft=3.0, Gf=0.1))
    assert shape_difference(table, "HORDYK") > 0.05
    assert shape_difference(table, "LINEAR") > shape_difference(table, "HORDYK")


def test_diana_refuses_a_discrete_crack_asked_for_and_says_why(tmp_path):
    from fracid.runtime.exits import UsageError

    with pytest.raises(UsageError, match="smeared only"):
        export_text(write_result(tmp_path, "cohesive-crack", CRACK, ("ft", "Gf")), "diana", representation="discrete")


@pytest.mark.parametrize("model_type, values", [("cohesive-crack", CRACK), ("gradient-damage", DAMAGE)])
def test_abaqus_interpolating_the_damage_table_between_rows_keeps_the_traction(model_type, values):
    """Abaqus interpolates D linearly between rows: at every quarter of every row interval the traction (1 - D) K
    (delta0 + u) stays within 0.1 % of ft of the law; the law's own openings alone would be off by far more (1 - D
    falls over a few delta0, which 101 equal rows do not resolve)."""
    from fracid.exchange.abaqus import STIFFNESS_IN_LAW_SLOPES, damage_table

    model = model_from_type(model_type)
    table = model.cohesive_law(model.parameters(**values))
    K = STIFFNESS_IN_LAW_SLOPES * table.strength / table.critical_opening

    def worst(damage, u):
        between = np.sort(np.concatenate([u, *(a * u[1:] + (1 - a) * u[:-1] for a in (0.25, 0.5, 0.75))]))
        traction = (1 - np.interp(between, u, damage)) * K * (table.strength / K + between)
        return np.max(np.abs(traction - np.interp(between, table.opening, table.traction))) / table.strength

    assert worst(*damage_table(table, K)) < 1e-3
    sparse = 1.0 - table.traction / (K * (table.strength / K + table.opening))
    assert worst(sparse, table.opening) > 0.1
