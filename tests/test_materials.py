"""Consistent tangents and stresses against central finite differences."""
import numpy as np
import pytest

from skfem_pg import materials as mat

MATERIALS = [
    mat.LinearElastic(lam=1.2, mu=0.8),
    mat.LinearElastic(lam=1.2, mu=0.8, plane_stress=True),
    mat.StVenantKirchhoff(lam=1.2, mu=0.8),
    mat.NeoHooke(lam=1.2, mu=0.8),
    mat.NeoHookeIsoVol.from_lame(1.2, 0.8),
]


def random_F(d, n=7, seed=0, scale=0.3):
    rng = np.random.default_rng(seed)
    F = np.eye(d)[:, :, None] + scale * rng.uniform(-1, 1, (d, d, n))
    # keep J > 0
    J = np.linalg.det(np.moveaxis(F, -1, 0))
    assert np.all(J > 0.2)
    return F


def d_dF(fn, F, h=1e-6):
    """Central differences of ``fn`` with respect to each ``F[k, L]``:
    shape ``fn(F).shape[:-1] + (d, d, n)``."""
    d = F.shape[0]
    out = None
    for k in range(d):
        for L in range(d):
            dF = np.zeros_like(F)
            dF[k, L] = h
            col = (fn(F + dF) - fn(F - dF)) / (2 * h)
            if out is None:
                out = np.zeros(col.shape[:-1] + (d, d, F.shape[-1]))
            out[..., k, L, :] = col
    return out


@pytest.mark.parametrize("d", [2, 3])
@pytest.mark.parametrize("m", MATERIALS, ids=repr)
def test_tangent_matches_finite_differences(m, d):
    F = random_F(d, seed=d)
    A = m.tangent(F)
    assert np.abs(A - d_dF(m.stress, F)).max() <= \
        1e-7 * max(1.0, np.abs(A).max())


@pytest.mark.parametrize("d", [2, 3])
@pytest.mark.parametrize("m", MATERIALS[2:], ids=repr)
def test_stress_is_energy_derivative(m, d):
    F = random_F(d, seed=10 + d)
    P = m.stress(F)
    assert np.abs(P - d_dF(m.energy, F)).max() <= \
        1e-7 * max(1.0, np.abs(P).max())


@pytest.mark.parametrize("m", MATERIALS[2:], ids=repr)
def test_stress_free_reference_and_small_strain_limit(m):
    d = 3
    F = np.eye(d)[:, :, None] * np.ones(2)
    assert np.abs(m.stress(F)).max() < 1e-14
    lin = mat.LinearElastic(lam=1.2, mu=0.8)
    A0 = m.tangent(F)
    assert np.abs(A0 - lin.tangent(F)).max() < 1e-12
