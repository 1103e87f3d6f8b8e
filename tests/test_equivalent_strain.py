import numpy as np
import pytest

from fracid.fem.material.equivalent_strain import (
    modified_von_mises_3d,
    modified_von_mises_plane_stress,
    modified_von_mises_uniaxial,
)

NU, ETA = 0.2, 10.0


def uniaxial_stress_3d(eps, nu=NU):
    return np.array([eps, -nu * eps, -nu * eps, 0.0, 0.0, 0.0])


@pytest.mark.parametrize("eps", [1e-4, 3e-3])
def test_uniaxial_tension_and_compression_3d(eps):
    assert modified_von_mises_3d(uniaxial_stress_3d(eps), NU, ETA)[0] == pytest.approx(eps, rel=1e-12)
    assert modified_von_mises_3d(uniaxial_stress_3d(-eps), NU, ETA)[0] == pytest.approx(eps / ETA, rel=1e-12)


@pytest.mark.parametrize("eps", [1e-4, 3e-3])
def test_uniaxial_tension_and_compression_plane_stress(eps):
    # uniaxial stress along x in plane stress: eyy = -nu exx, ezz follows from plane stress
    for sign, expected in ((1, eps), (-1, eps / ETA)):
        strain = np.array([sign * eps, -NU * sign * eps, 0.0])
        assert modified_von_mises_plane_stress(strain, NU, ETA)[0] == pytest.approx(expected, rel=1e-12)
    # the same along y, and rotated by 45 degrees (pure axial stress in a rotated frame)
    assert modified_von_mises_plane_stress(np.array([-NU * eps, eps, 0.0]), NU, ETA)[0] == pytest.approx(eps)
    rotated = np.array([(1 - NU) * eps / 2, (1 - NU) * eps / 2, (1 + NU) * eps])
    assert modified_von_mises_plane_stress(rotated, NU, ETA)[0] == pytest.approx(eps, rel=1e-12)


def test_uniaxial_1d_tension_compression_and_agreement_with_3d():
    eps = np.array([-2e-3, -1e-5, 1e-5, 4e-4])
    value, deriv = modified_von_mises_uniaxial(eps[:, None], NU, ETA)
    np.testing.assert_allclose(value, np.where(eps > 0, eps, -eps / ETA), rtol=1e-14)
    np.testing.assert_allclose(deriv[:, 0], np.where(eps > 0, 1.0, -1.0 / ETA), rtol=1e-14)
    full = np.array([modified_von_mises_3d(uniaxial_stress_3d(e), NU, ETA)[0] for e in eps])
    np.testing.assert_allclose(value, full, rtol=1e-12)


def test_plane_stress_equals_3d_with_ezz():
    rng = np.random.default_rng(0)
    strain = rng.normal(scale=1e-3, size=(20, 3))
    ezz = -NU / (1 - NU) * (strain[:, 0] + strain[:, 1])
    full = np.column_stack([strain[:, 0], strain[:, 1], ezz, strain[:, 2], np.zeros(20), np.zeros(20)])
    np.testing.assert_allclose(
        modified_von_mises_plane_stress(strain, NU, ETA)[0], modified_von_mises_3d(full, NU, ETA)[0], rtol=1e-13
    )


def central_difference(fn, strain, h):
    grad = np.zeros_like(strain)
    for j in range(strain.shape[-1]):
        step = np.zeros(strain.shape[-1])
        step[j] = h
        grad[..., j] = (fn(strain + step)[0] - fn(strain - step)[0]) / (2 * h)
    return grad


@pytest.mark.parametrize(
    "fn, n", [(modified_von_mises_3d, 6), (modified_von_mises_plane_stress, 3), (modified_von_mises_uniaxial, 1)]
)
@pytest.mark.parametrize("nu, eta", [(0.2, 10.0), (0.0, 1.0), (0.3, 3.0)])
def test_derivative_matches_central_differences(fn, n, nu, eta):
    rng = np.random.default_rng(1)
    strain = rng.normal(scale=1e-3, size=(50, n))
    strain = strain[np.all(np.abs(strain) > 1e-5, axis=1)]  # away from the kink of |eps| in 1D
    h = 1e-9
    numeric = central_difference(lambda e: fn(e, nu, eta), strain, h)
    analytic = fn(strain, nu, eta)[1]
    np.testing.assert_allclose(analytic, numeric, rtol=1e-6, atol=1e-9)


def test_zero_strain_is_finite():
    for fn, n in ((modified_von_mises_3d, 6), (modified_von_mises_plane_stress, 3), (modified_von_mises_uniaxial, 1)):
        value, deriv = fn(np.zeros((4, n)), NU, ETA)
        assert np.all(value == 0) and np.all(np.isfinite(deriv))
