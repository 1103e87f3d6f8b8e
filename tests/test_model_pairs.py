"""Which model runs on which specimen (the README's table), and the crack models on the dog-bone."""

import numpy as np
import pytest

from fracid.fem.material.cohesive import CohesiveParameters
from fracid.models import MODEL_TYPES, CohesiveCrackModel, CrackBandModel, model_from_type, runs_on
from fracid.specimens import SPECIMENS, BarWithWeakZone, DogBone, NotchedBeam, TensionStrip, WedgeSplitting

# model type -> specimens it runs on (the README's table of pairs)
PAIRS = {
    "gradient-damage": {BarWithWeakZone, NotchedBeam, DogBone, WedgeSplitting},
    "local-damage": {BarWithWeakZone, NotchedBeam, DogBone, WedgeSplitting},
    "integral-damage": {BarWithWeakZone, NotchedBeam, DogBone, WedgeSplitting},
    "cohesive-crack": {NotchedBeam, DogBone, WedgeSplitting},
    "crack-band": {NotchedBeam, DogBone, TensionStrip, WedgeSplitting},
    "pf-czm": {BarWithWeakZone, NotchedBeam, DogBone, TensionStrip, WedgeSplitting},
}


@pytest.mark.parametrize("kind", sorted(MODEL_TYPES))
def test_the_table_of_pairs(kind):
    specimens = [BarWithWeakZone(n_elements=20), NotchedBeam(h_fine=5.0, h_coarse=10.0), DogBone(size=50.0, h_fine=5.0),
                 TensionStrip(), WedgeSplitting(h_fine=10.0, h_coarse=40.0)]
    model = model_from_type(kind)
    assert {type(s) for s in specimens if runs_on(model, s)} == PAIRS[kind]
    for specimen in specimens:
        if not runs_on(model, specimen):
            with pytest.raises(TypeError, match="does not run on"):
                model.simulate(specimen, model.parameters(), target=0.01)
    assert {cls for cls in SPECIMENS.values() if cls.default_instance() is not None} <= {type(s) for s in specimens}


def test_cohesive_crack_and_crack_band_on_the_dogbone():
    """Both crack models on the glued dog-bone (crack along the mid-height section): the peak is the
    strength of the notched section within a few percent, the models agree with each other, and the
    energy dissipated to the end of the run is below Gf times the section."""
    params = CohesiveParameters(E=30000.0, nu=0.2, ft=3.0, Gf=0.08)
    dogbone = DogBone(size=50.0, h_fine=3.0)
    runs = {model.key: model.simulate(dogbone, params, target=0.03, stop_force_fraction=None)
            for model in (CohesiveCrackModel(), CrackBandModel())}
    section = dogbone.nominal_section
    peaks = {key: float(np.max(run.force)) for key, run in runs.items()}
    for key, run in runs.items():
        assert run.status == "target reached", key
        assert 0.93 < peaks[key] / (params.ft * section) < 1.0, key
        dissipated = run.observables["dissipated_energy"][-1]
        assert 0.3 * params.Gf * section < dissipated < params.Gf * section, key
    cohesive, band = runs["cohesive-crack-hordijk"], runs["crack-band-hordijk"]
    assert peaks["crack-band-hordijk"] == pytest.approx(peaks["cohesive-crack-hordijk"], rel=0.02)
    np.testing.assert_allclose(np.interp(cohesive.control, band.control, band.force), cohesive.force,
                               atol=0.03 * peaks["cohesive-crack-hordijk"])
    assert cohesive.observables["crack_length"][-1] > 0.8 * 0.5 * dogbone.notch_width * dogbone.size
