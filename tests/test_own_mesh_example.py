"""examples/own_mesh: the half notched beam drawn in Gmsh (half_beam.geo -> half_beam.msh) and its identification
config validate, and the specimen they describe runs (a short forward run, no identification)."""

from pathlib import Path

import numpy as np
import pytest

from fracid.models import DamageModel

pytest.importorskip("meshio")

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "own_mesh"


def test_the_own_mesh_example_validates_and_its_specimen_runs():
    from fracid.config import build_parameters, build_specimen, load_config

    cfg = load_config(EXAMPLE / "identify.toml", purpose="identify")
    assert cfg.specimen.type == "mesh"
    assert cfg.experiments[0].file.resolve() == (
        EXAMPLE / "../../src/fracid/datasets/gregoire2013_beam4/load_cmod.csv").resolve()
    specimen = build_specimen(cfg)
    description = specimen.describe()
    assert description.cells.shape[1] == 6  # the linear Gmsh triangles run as T6
    for group in ("ligament", "support", "support_point", "loading_plate", "mouth"):
        assert len(description.nodes_of(group)) > 0
    np.testing.assert_allclose(description.nodes[description.nodes_of("mouth")], [[1.0, 0.0]])

    params = build_parameters(cfg)
    result = DamageModel().simulate(specimen, params, target=0.02, stop_force_fraction=None)
    assert result.status == "target reached"
    assert "fpz_width" in result.observables  # the crack line of the config
    assert result.control[-1] == pytest.approx(0.02)
    slope = result.force[1] / result.control[1]
    assert slope > 0
    # the whole beam's elastic force-CMOD slope, about 87 kN/mm for the built-in beam of E = 36 250 MPa
    assert 0.9 * 87_000 < slope < 1.1 * 87_000
