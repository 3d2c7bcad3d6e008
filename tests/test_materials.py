"""Consistent tangents and stresses against central finite differences."""
import numpy as np
import pytest

from skfem_pg import materials as mat

MATERIALS = [
    mat.LinearElastic(1.2, 0.8),
    mat.LinearElastic(1.2, 0.8, plane_stress=True),
    mat.StVenantKirchhoff(1.2, 0.8),
    mat.NeoHooke(1.2, 0.8),
    mat.NeoHookeIsoVol.from_lame(1.2, 0.8),
]


def random_F(d, n=7, seed=0, scale=0.3):
    rng = np.random.default_rng(seed)
    F = np.eye(d)[:, :, None] + scale * rng.uniform(-1, 1, (d, d, n))
    # keep J > 0
    J = np.linalg.det(np.moveaxis(F, -1, 0))
    assert np.all(J > 0.2)
    return F


@pytest.mark.parametrize("d", [2, 3])
@pytest.mark.parametrize("m", MATERIALS, ids=repr)
def test_tangent_matches_finite_differences(m, d):
    F = random_F(d, seed=d)
    A = m.tangent(F)
    h = 1e-6
    A_fd = np.zeros_like(A)
    for k in range(d):
        for L in range(d):
            dF = np.zeros_like(F)
            dF[k, L] = h
            A_fd[:, :, k, L] = (m.stress(F + dF) - m.stress(F - dF)) / (2 * h)
    assert np.abs(A - A_fd).max() <= 1e-7 * max(1.0, np.abs(A).max())


@pytest.mark.parametrize("d", [2, 3])
@pytest.mark.parametrize("m", MATERIALS[2:], ids=repr)
def test_stress_is_energy_derivative(m, d):
    F = random_F(d, seed=10 + d)
    P = m.stress(F)
    h = 1e-6
    P_fd = np.zeros_like(P)
    for k in range(d):
        for L in range(d):
            dF = np.zeros_like(F)
            dF[k, L] = h
            P_fd[k, L] = (m.energy(F + dF) - m.energy(F - dF)) / (2 * h)
    assert np.abs(P - P_fd).max() <= 1e-7 * max(1.0, np.abs(P).max())


@pytest.mark.parametrize("m", MATERIALS[2:], ids=repr)
def test_stress_free_reference_and_small_strain_limit(m):
    d = 3
    F = np.eye(d)[:, :, None] * np.ones(2)
    assert np.abs(m.stress(F)).max() < 1e-14
    lin = mat.LinearElastic(1.2, 0.8)
    A0 = m.tangent(F)
    assert np.abs(A0 - lin.tangent(F)).max() < 1e-12
