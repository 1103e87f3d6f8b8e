import numpy as np
import pytest

from fracid.fem.material.damage import exponential_damage, kappa_at_damage, update_history

KI = 1e-4


@pytest.mark.parametrize("alpha, beta", [(0.99, 300.0), (1.0, 0.0), (0.5, 1000.0), (0.0, 50.0)])
def test_damage_derivative_matches_central_differences(alpha, beta):
    kappa = np.linspace(1.01 * KI, 40 * KI, 200)
    h = 1e-10
    numeric = (exponential_damage(kappa + h, KI, alpha, beta)[0] - exponential_damage(kappa - h, KI, alpha, beta)[0]) / (2 * h)
    np.testing.assert_allclose(exponential_damage(kappa, KI, alpha, beta)[1], numeric, rtol=1e-6)


def test_damage_values():
    omega, d = exponential_damage(np.array([0.0, 0.5 * KI, KI]), KI, 0.99, 300.0)
    assert np.all(omega == 0.0)  # continuous at the threshold
    assert np.all(d[:2] == 0.0)
    # perfect damage: stress (1 - omega) E kappa stays E kappa_i
    kappa = np.linspace(KI, 10 * KI, 7)
    omega, _ = exponential_damage(kappa, KI, 1.0, 0.0)
    np.testing.assert_allclose((1 - omega) * kappa, KI, rtol=1e-14)
    # alpha = 1: damage tends to 1; alpha < 1: the residual stress (1-alpha) E kappa_i remains
    assert exponential_damage(1.0, KI, 1.0, 300.0)[0] == pytest.approx(1.0)
    assert (1 - exponential_damage(1.0, KI, 0.9, 1e4)[0]) * 1.0 == pytest.approx(0.1 * KI, rel=1e-9)


def test_kappa_at_damage_inverts_the_law():
    for omega in (0.0, 0.1, 0.5, 0.99):
        kappa = kappa_at_damage(omega, KI, 0.99, 300.0)
        assert exponential_damage(kappa, KI, 0.99, 300.0)[0] == pytest.approx(omega, abs=1e-12)
    with pytest.raises(ValueError, match="never reached"):
        kappa_at_damage(1.0, KI, 0.99, 300.0)


def test_history_update_kuhn_tucker():
    kappa_old = np.array([0.0, 2e-4, 2e-4, 3e-4])
    driving = np.array([1e-4, 1e-4, 3e-4, 3e-4])
    kappa, loading = update_history(kappa_old, driving)
    np.testing.assert_array_equal(kappa, [1e-4, 2e-4, 3e-4, 3e-4])
    np.testing.assert_array_equal(loading, [True, False, True, True])  # neutral loading counts as loading
